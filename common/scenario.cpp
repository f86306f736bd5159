#include "common/scenario.hpp"

#include <set>

namespace ddswarm {

const char* to_string(TimeMode m) { return m == TimeMode::kLockstep ? "lockstep" : "realtime"; }

void load(YamlSection s, ScenarioConfig& c) {
  s.get("name", c.name);
  s.get("seed", c.seed);
  s.get("drones", c.drones);
  s.get_enum("mode", c.mode, {{"realtime", TimeMode::kRealtime}, {"lockstep", TimeMode::kLockstep}});
  s.finish();
}

void ScenarioConfig::validate() const {
  if (drones < 1 || drones > 1024)
    throw FieldError("scenario.drones", std::to_string(drones), "must be in [1, 1024]");
}

void check_sections(const YamlDocument& doc) {
  static const std::set<std::string> known = {"scenario", "sim",    "quadrotor",      "controller",
                                              "sensors",  "scene",  "agent",          "comm",
                                              "dds",      "ground_station", "task"};
  const auto& root = doc.root();
  if (!root || !root.IsMap()) return;
  for (auto it = root.begin(); it != root.end(); ++it) {
    if (!known.count(it->first.Scalar()))
      throw ConfigError(doc.file() + ":" + std::to_string(it->first.Mark().line + 1) + ": " +
                        it->first.Scalar() + ": unknown section");
  }
}

YamlDocument load_scenario(const std::string& path) {
  auto doc = YamlDocument::load_file(path);
  check_sections(doc);
  return doc;
}

}  // namespace ddswarm
