#include "common/scenario.hpp"

#include <set>

namespace ddswarm {

const char* to_string(TimeMode m) { return m == TimeMode::kLockstep ? "lockstep" : "realtime"; }

void load(YamlSection s, ScenarioConfig& c) {
  FieldLoader load(s);
  ScenarioConfig::fields(c, load);
  s.finish();
}

void ScenarioConfig::validate() const {
  FieldChecker check("scenario");
  fields(*this, check);
}

void check_sections(const YamlDocument& doc) {
  static const std::set<std::string> known = {
      "scenario", "sim", "quadrotor",      "controller", "sensors", "scene", "agent",
      "comm",     "dds", "ground_station", "task",       "wind",    "aero"};
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
