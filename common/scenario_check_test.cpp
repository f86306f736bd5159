#include "common/scenario_check.hpp"

#include <gtest/gtest.h>

namespace ddswarm {
namespace {

// The user's file, as they wrote it: the lines errors must name.
const char* kUserFile =
    "scenario:\n"                              // 1
    "  drones: 6\n"                            // 2
    "sim:\n"                                   // 3
    "  control_rate_hz: 70\n"                  // 4
    "agent:\n"                                 // 5
    "  inter_distance_m: -1\n"                 // 6
    "scene:\n"                                 // 7
    "  cylinders:\n"                           // 8
    "    - {center: [0, 0], radius_m: 1}\n"    // 9
    "    - {center: [5, 0], radius_m: -2}\n";  // 10

ScenarioOrigin origin(std::vector<OverrideOrigin> overrides = {}) {
  return {"config/mine.yaml", key_lines(YAML::Load(kUserFile)), std::move(overrides)};
}

OverrideOrigin flag(const std::string& text) {
  return {text.substr(0, text.find('=')), "--set " + text, true};
}

const std::string kCopy = "/tmp/scenario-42.yaml";

TEST(KeyLines, NamesEveryDottedPathAndListItemAtItsLine) {
  const auto lines = key_lines(YAML::Load(kUserFile));
  EXPECT_EQ(lines.at("scenario"), 1);
  EXPECT_EQ(lines.at("sim.control_rate_hz"), 4);
  EXPECT_EQ(lines.at("agent.inter_distance_m"), 6);
  EXPECT_EQ(lines.at("scene.cylinders[1]"), 10);
  EXPECT_EQ(lines.at("scene.cylinders[1].radius_m"), 10);
  EXPECT_FALSE(lines.count("agent.max_speed_mps"));
}

TEST(ErrorField, IsTheFieldAValueOrAKeyErrorIsAbout) {
  EXPECT_EQ(error_field("agent.inter_distance_m = -1: must be > 0"), "agent.inter_distance_m");
  EXPECT_EQ(error_field("agent.nope: unknown key"), "agent.nope");
  EXPECT_EQ(error_field("physics: unknown section"), "physics");
  EXPECT_EQ(error_field("scene.cylinders[1].radius_m = -2: must be > 0"),
            "scene.cylinders[1].radius_m");
  EXPECT_EQ(error_field("invalid YAML: end of map not found"), "");
  EXPECT_EQ(error_field("cannot open file"), "");
  EXPECT_EQ(error_field("--id/--ids = 9: must be in [0, 5]"), "");
  EXPECT_EQ(error_field(""), "");
}

TEST(OverrideWrote, TheKeyWhatIsUnderItAndTheSectionItMade) {
  EXPECT_TRUE(override_wrote("agent.x", "agent.x"));
  EXPECT_TRUE(override_wrote("agent", "agent.x"));
  EXPECT_TRUE(override_wrote("scene.cylinders", "scene.cylinders[1].radius_m"));
  EXPECT_TRUE(override_wrote("foo.bar", "foo"));
  EXPECT_FALSE(override_wrote("agent.x", "agent.xy"));
  EXPECT_FALSE(override_wrote("sim.physics_rate_hz", "sim.control_rate_hz"));
}

TEST(ExplainScenarioError, ABadValueThroughSetNamesTheFlag) {
  const auto o = origin({flag("agent.inter_distance_m=-1")});
  EXPECT_EQ(explain_scenario_error(
                "ddswarm-agent: error: " + kCopy + ":50: agent.inter_distance_m = -1: must be > 0",
                kCopy, o),
            "--set agent.inter_distance_m=-1: must be > 0");
  // The reader prints the value it read, not the text typed.
  EXPECT_EQ(explain_scenario_error(kCopy + ":3: sensors.count = 100000: must be in [1, 4096]",
                                   kCopy, origin({flag("sensors.count=1e5")})),
            "--set sensors.count=1e5: must be in [1, 4096]");
}

TEST(ExplainScenarioError, AnUnknownKeyOrSectionThroughSetNamesTheFlag) {
  EXPECT_EQ(explain_scenario_error(kCopy + ":51: agent.inter_distanse_m: unknown key", kCopy,
                                   origin({flag("agent.inter_distanse_m=3")})),
            "--set agent.inter_distanse_m=3: unknown key");
  EXPECT_EQ(explain_scenario_error(kCopy + ":60: physiks: unknown section", kCopy,
                                   origin({flag("physiks.rate=3")})),
            "--set physiks.rate=3: physiks: unknown section");
  // A key with a blank in it is still the override's.
  EXPECT_EQ(explain_scenario_error(kCopy + ":51: agent.max speed: unknown key", kCopy,
                                   origin({flag("agent.max speed=3")})),
            "--set agent.max speed=3: unknown key");
}

TEST(ExplainScenarioError, AFieldUnderASetMappingNamesTheFlagAndTheField) {
  EXPECT_EQ(explain_scenario_error(kCopy + ":7: agent.inter_distance_m = -1: must be > 0", kCopy,
                                   origin({flag("agent={inter_distance_m: -1}")})),
            "--set agent={inter_distance_m: -1}: agent.inter_distance_m = -1: must be > 0");
  // Of two overrides that wrote it, the more specific one.
  EXPECT_EQ(
      explain_scenario_error(kCopy + ":7: agent.law.type = x: must be one of a|b", kCopy,
                             origin({flag("agent={law: {type: a}}"), flag("agent.law.type=x")})),
      "--set agent.law.type=x: must be one of a|b");
}

TEST(ExplainScenarioError, AValueOfTheFileNamesTheFileAndItsLineThere) {
  EXPECT_EQ(explain_scenario_error(
                "ddswarm-agent: error: " + kCopy + ":50: agent.inter_distance_m = -1: must be > 0",
                kCopy, origin({flag("comm.latency_s=0.3")})),
            "config/mine.yaml:6: agent.inter_distance_m = -1: must be > 0");
  EXPECT_EQ(explain_scenario_error(kCopy + ":33: scene.cylinders[1].radius_m = -2: must be > 0",
                                   kCopy, origin()),
            "config/mine.yaml:10: scene.cylinders[1].radius_m = -2: must be > 0");
  // Not in the file: its section's line; nothing of it in the file: no line.
  EXPECT_EQ(
      explain_scenario_error(kCopy + ":9: agent.max_speed_mps = 0: must be > 0", kCopy, origin()),
      "config/mine.yaml:5: agent.max_speed_mps = 0: must be > 0");
  EXPECT_EQ(explain_scenario_error(kCopy + ": task.speed_mps = 0: must be > 0", kCopy, origin()),
            "config/mine.yaml: task.speed_mps = 0: must be > 0");
}

TEST(ExplainScenarioError, AFileValueMadeWrongByAnOverrideOfItsSectionSaysWith) {
  EXPECT_EQ(explain_scenario_error(
                kCopy + ":12: sim.control_rate_hz = 70: must divide physics_rate_hz (300)", kCopy,
                origin({flag("sim.physics_rate_hz=300"), flag("agent.max_speed_mps=2")})),
            "config/mine.yaml:4: sim.control_rate_hz = 70: must divide physics_rate_hz (300) "
            "(with --set sim.physics_rate_hz=300)");
}

TEST(ExplainScenarioError, AnExperimentSetIsNamedByItsFileLineAndName) {
  const auto o = origin({{"sim.control_rate_hz", "config/exp.yaml:14: set 'Slow'", false}});
  EXPECT_EQ(explain_scenario_error("ddswarm-sim: error: " + kCopy +
                                       ":8: sim.control_rate_hz = 70: must divide physics_rate_hz "
                                       "(1000)",
                                   kCopy, o),
            "config/exp.yaml:14: set 'Slow': sim.control_rate_hz = 70: must divide "
            "physics_rate_hz (1000)");
}

TEST(ExplainScenarioError, AnErrorNamingNoFieldNamesTheUsersFile) {
  EXPECT_EQ(explain_scenario_error(kCopy + ": --id/--ids = 9: must be in [0, 5]", kCopy,
                                   origin({flag("scenario.drones=6")})),
            "config/mine.yaml: --id/--ids = 9: must be in [0, 5]");
  EXPECT_EQ(explain_scenario_error("ddswarm-sim: error: no such thing", kCopy, origin()),
            "no such thing");
}

}  // namespace
}  // namespace ddswarm
