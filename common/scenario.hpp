#pragma once
// The `scenario:` section: what every process must agree on.
#include <cstdint>
#include <string>

#include "common/config_fields.hpp"
#include "common/yaml_section.hpp"

namespace ddswarm {

/// The most drones a scenario flies (scenario.drones; the IDL sequences' bound).
inline constexpr int kMaxDrones = 1024;

enum class TimeMode { kRealtime, kLockstep };
const char* to_string(TimeMode m);

struct ScenarioConfig {
  std::string name = "unnamed";
  std::uint64_t seed = 1;
  int drones = 6;
  TimeMode mode = TimeMode::kRealtime;

  /// Every field once (common/config_fields.hpp).
  template <class Self, class V>
  static void fields(Self& c, V& v) {
    static const Choices<TimeMode> kModes{{"realtime", TimeMode::kRealtime},
                                          {"lockstep", TimeMode::kLockstep}};
    v.field("name", c.name, {"", any(), "shown in logs and results"});
    v.field("seed", c.seed, {"", any(), "seeds sensor noise, random starts, comm models and laws"});
    v.field("drones", c.drones, {"", in(1, kMaxDrones), "number of drones, ids 0..drones-1"});
    v.choice("mode", c.mode, kModes,
             {"", any(), "realtime: wall-clock paced; lockstep: waits for every agent"});
  }

  void validate() const;
};

void load(YamlSection s, ScenarioConfig& c);

/// Top-level sections a scenario file may hold. Each process reads the ones it
/// owns strictly and checks that no unknown section is present.
void check_sections(const YamlDocument& doc);

/// Loads a scenario file and checks its top-level sections (ConfigError otherwise).
YamlDocument load_scenario(const std::string& path);

}  // namespace ddswarm
