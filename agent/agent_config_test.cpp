#include "agent/agent_config.hpp"
#include "agent/comm_config.hpp"
#include "common/config_reference.hpp"

#include <gtest/gtest.h>

using namespace ddswarm;
using namespace ddswarm::agent;

namespace {

/// Loads and validates `text` as a scenario; returns the ConfigError text, or "".
std::string error_of(const std::string& text) {
  try {
    auto doc = YamlDocument::parse(text, "s.yaml");
    AgentConfig c;
    doc.guard([&] {
      load(doc.section("agent"), c);
      c.validate();
    });
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

AgentConfig loaded(const std::string& text) {
  auto doc = YamlDocument::parse(text, "s.yaml");
  AgentConfig c;
  load(doc.section("agent"), c);
  c.validate();
  return c;
}

}  // namespace

TEST(AgentConfig, DefaultsAreValidAndMatchTheThesis) {
  AgentConfig c;
  EXPECT_NO_THROW(c.validate());
  EXPECT_EQ(c.inter_distance_m, 4.0);
  EXPECT_EQ(c.task_speed_mps, 0.8);
  EXPECT_GT(c.activation.repulsion_gain, c.activation.attraction_gain);
  EXPECT_EQ(c.sensor_function.type, SensorFunctionType::kFs1);
  // An absent section keeps every default.
  EXPECT_EQ(loaded("other: {}\n").max_speed_mps, c.max_speed_mps);
}

TEST(AgentConfig, ReadsEveryFieldIncludingNestedSections) {
  AgentConfig c = loaded(R"(
agent:
  inter_distance_m: 6
  max_speed_mps: 4
  altitude_hold: false
  altitude_gain: 2
  altitude_tolerance_m: 0.2
  min_altitude_m: 1
  takeoff_altitude_m: 3
  takeoff_speed_mps: 1.5
  landing_speed_mps: 0.4
  task_speed_mps: 1.2
  teleop_timeout_s: 0.5
  server_timeout_s: 2
  activation:
    type: custom
    points: [[-3, -2], [0, 0], [2, 0.5]]
    max_mps: 2
    cutoff_m: 12
    neighbours: 7
  sensor_function:
    type: custom
    points: [[0.5, 3], [2, 1], [5, 0]]
    safety_distance_m: 0.8
)");
  EXPECT_EQ(c.inter_distance_m, 6);
  EXPECT_EQ(c.max_speed_mps, 4);
  EXPECT_FALSE(c.altitude_hold);
  EXPECT_EQ(c.altitude_gain, 2);
  EXPECT_EQ(c.altitude_tolerance_m, 0.2);
  EXPECT_EQ(c.min_altitude_m, 1);
  EXPECT_EQ(c.takeoff_altitude_m, 3);
  EXPECT_EQ(c.takeoff_speed_mps, 1.5);
  EXPECT_EQ(c.landing_speed_mps, 0.4);
  EXPECT_EQ(c.task_speed_mps, 1.2);
  EXPECT_EQ(c.teleop_timeout_s, 0.5);
  EXPECT_EQ(c.server_timeout_s, 2);
  EXPECT_EQ(c.activation.type, ActivationType::kCustom);
  ASSERT_EQ(c.activation.points.size(), 3u);
  EXPECT_EQ(c.activation.points[0], Eigen::Vector2d(-3, -2));
  EXPECT_EQ(c.activation.max_mps, 2);
  EXPECT_EQ(c.activation.cutoff_m, 12);
  EXPECT_EQ(c.activation.neighbours, 7);
  EXPECT_EQ(c.sensor_function.type, SensorFunctionType::kCustom);
  EXPECT_EQ(c.sensor_function.points.back(), Eigen::Vector2d(5, 0));
  EXPECT_EQ(c.sensor_function.safety_distance_m, 0.8);

  AgentConfig lin = loaded(
      "agent:\n  activation: {attraction_gain: 0.5, repulsion_gain: 2, max_mps: 1}\n"
      "  sensor_function: {type: log, max_mps: 3, log_gain_mps: 1.5}\n");
  EXPECT_EQ(lin.activation.attraction_gain, 0.5);
  EXPECT_EQ(lin.activation.repulsion_gain, 2);
  EXPECT_EQ(lin.activation.max_mps, 1);
  EXPECT_EQ(lin.sensor_function.type, SensorFunctionType::kLog);
  EXPECT_EQ(lin.sensor_function.max_mps, 3);
  EXPECT_EQ(lin.sensor_function.log_gain_mps, 1.5);
}

TEST(AgentConfig, UnknownKeysAreErrorsWithFileAndLine) {
  EXPECT_EQ(error_of("agent:\n  inter_distance: 4\n"),
            "s.yaml:2: agent.inter_distance: unknown key");
  EXPECT_EQ(error_of("agent:\n  activation:\n    slope: 1\n"),
            "s.yaml:3: agent.activation.slope: unknown key");
  EXPECT_EQ(error_of("agent:\n  sensor_function:\n    range_m: 5\n"),
            "s.yaml:3: agent.sensor_function.range_m: unknown key");
}

TEST(AgentConfig, BadEnumNamesTheChoices) {
  EXPECT_EQ(error_of("agent:\n  sensor_function:\n    type: fs3\n"),
            "s.yaml:3: agent.sensor_function.type = fs3: must be one of custom|fs1|fs2|log");
}

TEST(AgentConfig, ValidationErrorsNameTheField) {
  EXPECT_EQ(error_of("agent:\n  inter_distance_m: -4\n"),
            "s.yaml:2: agent.inter_distance_m = -4: must be > 0");
  // Re-joining DDS needs time to discover first: 0 (never) or at least 2 s.
  EXPECT_EQ(error_of("agent:\n  rejoin_after_s: 0.5\n"),
            "s.yaml:2: agent.rejoin_after_s = 0.5: must be in [2, 3600]");
  EXPECT_EQ(error_of("agent:\n  rejoin_after_s: 0\n"), "");
  EXPECT_EQ(error_of("agent:\n  handshake_timeout_s: 1\n"),
            "s.yaml:2: agent.handshake_timeout_s = 1: must be in [2, 3600]");
  EXPECT_EQ(error_of("agent:\n  handshake_timeout_s: 0\n"), "");
  EXPECT_NE(
      error_of("agent:\n  activation:\n    repulsion_gain: 0.1\n")
          .find("s.yaml:3: agent.activation.repulsion_gain = 0.1: must be >= attraction_gain"),
      std::string::npos);
  EXPECT_NE(error_of("agent:\n  task_speed_mps: 5\n")
                .find("agent.task_speed_mps = 5: must be <= max_speed_mps"),
            std::string::npos);
  EXPECT_NE(
      error_of("agent:\n  activation:\n    cutoff_m: 3\n").find("agent.activation.cutoff_m = 3"),
      std::string::npos);
  EXPECT_EQ(error_of("agent:\n  activation:\n    neighbours: -1\n"),
            "s.yaml:3: agent.activation.neighbours = -1: must be 0 (every peer) or 1..64");
  EXPECT_NE(error_of("agent:\n  min_altitude_m: 3\n").find("agent.takeoff_altitude_m = 2"),
            std::string::npos);
}

TEST(AgentConfig, CustomActivationCurveIsChecked) {
  auto err = [](const std::string& pts) {
    return error_of("agent:\n  activation:\n    type: custom\n    points: " + pts + "\n");
  };
  EXPECT_EQ(err("[[-2, -1], [0, 0], [2, 1]]"), "");
  EXPECT_NE(err("[[-2, -1], [0, 0.1], [2, 1]]").find("must pass through (0, 0)"),
            std::string::npos);
  EXPECT_NE(err("[[-2, -1], [2, 1]]").find("must contain the point [0, 0]"), std::string::npos);
  EXPECT_NE(err("[[-2, 1], [0, 0], [2, 1]]")
                .find("agent.activation.points[0] = [-2, 1]: f must be < 0 (repulsive)"),
            std::string::npos);
  EXPECT_NE(err("[[-2, -1], [0, 0], [2, -1]]").find("f must be > 0 (attractive)"),
            std::string::npos);
  EXPECT_NE(err("[[0, 0], [-2, -1], [2, 1]]").find("agent.activation.points[1]"),
            std::string::npos);
  EXPECT_NE(err("[[0, 0], [2, 1]]").find("both sides of 0"), std::string::npos);
  EXPECT_NE(err("[[0, 0]]").find("at least 2 points"), std::string::npos);
  // The validation error points at the offending line.
  EXPECT_EQ(err("[[-2, 1], [0, 0], [2, 1]]").rfind("s.yaml:4:", 0), 0u);
  // Points without type: custom would silently do nothing.
  EXPECT_NE(error_of("agent:\n  activation:\n    points: [[-1, -1], [0, 0], [1, 1]]\n")
                .find("only used with type: custom"),
            std::string::npos);
}

TEST(AgentConfig, CustomSensorCurveIsChecked) {
  auto err = [](const std::string& pts) {
    return error_of("agent:\n  sensor_function:\n    type: custom\n    points: " + pts + "\n");
  };
  EXPECT_EQ(err("[[0, 2], [3, 0]]"), "");
  EXPECT_NE(err("[[0, 2], [3, 0.5]]").find("the last point must have f = 0"), std::string::npos);
  EXPECT_NE(err("[[-1, 2], [3, 0]]").find("distance S must be >= 0"), std::string::npos);
  EXPECT_NE(err("[[0, -2], [3, 0]]").find("f must be >= 0"), std::string::npos);
  EXPECT_NE(err("[[3, 2], [1, 0]]").find("strictly increasing"), std::string::npos);
  EXPECT_NE(error_of("agent:\n  sensor_function:\n    safety_distance_m: -1\n")
                .find("agent.sensor_function.safety_distance_m = -1: must be >= 0"),
            std::string::npos);
}

TEST(AgentConfig, ShippedScenariosLoad) {
  for (const char* name : {"thesis_course.yaml", "swarm_field.yaml"}) {
    SCOPED_TRACE(name);
    auto doc = YamlDocument::load_file(std::string(DDSWARM_CONFIG_DIR) + "/" + name);
    AgentConfig c;
    EXPECT_NO_THROW(doc.guard([&] {
      load(doc.section("agent"), c);
      c.validate();
    }));
    // The large field flies the law for dense swarms; the course, the thesis's.
    EXPECT_EQ(c.activation.neighbours, std::string(name) == "swarm_field.yaml" ? 6 : 0);
  }
}

TEST(AgentConfig, TheThesisLawIsTheDefaultForEveryDrone) {
  AgentConfig c = loaded("agent: {}\n");
  EXPECT_EQ(c.law.type, LawType::kThesis);
  EXPECT_TRUE(c.overrides.empty());
  EXPECT_EQ(&c.law_for(0), &c.law);
  EXPECT_EQ(&c.law_for(511), &c.law);
}

TEST(AgentConfig, OverridesGiveDronesTheirOwnLaw) {
  AgentConfig c = loaded(R"(
agent:
  law: {type: reynolds}
  overrides:
    - ids: 3-5
      law: {type: vasarhelyi, params: {v_flock_mps: 1.5}}
    - ids: 7
      law: {type: olfati_saber}
)");
  EXPECT_EQ(c.law_for(0).type, LawType::kReynolds);
  EXPECT_EQ(c.law_for(2).type, LawType::kReynolds);
  for (int id : {3, 4, 5}) EXPECT_EQ(c.law_for(id).type, LawType::kVasarhelyi) << id;
  EXPECT_EQ(c.law_for(3).params.at("v_flock_mps"), "1.5");
  EXPECT_EQ(c.law_for(6).type, LawType::kReynolds);
  EXPECT_EQ(c.law_for(7).type, LawType::kOlfatiSaber);
}

TEST(AgentConfig, ALawRefusesWhatItDoesNotTakeNamingFileLineAndField) {
  const std::string unknown =
      error_of("agent:\n  law:\n    type: reynolds\n    params:\n      cohesion_gian: 1\n");
  EXPECT_EQ(
      unknown.rfind(
          "s.yaml:5: agent.law.params.cohesion_gian = 1: unknown parameter (this law takes ", 0),
      0u)
      << unknown;
  EXPECT_NE(unknown.find("cohesion_gain"), std::string::npos) << unknown;
  EXPECT_EQ(error_of("agent:\n  law: {type: thesis, params: {gain: 2}}\n"),
            "s.yaml:2: agent.law.params.gain = 2: unknown parameter (this law takes none)");
  EXPECT_EQ(error_of("agent:\n  law: {type: boids}\n"),
            "s.yaml:2: agent.law.type = boids: must be one of "
            "olfati_saber|plugin|python|reynolds|thesis|vasarhelyi");
  EXPECT_EQ(error_of("agent:\n  law: {type: reynolds, params: {cohesion_gain: fast}}\n"),
            "s.yaml:2: agent.law.params.cohesion_gain = fast: must be a finite number");
  EXPECT_EQ(error_of("agent:\n  law: {type: reynolds, params: {cohesion_gain: [1, 2]}}\n")
                .rfind("s.yaml:2: agent.law.params.cohesion_gain = (not a scalar): ", 0),
            0u);
  EXPECT_EQ(error_of("agent:\n  law: {type: vasarhelyi, params: nope}\n"),
            "s.yaml:2: agent.law.params: must be a mapping of key: value");
}

TEST(AgentConfig, AnOverrideIsCheckedLikeTheSwarmsLaw) {
  EXPECT_EQ(error_of("agent:\n  overrides:\n    - ids: 2\n      law:\n        type: olfati_saber\n"
                     "        params: {epsilon: -1}\n")
                .rfind("s.yaml:6: agent.overrides[0].law.params.epsilon = -1: must be in [", 0),
            0u);
  EXPECT_EQ(error_of("agent:\n  overrides:\n    - ids: 5-3\n      law: {type: reynolds}\n"),
            "s.yaml:3: agent.overrides[0].ids = 5-3: range 5-3 runs backwards");
  EXPECT_EQ(error_of("agent:\n  overrides:\n    - {ids: 1-3, law: {type: reynolds}}\n"
                     "    - {ids: 3, law: {type: vasarhelyi}}\n"),
            "s.yaml:4: agent.overrides[1].ids = 3: drone 3 is in an earlier override too");
  EXPECT_EQ(error_of("agent:\n  overrides:\n    - {ids: 1, lwa: {type: reynolds}}\n"),
            "s.yaml:3: agent.overrides[0].lwa: unknown key");
}

TEST(AgentConfig, AnInjectedLawFaultNeedsAKind) {
  EXPECT_EQ(error_of("agent:\n  law: {fault_after_s: 3}\n"),
            "s.yaml:2: agent.law.fault_after_s = 3: needs fault: nan or throw");
  EXPECT_EQ(loaded("agent:\n  law: {fault: throw, fault_after_s: 3}\n").law.fault,
            LawConfig::Fault::kThrow);
}

TEST(AgentConfig, APluginLibraryThatCannotBeFlownIsRefusedWithItsReason) {
  EXPECT_EQ(error_of("agent:\n  law: {type: plugin}\n"),
            "s.yaml:2: agent.law.library = \"\": a plug-in law needs the path of its library");
  EXPECT_EQ(error_of("agent:\n  law: {type: plugin, library: /nonexistent/libx.so}\n"),
            "s.yaml:2: agent.law.library = /nonexistent/libx.so: no such file");
  // A file that is no shared library, and a library that is no plug-in.
  EXPECT_EQ(error_of("agent:\n  law: {type: plugin, library: /etc/hostname}\n")
                .rfind("s.yaml:2: agent.law.library = /etc/hostname: cannot be loaded: ", 0),
            0u);
  const std::string libm = "/lib/x86_64-linux-gnu/libm.so.6";
  EXPECT_EQ(error_of("agent:\n  law: {type: plugin, library: " + libm + "}\n"),
            "s.yaml:2: agent.law.library = " + libm +
                ": is not a ddswarm law plug-in: it exports no ddswarm_law_api_version or "
                "ddswarm_law_factory (export the law with DDSWARM_LAW_PLUGIN, docs/laws.md)");
  EXPECT_EQ(error_of("agent:\n  law: {type: reynolds, library: x.so}\n"),
            "s.yaml:2: agent.law.library = x.so: only used with type: plugin");
}

TEST(AgentConfig, TheReferenceDescribesEveryFieldAsTheCodeDeclaresIt) {
  const std::string doc = configuration_reference();
  using Mismatches = std::vector<std::string>;
  EXPECT_EQ(reference_mismatches(doc, "### `agent:`", field_rows<AgentConfig>()), Mismatches{});
  EXPECT_EQ(reference_mismatches(doc, "(`agent.activation`)", field_rows<ActivationConfig>()),
            Mismatches{});
  EXPECT_EQ(
      reference_mismatches(doc, "(`agent.sensor_function`)", field_rows<SensorFunctionConfig>()),
      Mismatches{});
  EXPECT_EQ(reference_mismatches(doc, "(`agent.law`)", field_rows<LawConfig>()), Mismatches{});
  EXPECT_EQ(reference_mismatches(doc, "### `comm:`", field_rows<CommConfig>()), Mismatches{});
}
