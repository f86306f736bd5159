#include "common/agent_rejoin.hpp"

#include <gtest/gtest.h>

#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <string>

namespace ddswarm {
namespace {

std::string write_scenario(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("agent_rejoin_test_" + std::to_string(getpid()) + "_" + name + ".yaml");
  std::ofstream(path) << text;
  return path.string();
}

TEST(AgentRejoin, LongestSceneWaitIsTheSpreadAboveRejoinAfter) {
  EXPECT_DOUBLE_EQ(longest_scene_wait_s(kDefaultRejoinAfterS), 60.0);
  EXPECT_DOUBLE_EQ(longest_scene_wait_s(10.0), 15.0);
  EXPECT_DOUBLE_EQ(longest_scene_wait_s(0.0), 0.0);
}

// Under DDS Security agents queue for the server's key exchanges: at least
// 1 s per drone for the scene; without security, or at 0 (never), as given.
TEST(AgentRejoin, SecureSwarmsWaitLongerForTheScene) {
  EXPECT_DOUBLE_EQ(rejoin_after_for(40.0, 128, false), 40.0);
  EXPECT_DOUBLE_EQ(rejoin_after_for(40.0, 6, true), 40.0);
  EXPECT_DOUBLE_EQ(rejoin_after_for(40.0, 128, true), 128.0);
  EXPECT_DOUBLE_EQ(rejoin_after_for(200.0, 128, true), 200.0);
  EXPECT_DOUBLE_EQ(rejoin_after_for(0.0, 128, true), 0.0);
}

TEST(AgentRejoin, ReadsTheScenariosValue) {
  const auto p = write_scenario("set", "scenario:\n  drones: 3\nagent:\n  rejoin_after_s: 12\n");
  EXPECT_DOUBLE_EQ(scenario_rejoin_after_s(p), 12.0);
  std::filesystem::remove(p);
}

TEST(AgentRejoin, DefaultsWhenAbsentOrUnreadable) {
  const auto none = write_scenario("none", "scenario:\n  drones: 3\n");
  EXPECT_DOUBLE_EQ(scenario_rejoin_after_s(none), kDefaultRejoinAfterS);
  const auto bad = write_scenario("bad", "agent:\n  rejoin_after_s: [1, 2]\n");
  EXPECT_DOUBLE_EQ(scenario_rejoin_after_s(bad), kDefaultRejoinAfterS);
  EXPECT_DOUBLE_EQ(scenario_rejoin_after_s("/nonexistent/scenario.yaml"), kDefaultRejoinAfterS);
  std::filesystem::remove(none);
  std::filesystem::remove(bad);
}

}  // namespace
}  // namespace ddswarm
