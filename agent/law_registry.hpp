#pragma once
// Builds a drone's swarm law from its LawConfig: the thesis's law
// (agent/swarm_law.hpp) or one of the built-in laws of agent/laws/.
#include <memory>
#include <string>

#include "agent/agent_config.hpp"
#include "ddswarm/law.hpp"

namespace ddswarm::agent {

/// The law c names, built for ctx with rng. The thesis law reads its
/// parameters from agent (activation, sensor_function); the others from
/// c.params. Throws law::ParamError for a bad or unknown parameter.
std::unique_ptr<law::SwarmLaw> make_law(const LawConfig& c, const law::LawContext& ctx,
                                        law::Rng rng, const AgentConfig& agent);

/// The Python-law plug-in: $DDSWARM_PYTHON_LAW, else lib/ddswarm/ beside
/// the executable's bin/.
std::string python_law_plugin();

/// The seed of drone id's law: a function of the scenario seed and the id
/// alone, so a drone draws the same numbers in every run with that seed.
std::uint64_t law_seed(std::uint64_t scenario_seed, int drone_id);

}  // namespace ddswarm::agent
