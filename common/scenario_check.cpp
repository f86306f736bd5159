#include "common/scenario_check.hpp"

#include <cctype>

namespace ddswarm {
namespace {

void index_lines(const YAML::Node& n, const std::string& prefix, int depth,
                 std::map<std::string, int>& lines) {
  // A recursive alias makes an endless tree; YamlDocument refuses it past 32 levels.
  if (depth > 32) return;
  if (n.IsMap()) {
    for (auto it = n.begin(); it != n.end(); ++it) {
      const std::string p = (prefix.empty() ? "" : prefix + ".") + it->first.Scalar();
      lines.emplace(p, it->first.Mark().line + 1);
      index_lines(it->second, p, depth + 1, lines);
    }
  } else if (n.IsSequence()) {
    for (std::size_t i = 0; i < n.size(); ++i) {
      const std::string p = prefix + "[" + std::to_string(i) + "]";
      lines.emplace(p, n[i].Mark().line + 1);
      index_lines(n[i], p, depth + 1, lines);
    }
  }
}

bool starts_with(const std::string& s, const std::string& prefix) {
  return s.compare(0, prefix.size(), prefix) == 0;
}

/// s begins with path, followed by " = " or ":" (a field of an error).
bool names_field(const std::string& s, const std::string& path) {
  if (path.empty() || !starts_with(s, path)) return false;
  const std::string after = s.substr(path.size());
  return starts_with(after, " = ") || starts_with(after, ":");
}

/// The section a dotted path is in: "agent" of "agent.x" and of "agent[2]".
std::string section_of(const std::string& path) { return path.substr(0, path.find_first_of(".[")); }

/// "<program>: error: " at the start of a process's error line.
std::string without_program(const std::string& error) {
  const std::string tag = ": error: ";
  const auto at = error.find(tag);
  if (at == std::string::npos || at == 0) return error;
  for (std::size_t i = 0; i < at; ++i) {
    const unsigned char c = error[i];
    if (!std::isalnum(c) && c != '-' && c != '_' && c != '.') return error;
  }
  return error.substr(at + tag.size());
}

void replace_all(std::string& s, const std::string& from, const std::string& to) {
  if (from.empty()) return;
  for (auto at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size()))
    s.replace(at, from.size(), to);
}

/// The reason of "field = value: reason" or "field: reason", where value is
/// the text a --set gave (the reader may print it otherwise: 1e3 as 1000).
std::string reason_of(const std::string& rest, const std::string& field, const std::string& value) {
  if (starts_with(rest, field + ":")) {
    const std::string reason = rest.substr(field.size() + 1);
    return starts_with(reason, " ") ? reason.substr(1) : reason;
  }
  const std::string after = rest.substr(field.size() + 3);  // past " = "
  if (starts_with(after, value + ": ")) return after.substr(value.size() + 2);
  // A value with ": " in it (a mapping) would be cut in the wrong place.
  const auto colon = after.find(": ");
  if (value.find(':') == std::string::npos && colon != std::string::npos)
    return after.substr(colon + 2);
  return rest;
}

}  // namespace

std::map<std::string, int> key_lines(const YAML::Node& root) {
  std::map<std::string, int> lines;
  index_lines(root, "", 0, lines);
  return lines;
}

std::string error_field(const std::string& message) {
  const auto end = message.find_first_of(" :");
  if (end == 0 || end == std::string::npos) return "";
  const std::string token = message.substr(0, end);
  if (token[0] == '-' || !names_field(message, token)) return "";
  return token;
}

bool override_wrote(const std::string& key, const std::string& field) {
  if (key.empty() || field.empty()) return false;
  return key == field || starts_with(field, key + ".") || starts_with(field, key + "[") ||
         starts_with(key, field + ".") || starts_with(key, field + "[");
}

std::string explain_scenario_error(const std::string& error, const std::string& derived,
                                   const ScenarioOrigin& origin) {
  std::string rest = without_program(error);
  const bool about_derived = !derived.empty() && starts_with(rest, derived + ":");
  if (about_derived) {
    rest = rest.substr(derived.size() + 1);
    std::size_t digits = 0;
    while (digits < rest.size() && std::isdigit(static_cast<unsigned char>(rest[digits]))) ++digits;
    if (digits > 0 && digits < rest.size() && rest[digits] == ':') rest = rest.substr(digits + 1);
    if (starts_with(rest, " ")) rest = rest.substr(1);
  }
  // The field: an override's key as it was written (it may hold anything, a
  // blank too), or else the message's first word.
  std::string field;
  for (const auto& o : origin.overrides)
    if (o.key.size() > field.size() && names_field(rest, o.key)) field = o.key;
  if (field.empty()) field = error_field(rest);
  if (!about_derived) {
    replace_all(rest, derived, origin.file);
    return rest;
  }
  // Its line is the copy's: of no use to the user.
  if (field.empty()) return origin.file + ": " + rest;
  // The most specific override that wrote the field is the one to name.
  const OverrideOrigin* by = nullptr;
  for (const auto& o : origin.overrides)
    if (override_wrote(o.key, field) && (!by || o.key.size() > by->key.size())) by = &o;
  if (by) {
    if (by->where_has_value && field == by->key) {
      const auto eq = by->where.find('=');
      const std::string value = eq == std::string::npos ? "" : by->where.substr(eq + 1);
      return by->where + ": " + reason_of(rest, field, value);
    }
    return by->where + ": " + rest;
  }
  // A field of the user's file: its line there, or its nearest parent's.
  int line = 0;
  for (std::string p = field; !p.empty() && line == 0;) {
    if (const auto it = origin.lines.find(p); it != origin.lines.end()) {
      line = it->second;
    } else {
      const auto cut = p.find_last_of(".[");
      p = cut == std::string::npos ? "" : p.substr(0, cut);
    }
  }
  std::string out = origin.file + ":" + (line > 0 ? std::to_string(line) + ":" : "") + " " + rest;
  // A field checked against another (control_rate_hz must divide
  // physics_rate_hz) is wrong with an override of the same section, perhaps
  // because of it.
  std::string with;
  for (const auto& o : origin.overrides)
    if (section_of(o.key) == section_of(field)) with += (with.empty() ? "" : ", ") + o.where;
  if (!with.empty()) out += " (with " + with + ")";
  return out;
}

}  // namespace ddswarm
