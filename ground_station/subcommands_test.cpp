#include "ground_station/subcommands.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <thread>

#include "common/config_error.hpp"
#include "common/participant.hpp"
#include "common/process.hpp"
#include "experiment/report.hpp"
#include "ground_station/growing_wait.hpp"
#include "ground_station/trace.hpp"
#include "ground_station/web/web_bridge.hpp"

namespace ddswarm::gs {
namespace {

std::filesystem::path temp_dir(const std::string& name) {
  auto d = std::filesystem::temp_directory_path() /
           ("gs_subcommands_test_" + std::to_string(getpid()) + "_" + name);
  std::filesystem::remove_all(d);
  std::filesystem::create_directories(d);
  return d;
}

bool parse(CLI::App& app, std::vector<std::string> args) {
  std::reverse(args.begin(), args.end());  // CLI11 takes them last first
  try {
    app.parse(args);
    return true;
  } catch (const CLI::ParseError&) {
    return false;
  }
}

TEST(GsCommandLine, BindsEachSubcommandsOptions) {
  CLI::App app;
  GsCommandLine cl;
  add_gs_command_line(app, cl);
  ASSERT_TRUE(
      parse(app, {"--config", "s.yaml", "task", "--speed", "1.2", "--csv", "r.csv", "--takeoff"}));
  EXPECT_EQ(cl.config, "s.yaml");
  EXPECT_TRUE(*cl.task);
  EXPECT_FALSE(*cl.move);
  EXPECT_DOUBLE_EQ(cl.speed, 1.2);
  EXPECT_EQ(cl.csv, "r.csv");
  EXPECT_TRUE(cl.fly);
  EXPECT_FALSE(cl.attach);
  EXPECT_EQ(cl.out_dir, "results");  // untouched defaults
  EXPECT_EQ(cl.trace_every, 5);
}

TEST(GsCommandLine, RefusesTwoSubcommandsAndOutOfRangeValues) {
  {
    CLI::App app;
    GsCommandLine cl;
    add_gs_command_line(app, cl);
    EXPECT_FALSE(parse(app, {"land", "status"}));
  }
  {
    CLI::App app;
    GsCommandLine cl;
    add_gs_command_line(app, cl);
    EXPECT_FALSE(parse(app, {"move", "--north", "51", "--time", "1"}));
  }
  {
    CLI::App app;
    GsCommandLine cl;
    add_gs_command_line(app, cl);
    EXPECT_FALSE(parse(app, {"move", "--north", "1"}));  // --time is required
  }
}

TaskOutcome outcome(bool ok, double task_time_s) {
  TaskOutcome o;
  o.ok = ok;
  o.task_time_s = task_time_s;
  o.speed_mps = 0.8;
  o.seed = 7;
  if (!ok) o.reason = "timeout";
  return o;
}

TEST(AppendResult, WritesOneRowPerTaskAndNothingWithoutAFile) {
  const auto dir = temp_dir("append");
  const std::string csv = (dir / "r.csv").string();
  append_result("", outcome(true, 80.0), 6);  // no file named: nothing to do
  append_result(csv, outcome(true, 81.06), 6);
  append_result(csv, outcome(false, 12.0), 6);
  const auto rows = read_csv(csv);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].set_name, "cli");  // a task with no scenario name
  EXPECT_EQ(rows[0].drones, 6);
  EXPECT_EQ(rows[0].seed, 7u);
  EXPECT_TRUE(rows[0].ok);
  EXPECT_NEAR(rows[0].task_time_s, 81.06, 1e-9);
  EXPECT_FALSE(rows[1].ok);
  EXPECT_EQ(rows[1].failure_reason, "timeout");
  EXPECT_TRUE(std::isnan(rows[1].task_time_s));  // a failed run has no task time
  std::filesystem::remove_all(dir);
}

TEST(CompareExperiments, SameRunsDoNotDifferAndBadArgumentsAreRefused) {
  const auto dir = temp_dir("compare");
  const std::string a = (dir / "a.csv").string(), b = (dir / "b.csv").string();
  for (const auto& f : {a, b})
    for (int k = 0; k < 5; ++k) append_result(f, outcome(true, 80.0 + k), 6);
  testing::internal::CaptureStdout();
  const int rc = compare_experiments({a, b}, {"base", "new"}, "", true);
  const std::string out = testing::internal::GetCapturedStdout();
  EXPECT_EQ(rc, 0);
  EXPECT_NE(out.find("new against base:"), std::string::npos) << out;
  EXPECT_THROW(compare_experiments({a}, {}, "", false), FieldError);
  EXPECT_THROW(compare_experiments({a, b}, {"only one"}, "", false), FieldError);
  EXPECT_THROW(compare_experiments({a, (dir / "missing.csv").string()}, {}, "", false),
               ConfigError);
  std::filesystem::remove_all(dir);
}

