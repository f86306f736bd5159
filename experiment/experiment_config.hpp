#pragma once
// Experiment files: a scenario run many times under several parameter sets,
// like the thesis's Table 1 (config/table1.yaml).
//
//   experiment:
//     name: table1
//     scenario: thesis_course.yaml   # relative to the experiment file
//     runs_per_set: 15
//     base_seed: 1000
//     mode: lockstep
//     timeout_s: 300
//     sets:
//       - name: Sim 1
//         set: { agent.inter_distance_m: 4, task.speed_mps: 0.8 }
//
// Each set's `set:` maps dotted key paths of the scenario YAML to values;
// apply_overrides() writes them into a copy of the scenario, whose own loader
// then checks them like any other scenario key.
//
// Seeds: run k (0-based) of set s (0-based, in file order) uses
// base_seed + s * 1000 + k, so a run can be repeated alone and adding sets or
// runs never changes the seeds of the others.
#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "common/config_fields.hpp"
#include "common/scenario_check.hpp"
#include "common/scenario_overrides.hpp"  // apply_overrides, parse_set_options
#include "common/yaml_section.hpp"

namespace ddswarm::gs {

/// One parameter set: one column of the results table.
struct ExperimentSet {
  std::string name;                             ///< column title, e.g. "Sim 1"; unique, non-empty
  std::map<std::string, YAML::Node> overrides;  ///< dotted scenario key -> value
  /// Line in the experiment file of each override written there; one
  /// without a line came from the command line (override_every_set).
  std::map<std::string, int> lines;
};

struct ExperimentConfig {
  std::string file;  ///< the experiment file, as named (errors name it)
  std::string name = "experiment";
  std::string scenario;       ///< scenario file as written
  std::string scenario_path;  ///< scenario file resolved against the experiment's folder
  int runs_per_set = 15;
  std::uint64_t base_seed = 1000;  ///< see seed()
  std::string mode = "lockstep";
  double timeout_s = 300;
  std::vector<ExperimentSet> sets;  ///< at least one; load() reads them (their `set:` is free-form)

  /// The scalar fields of `experiment:`; validate() adds what relates them.
  template <class Self, class V>
  static void fields(Self& c, V& v) {
    v.field("name", c.name, {"", any(), "output file names; non-empty"});
    v.field("scenario", c.scenario, {"", any(), "scenario file, relative to the experiment's"});
    v.field("runs_per_set", c.runs_per_set, {"", in(1, 1000), "runs of each set"});
    v.field("base_seed", c.base_seed, {"", any(), "seed of run 0 of set 0"});
    v.field("mode", c.mode, {"", any(), "clock of every run: lockstep or realtime"});
    v.field("timeout_s", c.timeout_s, {"s (sim)", positive(), "a run's task fails after this"});
  }

  /// Throws FieldError("experiment.…") naming the first bad field.
  void validate() const;

  /// Seed of run run_index of set set_index: base_seed + set_index * 1000 + run_index.
  std::uint64_t seed(int set_index, int run_index) const;
};

/// Reads the `experiment:` section (strict: unknown keys are an error).
/// scenario_path is resolved against base_dir. Does not validate.
void load(YamlSection s, ExperimentConfig& c, const std::string& base_dir);

/// Loads and validates an experiment file. Throws ConfigError "file:line: …".
ExperimentConfig load_experiment_file(const std::string& path);

/// Same, from text; file names the text in errors and anchors the scenario path.
ExperimentConfig parse_experiment(const std::string& text, const std::string& file);

/// Writes overrides into every set of c, over the set's own value for the same
/// key (e.g. `experiment --set sim.physics_rate_hz=250` flies every set at
/// 250 Hz); each run's CSV row records them with the set's. Validates c again.
void override_every_set(ExperimentConfig& c, const std::map<std::string, YAML::Node>& overrides);

/// Where each override of set set_index came from, as an error names it:
/// "<experiment file>:<line>: set '<name>'" for one of the file's `set:`,
/// "--set <key>=<value>" for one of override_every_set's.
std::vector<OverrideOrigin> override_origins(const ExperimentConfig& c, std::size_t set_index);

/// The scenario of set set_index: the scenario file with the set's overrides
/// applied. Throws ConfigError (unreadable scenario, bad override: naming it
/// as override_origins does) or std::out_of_range (set_index).
YAML::Node scenario_for_set(const ExperimentConfig& c, std::size_t set_index);

}  // namespace ddswarm::gs
