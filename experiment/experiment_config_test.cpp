#include "experiment/experiment_config.hpp"

#include "common/config_reference.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace ddswarm::gs {
namespace {

namespace fs = std::filesystem;

std::string error_of(const std::string& text) {
  try {
    parse_experiment(text, "/exp/table.yaml");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "no error";
}

const char* kValid = R"(experiment:
  name: demo
  scenario: course.yaml
  runs_per_set: 3
  base_seed: 7
  sets:
    - name: A
      set: { agent.inter_distance_m: 4 }
    - name: B
)";

TEST(ExperimentConfig, ReadsTheThesisTable1File) {
  const auto c = load_experiment_file(DDSWARM_SOURCE_DIR "/config/table1.yaml");
  EXPECT_EQ(c.name, "table1");
  EXPECT_EQ(c.scenario, "thesis_course.yaml");
  EXPECT_EQ(c.scenario_path, DDSWARM_SOURCE_DIR "/config/thesis_course.yaml");
  EXPECT_EQ(c.runs_per_set, 15);
  EXPECT_EQ(c.mode, "lockstep");
  EXPECT_EQ(c.timeout_s, 300);
  ASSERT_EQ(c.sets.size(), 4u);
  const double d_int[] = {4, 4, 4, 6};
  const double speed[] = {0.8, 0.8, 1.2, 1.2};
  const char* sensor[] = {"fs1", "fs2", "fs2", "fs2"};
  for (int i = 0; i < 4; ++i) {
    SCOPED_TRACE(i);
    const auto& o = c.sets[i].overrides;
    EXPECT_EQ(c.sets[i].name, "Sim " + std::to_string(i + 1));
    EXPECT_EQ(o.at("scenario.drones").as<int>(), 6);
    EXPECT_EQ(o.at("agent.inter_distance_m").as<double>(), d_int[i]);
    EXPECT_EQ(o.at("task.speed_mps").as<double>(), speed[i]);
    EXPECT_EQ(o.at("agent.sensor_function.type").as<std::string>(), sensor[i]);
  }
  EXPECT_EQ(c.seed(0, 0), 1000u);
  EXPECT_EQ(c.seed(3, 14), 4014u);
}

// Overrides only replace keys the scenario already has, so a typo in
// table1.yaml cannot silently add an ignored key.
TEST(ExperimentConfig, Table1OverridesReplaceExistingScenarioKeys) {
  const auto c = load_experiment_file(DDSWARM_SOURCE_DIR "/config/table1.yaml");
  if (!fs::exists(c.scenario_path)) GTEST_SKIP() << c.scenario_path << " is missing";
  const YAML::Node base = YamlDocument::load_file(c.scenario_path).root();
  for (std::size_t i = 0; i < c.sets.size(); ++i) {
    const YAML::Node sc = scenario_for_set(c, i);
    for (const auto& [key, value] : c.sets[i].overrides) {
      SCOPED_TRACE(c.sets[i].name + ": " + key);
      YAML::Node before = base, after = sc;
      std::string::size_type start = 0;
      for (;;) {
        const auto dot = key.find('.', start);
        const std::string part = key.substr(start, dot - start);
        before.reset(before[part]);
        after.reset(after[part]);
        ASSERT_TRUE(before.IsDefined());
        if (dot == std::string::npos) break;
        start = dot + 1;
      }
      EXPECT_EQ(after.Scalar(), value.Scalar());
    }
  }
}

TEST(ExperimentConfig, DefaultsAndRelativeScenario) {
  const auto c = parse_experiment(kValid, "/exp/table.yaml");
  EXPECT_EQ(c.scenario_path, "/exp/course.yaml");
  EXPECT_EQ(c.mode, "lockstep");
  EXPECT_EQ(c.timeout_s, 300);
  ASSERT_EQ(c.sets.size(), 2u);
  EXPECT_TRUE(c.sets[1].overrides.empty());
  EXPECT_EQ(c.seed(1, 2), 1009u);
  EXPECT_EQ(parse_experiment(std::string(kValid) + "  # comment\n", "rel/dir/t.yaml").scenario_path,
            "rel/dir/course.yaml");
}

TEST(ExperimentConfig, UnknownKeysNameFileAndLine) {
  EXPECT_EQ(error_of(std::string(kValid) + "  repeat: 3\n"),
            "/exp/table.yaml:10: experiment.repeat: unknown key");
  EXPECT_EQ(error_of(std::string(kValid) + "    - name: C\n      runs: 2\n"),
            "/exp/table.yaml:11: experiment.sets[2].runs: unknown key");
  EXPECT_EQ(error_of(std::string(kValid) + "extra: 1\n"), "/exp/table.yaml:10: extra: unknown key");
  EXPECT_EQ(error_of("other: 1\n"), "/exp/table.yaml:1: no `experiment:` section");
}

TEST(ExperimentConfig, BadValuesNameFieldAndLine) {
  auto with = [](const std::string& from, const std::string& to) {
    std::string t = kValid;
    t.replace(t.find(from), from.size(), to);
    return error_of(t);
  };
  EXPECT_EQ(with("runs_per_set: 3", "runs_per_set: 0"),
            "/exp/table.yaml:4: experiment.runs_per_set = 0: must be in [1, 1000]");
  EXPECT_EQ(with("runs_per_set: 3", "runs_per_set: three"),
            "/exp/table.yaml:4: experiment.runs_per_set = three: must be an integer");
  EXPECT_EQ(with("  base_seed: 7", "  mode: turbo"),
            "/exp/table.yaml:5: experiment.mode = turbo: must be lockstep or realtime");
  EXPECT_EQ(with("  base_seed: 7", "  timeout_s: -1"),
            "/exp/table.yaml:5: experiment.timeout_s = -1: must be > 0");
  EXPECT_EQ(with("name: B", "name: A"),
            "/exp/table.yaml:9: experiment.sets[1].name = A: another set has this name");
  EXPECT_EQ(with("  scenario: course.yaml\n", ""),
            "/exp/table.yaml:1: experiment.scenario = \"\": must name a scenario file");
  EXPECT_EQ(with("{ agent.inter_distance_m: 4 }", "{ agent..x: 4 }"),
            "/exp/table.yaml:8: experiment.sets[0].set.agent..x = agent..x: must be a dotted "
            "key path like agent.x");
  EXPECT_EQ(with("{ agent.inter_distance_m: 4 }", "{ agent: {}, agent.x: 4 }"),
            "/exp/table.yaml:8: experiment.sets[0].set.agent.x = agent.x: conflicts with agent "
            "(set one or the other)");
  EXPECT_EQ(with("{ agent.inter_distance_m: 4 }", "{ a.b: 4, a.b: 5 }"),
            "/exp/table.yaml:8: experiment.sets[0].set.a.b: duplicate key (first at line 8)");
  EXPECT_EQ(with("{ agent.inter_distance_m: 4 }", "[ 4 ]"),
            "/exp/table.yaml:8: experiment.sets[0].set: must be a mapping of key: value");
  std::string no_sets = kValid;
  no_sets.resize(no_sets.find("  sets:"));
  EXPECT_EQ(error_of(no_sets),
            "/exp/table.yaml:1: experiment.sets = []: must list at least one set");
}

TEST(ExperimentConfig, TheReferenceDescribesEveryField) {
  EXPECT_EQ(reference_mismatches(configuration_reference(), "## Experiment files",
                                 field_rows<ExperimentConfig>()),
            std::vector<std::string>{});
}

TEST(ExperimentConfig, MissingFileIsAConfigError) {
  EXPECT_THROW(load_experiment_file("/no/such/experiment.yaml"), ConfigError);
}

TEST(ApplyOverrides, SetsNestedKeysOnADeepCopy) {
  const YAML::Node scenario = YAML::Load(
      "scenario: { drones: 6, seed: 1 }\n"
      "agent: { inter_distance_m: 4, sensor_function: { type: fs1, max_mps: 2 } }\n");
  std::map<std::string, YAML::Node> o;
  o["scenario.drones"] = YAML::Load("12");
  o["agent.sensor_function.type"] = YAML::Load("fs2");
  o["task.speed_mps"] = YAML::Load("1.2");
  o["scene.cylinders"] = YAML::Load("[{ center_xy: [0, 10], radius_m: 1 }]");
  YAML::Node out = apply_overrides(scenario, o);

  EXPECT_EQ(out["scenario"]["drones"].as<int>(), 12);
  EXPECT_EQ(out["scenario"]["seed"].as<int>(), 1);  // siblings kept
  EXPECT_EQ(out["agent"]["sensor_function"]["type"].as<std::string>(), "fs2");
  EXPECT_EQ(out["agent"]["sensor_function"]["max_mps"].as<double>(), 2);
  EXPECT_EQ(out["task"]["speed_mps"].as<double>(), 1.2);  // missing mappings are created
  EXPECT_EQ(out["scene"]["cylinders"][0]["radius_m"].as<double>(), 1);

  // The input and the override values are untouched by the copy.
  EXPECT_EQ(scenario["scenario"]["drones"].as<int>(), 6);
  EXPECT_EQ(scenario["agent"]["sensor_function"]["type"].as<std::string>(), "fs1");
  EXPECT_FALSE(scenario["task"]);
  out["scene"]["cylinders"][0]["radius_m"] = 5;
  EXPECT_EQ(o["scene.cylinders"][0]["radius_m"].as<double>(), 1);
}

TEST(ApplyOverrides, EmptyScenarioAndNullSections) {
  std::map<std::string, YAML::Node> o{{"agent.inter_distance_m", YAML::Load("6")}};
  EXPECT_EQ(apply_overrides(YAML::Node(), o)["agent"]["inter_distance_m"].as<double>(), 6);
  EXPECT_EQ(apply_overrides(YAML::Load("agent:\n"), o)["agent"]["inter_distance_m"].as<double>(),
            6);
  EXPECT_EQ(apply_overrides(YAML::Load("a: 1"), {})["a"].as<int>(), 1);
}

TEST(ApplyOverrides, ErrorsNameTheKey) {
  const YAML::Node scenario =
      YAML::Load("agent: { inter_distance_m: 4 }\nscene: { cylinders: [] }");
  auto error = [&](const std::string& key) -> std::string {
    try {
      apply_overrides(scenario, {{key, YAML::Load("1")}});
    } catch (const ConfigError& e) {
      return e.what();
    }
    return "no error";
  };
  EXPECT_EQ(error("agent.inter_distance_m.x"),
            "override agent.inter_distance_m.x: agent.inter_distance_m is a value, not a mapping");
  EXPECT_EQ(error("scene.cylinders.0.radius_m"),
            "override scene.cylinders.0.radius_m: scene.cylinders is a list, not a mapping");
  EXPECT_EQ(error(".agent"), "override .agent: must be a dotted key path like agent.x");
  EXPECT_EQ(error("agent."), "override agent.: must be a dotted key path like agent.x");
  EXPECT_THROW(apply_overrides(YAML::Load("[1, 2]"), {{"a", YAML::Load("1")}}), ConfigError);
}

TEST(ApplyOverrides, ScenarioForSetReadsTheScenarioFile) {
  const fs::path dir = fs::temp_directory_path() / ("gs_exp_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  {
    std::ofstream(dir / "course.yaml")
        << "scenario: { drones: 6 }\nagent: { inter_distance_m: 4 }\n";
  }
  { std::ofstream(dir / "exp.yaml") << kValid; }
  const auto c = load_experiment_file((dir / "exp.yaml").string());
  EXPECT_EQ(scenario_for_set(c, 0)["agent"]["inter_distance_m"].as<double>(), 4);
  { std::ofstream(dir / "course.yaml") << "agent: { inter_distance_m: 3 }\n"; }
  EXPECT_EQ(scenario_for_set(c, 0)["agent"]["inter_distance_m"].as<double>(), 4);
  EXPECT_EQ(scenario_for_set(c, 1)["agent"]["inter_distance_m"].as<double>(), 3);
  EXPECT_THROW(scenario_for_set(c, 2), std::out_of_range);
  { std::ofstream(dir / "course.yaml") << "agent: 3\n"; }
  try {
    scenario_for_set(c, 0);
    FAIL();
  } catch (const ConfigError& e) {
    // Named by the experiment file's line of the override.
    EXPECT_EQ(std::string(e.what()), (dir / "exp.yaml").string() +
                                         ":8: set 'A': agent.inter_distance_m: agent is a value, "
                                         "not a mapping");
  }
  fs::remove(dir / "course.yaml");
  EXPECT_THROW(scenario_for_set(c, 0), ConfigError);
  fs::remove_all(dir);
}

// `ddswarm-gs experiment --set`: one value for every set, over the set's own.
TEST(ExperimentConfig, CommandLineOverridesWinInEverySet) {
  auto c = parse_experiment(R"(experiment:
  scenario: course.yaml
  sets:
    - name: A
      set: { agent.inter_distance_m: 4, agent.sensor_function.type: fs1 }
    - name: B
      set: { agent.sensor_function: { type: fs2 } }
)",
                            "/exp/table.yaml");
  override_every_set(
      c, parse_set_options({"sim.physics_rate_hz=250", "agent.sensor_function.type=fs2"}));
  for (const auto& set : c.sets) {
    SCOPED_TRACE(set.name);
    EXPECT_EQ(set.overrides.at("sim.physics_rate_hz").as<int>(), 250);
    EXPECT_EQ(set.overrides.at("agent.sensor_function.type").as<std::string>(), "fs2");
    EXPECT_EQ(set.overrides.count("agent.sensor_function"), 0u);  // its parent gave way
  }
  EXPECT_EQ(c.sets[0].overrides.at("agent.inter_distance_m").as<double>(), 4);
  EXPECT_EQ(c.sets[1].overrides.size(), 2u);
  // An error names each override where it was written: the file's line, or the flag.
  const auto origins = override_origins(c, 0);
  ASSERT_EQ(origins.size(), 3u);
  EXPECT_EQ(origins[0].key, "agent.inter_distance_m");
  EXPECT_EQ(origins[0].where, "/exp/table.yaml:5: set 'A'");
  EXPECT_FALSE(origins[0].where_has_value);
  EXPECT_EQ(origins[1].key, "agent.sensor_function.type");
  EXPECT_EQ(origins[1].where, "--set agent.sensor_function.type=fs2");
  EXPECT_TRUE(origins[1].where_has_value);
  EXPECT_EQ(origins[2].where, "--set sim.physics_rate_hz=250");
  EXPECT_EQ(override_origins(c, 1).size(), 2u);
}

TEST(ExperimentConfig, RejectsASetOptionWithoutAKey) {
  for (const char* bad : {"sim.physics_rate_hz", "=250", ""}) {
    SCOPED_TRACE(bad);
    try {
      parse_set_options({"a.b=1", bad});
      FAIL();
    } catch (const FieldError& e) {
      EXPECT_EQ(std::string(e.what()), "--set = " + std::string(bad) + ": must be key.path=value");
    }
  }
  try {
    parse_set_options({"a.b=[1, 2"});
    FAIL();
  } catch (const FieldError& e) {
    EXPECT_NE(std::string(e.what()).find("--set = a.b=[1, 2: value is not YAML"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace ddswarm::gs
