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

/// Under DDS Security the server authenticates each agent and then exchanges
/// keys with it for every topic, and on a loaded machine the agents queue for
/// it: a secure agent waits for the scene at least this long per drone of the
/// scenario. 128 secure drones on 2 cores with the 40 s default: 84 agents
/// authenticated within about a second heard no scene within 40-60 s, joined
/// again (each a handshake more) and the swarm never came up; with 120 s the
/// same launch took off (docs/security.md, "Large secure swarms").
inline constexpr double kSecureSceneSecondsPerDrone = 1.0;

/// agent.rejoin_after_s as an agent of a swarm of `drones` uses it: as given
/// without security, and 0 (never) stays 0; otherwise at least
/// kSecureSceneSecondsPerDrone * drones.
constexpr double rejoin_after_for(double rejoin_after_s, int drones, bool secure) {
  if (!secure || rejoin_after_s <= 0) return rejoin_after_s;
  const double floor = kSecureSceneSecondsPerDrone * drones;
  return rejoin_after_s > floor ? rejoin_after_s : floor;
}

/// agent.rejoin_after_s of a scenario file; kDefaultRejoinAfterS when the file
/// names none, or when it or that value cannot be read (the agents name a bad
/// section themselves). Never throws.
double scenario_rejoin_after_s(const std::string& scenario_path);

}  // namespace ddswarm
