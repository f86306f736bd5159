#pragma once
// Scenario overrides: dotted key paths of a scenario YAML written into a copy
// of it (ddswarm-launch --set, the experiment runner's sets and --set). The
// scenario's own loaders then check the values like any other key.
#include <yaml-cpp/yaml.h>

#include <map>
#include <string>
#include <vector>

#include "common/config_error.hpp"

namespace ddswarm {

/// An override that cannot be written into a scenario. what() is
/// "override <key>: <reason>"; key() and reason() let a caller name the
/// override as its user wrote it (ddswarm-launch: "--set agent.x.y=1: ...").
class OverrideError : public ConfigError {
 public:
  OverrideError(const std::string& key, const std::string& reason)
      : ConfigError("override " + key + ": " + reason), key_(key), reason_(reason) {}
  const std::string& key() const { return key_; }
  const std::string& reason() const { return reason_; }

 private:
  std::string key_, reason_;
};

/// Splits "a.b.c" into its parts; empty when a part is empty.
std::vector<std::string> split_key_path(const std::string& key);

/// A deep copy of scenario with every override written in: key "a.b.c" sets
/// scenario[a][b][c], creating missing mappings. Throws OverrideError naming the
/// key when a path is malformed or walks through a value that is not a mapping.
YAML::Node apply_overrides(YAML::Node scenario, const std::map<std::string, YAML::Node>& overrides);

/// Command-line overrides, each "key.path=value" (ddswarm-launch --set and
/// ddswarm-gs experiment --set); the value is YAML. Throws FieldError(option,
/// text, ...) for text without '=' or with nothing before it.
std::map<std::string, YAML::Node> parse_set_options(const std::vector<std::string>& texts,
                                                    const std::string& option = "--set");

}  // namespace ddswarm
