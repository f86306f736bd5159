#pragma once
// One tick of a drone's swarm law inside the framework (ddswarm/law.hpp):
// the law is asked while the swarm flies, its answer is checked, and the
// framework's obstacle term, altitude hold and limits shape the command.
#include <string>

#include "agent/agent_config.hpp"
#include "agent/swarm_law.hpp"
#include "ddswarm/law.hpp"

namespace ddswarm::agent {

struct LawStep {
  LawTerms terms;             ///< the command and its parts (terms.velocity, m/s, world)
  double yaw_rate_rad_s = 0;  ///< rad/s, the law's
  /// Why the law failed this tick (it threw, or answered a non-finite
  /// number), one line; empty when it did not. Then terms fly the mission
  /// velocity alone, as without a law.
  std::string fault;
};

/// With in.swarm_enabled and a law: the law's answer to o stands for
/// C + V_mission (landing keeps the mission's vertical part), and
/// frame_law adds C_s unless the law opts out. Otherwise, or when the law
/// fails, the mission velocity alone through frame_law, as evaluate_law
/// flies it with the swarm off.
LawStep step_law(law::SwarmLaw* law, const law::Observation& o, const LawInput& in,
                 const AgentConfig& c);

}  // namespace ddswarm::agent
