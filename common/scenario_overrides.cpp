#include "common/scenario_overrides.hpp"

#include "common/config_error.hpp"

namespace ddswarm {
namespace {

const char* kind(const YAML::Node& n) {
  switch (n.Type()) {
    case YAML::NodeType::Scalar:
      return "a value";
    case YAML::NodeType::Sequence:
      return "a list";
    case YAML::NodeType::Map:
      return "a mapping";
    default:
      return "empty";
  }
}

}  // namespace

std::vector<std::string> split_key_path(const std::string& key) {
  std::vector<std::string> parts;
  std::string::size_type start = 0;
  for (;;) {
    const auto dot = key.find('.', start);
    parts.push_back(key.substr(start, dot - start));
    if (parts.back().empty()) return {};
    if (dot == std::string::npos) return parts;
    start = dot + 1;
  }
}

YAML::Node apply_overrides(YAML::Node scenario,
                           const std::map<std::string, YAML::Node>& overrides) {
  YAML::Node out = YAML::Clone(scenario);
  if (!out || out.IsNull()) out = YAML::Node(YAML::NodeType::Map);
  for (const auto& [key, value] : overrides) {
    const auto parts = split_key_path(key);
    if (parts.empty()) throw OverrideError(key, "must be a dotted key path like agent.x");
    if (!out.IsMap())
      throw OverrideError(key, std::string("the scenario is ") + kind(out) + ", not a mapping");
    // yaml-cpp: Node assignment writes through; reset() rebinds the handle.
    YAML::Node cur;
    cur.reset(out);
    std::string walked;
    for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
      walked += (i ? "." : "") + parts[i];
      YAML::Node next = cur[parts[i]];
      if (!next || next.IsNull()) {
        cur[parts[i]] = YAML::Node(YAML::NodeType::Map);
        next.reset(cur[parts[i]]);
      } else if (!next.IsMap()) {
        throw OverrideError(key, walked + " is " + kind(next) + ", not a mapping");
      }
      cur.reset(next);
    }
    cur[parts.back()] = YAML::Clone(value);
  }
  return out;
}

std::map<std::string, YAML::Node> parse_set_options(const std::vector<std::string>& texts,
                                                    const std::string& option) {
  std::map<std::string, YAML::Node> out;
  for (const auto& kv : texts) {
    const auto eq = kv.find('=');
    if (eq == std::string::npos || eq == 0) throw FieldError(option, kv, "must be key.path=value");
    try {
      out[kv.substr(0, eq)] = YAML::Load(kv.substr(eq + 1));
    } catch (const YAML::Exception& e) {
      throw FieldError(option, kv, "value is not YAML: " + e.msg);
    }
  }
  return out;
}

}  // namespace ddswarm