/// A random DDS domain in 80-99 (as dds_commander_test: apart from the other unit tests').
int random_test_domain() { return 95 + static_cast<int>(random_instance() % 5); }

// Past its timeout a wait goes on while the count reaches new highs, for
// the grace after each; a count that never rose, or stopped rising, ends it.
TEST(GrowingWait, WaitsOnWhileTheCountGrows) {
  GrowingWait w(0.0, 90.0, 30.0);
  EXPECT_DOUBLE_EQ(w.until_s(), 90.0);
  w.saw(-1, 10.0);  // no server
  w.saw(20, 50.0);  // where it starts from
  EXPECT_DOUBLE_EQ(w.until_s(), 90.0);
  w.saw(40, 80.0);
  EXPECT_DOUBLE_EQ(w.until_s(), 110.0);
  EXPECT_FALSE(w.past_timeout(89.0));
  EXPECT_TRUE(w.past_timeout(100.0));
  w.saw(40, 100.0);  // the same count is no growth
  EXPECT_DOUBLE_EQ(w.until_s(), 110.0);
  w.saw(35, 105.0);  // agents that left and join again
  w.saw(39, 107.0);  // ... and come back: below the high, no growth
  EXPECT_DOUBLE_EQ(w.until_s(), 110.0);
  w.saw(90, 108.0);
  EXPECT_DOUBLE_EQ(w.until_s(), 138.0);
  GrowingWait early(0.0, 90.0, 30.0);
  early.saw(3, 5.0);
  early.saw(128, 10.0);  // growth long before the timeout does not shorten it
  EXPECT_DOUBLE_EQ(early.until_s(), 90.0);
  GrowingWait flat(0.0, 11.0, 30.0);
  flat.saw(3, 10.0);  // 3 of 4 from the first look: nothing more is coming
  EXPECT_DOUBLE_EQ(flat.until_s(), 11.0);
}

TEST(WaitAgents, WithNoServerTimesOutSayingWhoseViewItIs) {
  DdsConfig dds;
  dds.domain_id = random_test_domain();
  DdsCommander gs(GroundStationConfig{}, dds);
  testing::internal::CaptureStdout();
  const double t0 = wall_seconds();
  const int rc = wait_agents_command(gs, 3, 0.3);
  const double took = wall_seconds() - t0;
  const std::string out = testing::internal::GetCapturedStdout();
  EXPECT_EQ(rc, 1);
  EXPECT_LT(took, 5.0);
  EXPECT_EQ(
      out,
      "timed out after 0.3 s: no server heard (this ground station hears 0/0 agents online)\n");
}

// The ground station's long-running applications end on their own stop(),
// from another thread, as a test hosting them in one process ends them.
TEST(WebBridge, StopEndsTheServing) {
  web::WebBridgeOptions o;
  web::parse_listen_address("127.0.0.1:0", o.server);
  o.server.web_root = web::default_web_root();
  o.dds.domain_id = random_test_domain();
  web::WebBridge bridge(o);
  std::thread stopper([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    bridge.stop();
  });
  const double t0 = wall_seconds();
  const auto counts = bridge.run();
  stopper.join();
  EXPECT_LT(wall_seconds() - t0, 5.0);
  EXPECT_EQ(counts.clients, 0u);
  EXPECT_FALSE(stop_requested());  // this bridge alone stopped
}

TEST(SwarmTrace, StopEndsTheTrace) {
  const auto dir = temp_dir("trace");
  DdsConfig dds;
  dds.domain_id = random_test_domain();
  SwarmTrace t(dds, (dir / "t.csv").string(), 1);
  std::thread stopper([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    t.stop();
  });
  const double t0 = wall_seconds();
  t.run(0);  // 0: until stopped
  stopper.join();
  EXPECT_LT(wall_seconds() - t0, 5.0);
  EXPECT_EQ(t.rows(), 0);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace ddswarm::gs
