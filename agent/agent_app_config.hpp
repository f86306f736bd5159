#pragma once
// What an agent process reads from a scenario file, on its own: the config
// fuzzer (tests/fuzz) loads it without the DDS application.
#include <string>
#include <vector>

#include "agent/agent_config.hpp"
#include "agent/comm_config.hpp"
#include "common/dds_config.hpp"
#include "common/scenario.hpp"

namespace ddswarm::agent {

/// Everything the agent reads from a scenario file.
struct AgentAppConfig {
  ScenarioConfig scenario;
  AgentConfig agent;
  CommConfig comm;
  DdsConfig dds;
  /// The drones this process flies, each in [0, scenario.drones): one (the
  /// usual agent process) or many (an agent host, `--ids 0-511`).
  std::vector<int> drone_ids{0};
  double duplicate_probe_s = 1.0;  ///< s wall: listen for another agent on this id before flying
  void validate() const;
};

/// Loads the scenario's scenario/agent/dds sections; throws ConfigError.
AgentAppConfig load_agent_config(const std::string& path);

}  // namespace ddswarm::agent
