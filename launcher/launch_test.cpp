#include "launcher/launch.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "common/config_error.hpp"
#include "common/process.hpp"

namespace ddswarm::gs {
namespace {

const std::string kScenario = std::string(DDSWARM_CONFIG_DIR) + "/thesis_course.yaml";

std::filesystem::path temp_dir(const std::string& name) {
  auto d = std::filesystem::temp_directory_path() /
           ("gs_launch_test_" + std::to_string(getpid()) + "_" + name);
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

/// A LaunchApp built from ddswarm-launch's command line, args after the program name.
std::unique_ptr<LaunchApp> build(std::vector<std::string> args) {
  CLI::App app;
  LaunchCommandLine cl;
  add_launch_command_line(app, cl);
  std::reverse(args.begin(), args.end());  // CLI11 takes them last first
  app.parse(args);
  return std::make_unique<LaunchApp>(app, std::move(cl));
}

TEST(SplitScript, TrimsEachStepAndDropsEmptyOnes) {
  EXPECT_EQ(split_script("takeoff --wait;  task ; ;\tland "),
            (std::vector<std::string>{"takeoff --wait", "task", "land"}));
  EXPECT_TRUE(split_script(" ; ").empty());
}

TEST(AgentsWait, IsTheBringUpPlusTheLongestFirstJoin) {
  EXPECT_DOUBLE_EQ(agents_wait_s(kScenario, 6, false), 90.0);  // agent.rejoin_after_s 40 by default
  const auto dir = temp_dir("wait");
  const auto p = (dir / "s.yaml").string();
  std::ofstream(p) << "scenario:\n  drones: 2\nagent:\n  rejoin_after_s: 10\n";
  EXPECT_DOUBLE_EQ(agents_wait_s(p, 2, false), 45.0);
  std::ofstream(p) << "scenario:\n  drones: 2\nagent:\n  rejoin_after_s: 0\n";
  EXPECT_DOUBLE_EQ(agents_wait_s(p, 2, false), 30.0);  // agents that never join again
  std::filesystem::remove_all(dir);
}

// A secure swarm's agents wait for the scene 1 s per drone at least, and the
// launcher's first wait follows: 30 s + 1.5 x 128 s at 128 drones.
TEST(AgentsWait, FollowsASecureSwarmsLongerSceneWait) {
  EXPECT_DOUBLE_EQ(agents_wait_s(kScenario, 6, true), 90.0);
  EXPECT_DOUBLE_EQ(agents_wait_s(kScenario, 128, false), 90.0);
  EXPECT_DOUBLE_EQ(agents_wait_s(kScenario, 128, true), 222.0);
}

TEST(LaunchApp, RefusesWhatItCannotStartBeforeStartingAnything) {
  EXPECT_THROW(build({kScenario, "--participant-id", "3"}), FieldError);
  EXPECT_THROW(build({kScenario, "--only", "agents", "--drones", "0"}), FieldError);
  EXPECT_THROW(build({kScenario, "--only", "agents", "--ids", "9"}), FieldError);  // 6 drones
  EXPECT_THROW(build({kScenario, "--only", "agents", "--discovery-server", "nowhere"}), FieldError);
}

TEST(LaunchApp, ABadSetIsNamedAndItsCopyRemovedBeforeAnythingStarts) {
  const auto dir = temp_dir("tmp");
  const char* tmpdir = std::getenv("TMPDIR");
  const std::string old_tmpdir = tmpdir ? tmpdir : "";
  setenv("TMPDIR", dir.c_str(), 1);
  try {
    build({kScenario, "--only", "agents", "--set", "agent.inter_distance_m=-1"});
    ADD_FAILURE() << "a launch with a bad --set was built";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "--set agent.inter_distance_m=-1: must be > 0");
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir)) << "the scenario's copy was left behind";
  {
    auto launch = build({kScenario, "--only", "agents", "--set", "agent.inter_distance_m=3"});
    EXPECT_EQ(std::filesystem::path(launch->scenario()).parent_path(), dir);
    EXPECT_TRUE(std::filesystem::exists(launch->scenario()));
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir)) << "the scenario's copy outlived the launch";
  if (old_tmpdir.empty())
    unsetenv("TMPDIR");
  else
    setenv("TMPDIR", old_tmpdir.c_str(), 1);
  std::filesystem::remove_all(dir);
}

TEST(LaunchApp, StopEndsTheRunAndStopsItsProcesses) {
  // One agent, on a domain of its own: it waits for a server that never comes.
  const auto dir = temp_dir("stop");
  const int domain = 100 + static_cast<int>(random_instance() % 20);
  auto launch = build({kScenario, "--only", "agents", "--ids", "0", "--domain",
                       std::to_string(domain), "--log-dir", dir.string()});
  std::thread stopper([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(1500));
    launch->stop();
  });
  const double t0 = wall_seconds();
  const int rc = launch->run();
  const double took = wall_seconds() - t0;
  stopper.join();
  EXPECT_EQ(rc, 0);  // stopped, nothing died
  EXPECT_TRUE(launch->stopping());
  EXPECT_LT(took, 10.0);
  EXPECT_TRUE(std::filesystem::exists(dir / "agent_0.log")) << "the agent's log";
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace ddswarm::gs
