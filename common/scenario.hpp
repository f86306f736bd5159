#pragma once
// The `scenario:` section: what every process must agree on.
#include <cstdint>
#include <string>

#include "common/yaml_section.hpp"

namespace ddswarm {

enum class TimeMode { kRealtime, kLockstep };
const char* to_string(TimeMode m);

struct ScenarioConfig {
  std::string name = "unnamed";  ///< shown in logs and results
  std::uint64_t seed = 1;        ///< seeds sensor noise, random starts and comm models
  int drones = 6;                ///< number of drones, [1, 1024]
  TimeMode mode = TimeMode::kRealtime;  ///< realtime: wall-clock paced; lockstep: waits for every agent

  void validate() const;
};

void load(YamlSection s, ScenarioConfig& c);

/// Top-level sections a scenario file may hold. Each process reads the ones it
/// owns strictly and checks that no unknown section is present.
void check_sections(const YamlDocument& doc);

/// Loads a scenario file and checks its top-level sections (ConfigError otherwise).
YamlDocument load_scenario(const std::string& path);

}  // namespace ddswarm
