#pragma once
// The agent's re-join timing (YAML agent.rejoin_after_s), which processes
// other than the agent need too: the launcher's --gs waits for agents that
// heard no scene and join again. agent/agent_config.hpp reads the field.
#include <string>

namespace ddswarm {

/// agent.rejoin_after_s by default: s (wall) without a scene after joining
/// before an agent leaves DDS and joins again as a new participant.
inline constexpr double kDefaultRejoinAfterS = 40.0;

/// A join waits rejoin_after_s for the scene, and up to this share longer,
/// different in every process: when a whole swarm missed the server, its
/// agents must not all re-join at once.
inline constexpr double kRejoinSpread = 0.5;

/// The longest a first join waits for the scene before joining again.
constexpr double longest_scene_wait_s(double rejoin_after_s) {
  return rejoin_after_s * (1.0 + kRejoinSpread);
}

/// agent.rejoin_after_s of a scenario file; kDefaultRejoinAfterS when the file
/// names none, or when it or that value cannot be read (the agents name a bad
/// section themselves). Never throws.
double scenario_rejoin_after_s(const std::string& scenario_path);

}  // namespace ddswarm
