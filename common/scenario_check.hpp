#pragma once
// Errors about a scenario that ddswarm derived from the user's own, told in
// the user's terms. ddswarm-launch --set and an experiment's sets write their
// values into a copy of the user's scenario, and every process reads that
// copy; a reader's error then names the copy, a file the user never wrote,
// at a line of it. explain_scenario_error() names what the user typed
// instead: the --set flag (or the experiment's set) when the bad field is one
// that an override wrote, or else the user's own file at the field's line in it.
#include <yaml-cpp/yaml.h>

#include <map>
#include <string>
#include <vector>

namespace ddswarm {

/// One value ddswarm wrote into the user's scenario, and how to name it.
struct OverrideOrigin {
  std::string key;  ///< the dotted key path it sets, e.g. "agent.inter_distance_m"
  /// What the user wrote, as an error names it: "--set agent.inter_distance_m=-1",
  /// "config/table1.yaml:14: set 'Slow'".
  std::string where;
  /// where shows the value (a --set's text): an error about key itself then
  /// gives only its reason ("--set agent.inter_distance_m=-1: must be > 0").
  bool where_has_value = false;
};

/// The user's scenario file and what was written into its copy.
struct ScenarioOrigin {
  std::string file;                  ///< the user's scenario file, as they named it
  std::map<std::string, int> lines;  ///< key_lines() of that file
  std::vector<OverrideOrigin> overrides;
};

/// The line (1-based) of every dotted key path of a YAML document:
/// "agent", "agent.inter_distance_m", "scene.cylinders[1].radius_m".
std::map<std::string, int> key_lines(const YAML::Node& root);

/// The field a reader's error (without file and line) is about: "agent.x" of
/// "agent.x = -1: must be > 0", of "agent.x: unknown key", of "foo: unknown
/// section"; "" when it names none.
std::string error_field(const std::string& message);

/// Whether an override of key wrote field: the same path, one under it
/// ("agent" wrote "agent.x", "scene.cylinders" wrote "scene.cylinders[1].radius_m"),
/// or one above it ("foo.bar" made the section "foo").
bool override_wrote(const std::string& key, const std::string& field);

/// A reader's one-line error about derived (origin.file with its overrides
/// written in), e.g. "ddswarm-agent: error: /tmp/s.yaml:50: agent.x = -1: must be > 0"
/// (a leading "<program>: error: " is dropped), told in the user's terms:
///  - about a field an override wrote: "<where>: <reason>" when where holds
///    the value and the field is its key, "<where>: <field = value: reason>" otherwise;
///  - about any other field: "<origin.file>:<its line there>: <field = value:
///    reason>" (the line of its nearest parent in the file when the field is
///    not in it, none when neither is), followed by "(with <where>, ...)" naming
///    the overrides of the same section, which may have made it wrong;
///  - an error about derived that names no field: "<origin.file>: <message>";
///  - any other error: as it is, derived replaced by origin.file.
std::string explain_scenario_error(const std::string& error, const std::string& derived,
                                   const ScenarioOrigin& origin);

}  // namespace ddswarm
