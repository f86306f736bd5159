#include "experiment/report.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

namespace ddswarm::gs {
namespace {

namespace fs = std::filesystem;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

/// A fresh directory per test, removed afterwards.
class ReportTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("gs_report_test_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

RunRecord run(const std::string& set, int index, double time, bool ok = true, int obstacle = 0,
              int drone = 0, double min_dist = 2.0) {
  RunRecord r;
  r.set_name = set;
  r.run_index = index;
  r.seed = 1000 + index;
  r.drones = 6;
  r.d_int_m = set == "Sim 2" ? 6 : 4;
  r.speed_mps = set == "Sim 2" ? 1.2 : 0.8;
  r.sensor_function = set == "Sim 2" ? "fs2" : "fs1";
  r.mode = "lockstep";
  r.ok = ok;
  r.failure_reason = ok ? "" : "timeout after 300 s";
  r.task_time_s = time;
  r.wall_time_s = 20.5;
  r.collisions_obstacle = obstacle;
  r.collisions_drone = drone;
  r.min_inter_drone_m = min_dist;
  r.min_clearance_m = 0.75;
  return r;
}

void expect_same(const RunRecord& a, const RunRecord& b) {
  auto same = [](double x, double y) { return (std::isnan(x) && std::isnan(y)) || x == y; };
  EXPECT_EQ(a.set_name, b.set_name);
  EXPECT_EQ(a.run_index, b.run_index);
  EXPECT_EQ(a.seed, b.seed);
  EXPECT_EQ(a.drones, b.drones);
  EXPECT_EQ(a.d_int_m, b.d_int_m);
  EXPECT_EQ(a.speed_mps, b.speed_mps);
  EXPECT_EQ(a.sensor_function, b.sensor_function);
  EXPECT_EQ(a.mode, b.mode);
  EXPECT_EQ(a.ok, b.ok);
  EXPECT_EQ(a.failure_reason, b.failure_reason);
  EXPECT_TRUE(same(a.task_time_s, b.task_time_s)) << a.task_time_s << " vs " << b.task_time_s;
  EXPECT_EQ(a.wall_time_s, b.wall_time_s);
  EXPECT_EQ(a.collisions_obstacle, b.collisions_obstacle);
  EXPECT_EQ(a.collisions_drone, b.collisions_drone);
  EXPECT_EQ(a.collisions_ground, b.collisions_ground);
  EXPECT_TRUE(same(a.min_inter_drone_m, b.min_inter_drone_m));
  EXPECT_TRUE(same(a.min_clearance_m, b.min_clearance_m));
  EXPECT_EQ(a.params, b.params);
  EXPECT_TRUE(same(a.metrics.order_mean, b.metrics.order_mean));
  EXPECT_TRUE(same(a.metrics.order_min, b.metrics.order_min));
  EXPECT_TRUE(same(a.metrics.speed_mean_mps, b.metrics.speed_mean_mps));
  EXPECT_EQ(a.metrics.near_misses, b.metrics.near_misses);
  EXPECT_EQ(a.metrics.components_max, b.metrics.components_max);
  EXPECT_TRUE(same(a.metrics.lambda2_min, b.metrics.lambda2_min));
  EXPECT_TRUE(same(a.metrics.range_m, b.metrics.range_m));
  EXPECT_TRUE(same(a.metrics.near_miss_m, b.metrics.near_miss_m));
}

/// r with swarm metrics as the referee would report them.
RunRecord measured(RunRecord r, double order_mean, double order_min, int near_misses,
                   int components_max = 1, double lambda2_min = 1.5) {
  r.metrics.order_mean = order_mean;
  r.metrics.order_min = order_min;
  r.metrics.speed_mean_mps = 0.75;
  r.metrics.near_misses = near_misses;
  r.metrics.components_max = components_max;
  r.metrics.lambda2_min = lambda2_min;
  r.metrics.range_m = 10;
  r.metrics.near_miss_m = 1;
  return r;
}

TEST_F(ReportTest, CsvRoundTripKeepsAwkwardFieldsExactly) {
  std::vector<RunRecord> rows = {run("Sim 1", 0, 82.6), run("Sim 1", 1, kNaN, false, 2, 1, kInf),
                                 run("Sim 1", 2, 0.1 + 0.2)};
  rows[0].set_name = "Sim, \"quoted\" 1";
  rows[0].failure_reason = " leading space, a comma\nand a second line ";
  rows[0].params = {{"agent.sensor_function.type", "fs1"}, {"odd;key=", "a\\b;c=d"}, {"empty", ""}};
  rows[1].seed = std::numeric_limits<std::uint64_t>::max();
  rows[1].collisions_ground = 3;
  rows[2].failure_reason = "\"";
  rows[2] = measured(rows[2], 0.1 + 0.7, -1.0 / 3.0, 4, 2, 0.0);
  for (const auto& r : rows) append_csv(path("runs.csv"), r);

  const auto back = read_csv(path("runs.csv"));
  ASSERT_EQ(back.size(), rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    SCOPED_TRACE(i);
    expect_same(back[i], rows[i]);
  }
}

TEST_F(ReportTest, AppendWritesOneHeaderAndEveryRow) {
  for (int i = 0; i < 25; ++i)
    append_csv(path("runs.csv"), run(i < 15 ? "Sim 1" : "Sim 2", i, 80 + i));
  const auto back = read_csv(path("runs.csv"));
  ASSERT_EQ(back.size(), 25u);
  for (int i = 0; i < 25; ++i) EXPECT_EQ(back[i].run_index, i);
  const std::string text = slurp(path("runs.csv"));
  EXPECT_EQ(text.find("set_name,"), 0u);
  EXPECT_EQ(text.find("set_name,", 1), std::string::npos);
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 26);
}

// The swarm metrics come after params: scripts that read the older columns by
// position (tests/experiment_test.sh) keep reading the same ones, and a CSV
// written before the metrics still reads, its runs not measured.
TEST_F(ReportTest, SwarmMetricColumnsFollowTheOlderOnesAndMayBeMissing) {
  append_csv(path("runs.csv"), measured(run("Sim 1", 0, 80), 0.9, 0.2, 3));
  const std::string text = slurp(path("runs.csv"));
  const std::string header = text.substr(0, text.find('\n'));
  EXPECT_EQ(header.find("set_name,run_index,seed,drones,d_int_m,speed_mps,sensor_function,mode,ok,"
                        "failure_reason,task_time_s,wall_time_s,collisions_obstacle,"
                        "collisions_drone,collisions_ground,min_inter_drone_m,min_clearance_m,"
                        "params,order_mean,order_min,speed_mean_mps,near_misses,components_max,"
                        "lambda2_min,metrics_range_m,near_miss_m"),
            0u)
      << header;
  EXPECT_NE(text.find(",0.9,0.2,0.75,3,1,1.5,10,1\n"), std::string::npos) << text;

  const std::string old = path("old.csv");
  std::ofstream(old) << header.substr(0, header.find(",order_mean")) << "\n"
                     << "Sim 1,0,1,6,4,0.8,fs1,lockstep,1,,82.6,20,0,0,0,1.9,0.8,\n";
  const auto back = read_csv(old);
  ASSERT_EQ(back.size(), 1u);
  EXPECT_EQ(back[0].task_time_s, 82.6);
  EXPECT_TRUE(std::isnan(back[0].metrics.order_mean));
  EXPECT_EQ(back[0].metrics.near_misses, 0u);
  EXPECT_EQ(summarize(back)[0].metrics_runs, 0);
  // Appending to it would mix two layouts under one header: refused.
  EXPECT_THROW(append_csv(old, run("Sim 1", 1, 80)), std::runtime_error);
}

TEST_F(ReportTest, AppendDoesNotMergeWithACutShortRow) {
  append_csv(path("runs.csv"), run("Sim 1", 0, 80));
  { std::ofstream(path("runs.csv"), std::ios::app) << "Sim 1,1,10"; }  // a crash mid-row
  append_csv(path("runs.csv"), run("Sim 1", 2, 81));
  const std::string text = slurp(path("runs.csv"));
  EXPECT_NE(text.find("Sim 1,1,10\nSim 1,2,"), std::string::npos);
  try {
    read_csv(path("runs.csv"));
    FAIL() << "a short row must be reported";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("runs.csv:3: expected 26 fields, found 3"),
              std::string::npos)
        << e.what();
  }
}

TEST_F(ReportTest, AppendRefusesAForeignFileAndUnwritablePaths) {
  { std::ofstream(path("other.csv")) << "a,b,c\n1,2,3\n"; }
  try {
    append_csv(path("other.csv"), run("Sim 1", 0, 80));
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path("other.csv") + ": not a ddswarm run CSV"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(slurp(path("other.csv")), "a,b,c\n1,2,3\n");  // untouched

  const std::string missing = path("no/such/dir/runs.csv");
  try {
    append_csv(missing, run("Sim 1", 0, 80));
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(missing + ": cannot open"), std::string::npos);
  }
}

TEST_F(ReportTest, ReadCsvNamesTheFileAndTheProblem) {
  EXPECT_THROW(read_csv(path("absent.csv")), std::runtime_error);
  { std::ofstream(path("cols.csv")) << "set_name,run_index\nSim 1,0\n"; }
  try {
    read_csv(path("cols.csv"));
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cols.csv:1: missing column 'seed'"), std::string::npos)
        << e.what();
  }
  append_csv(path("bad.csv"), run("Sim 1", 0, 80));
  std::string text = slurp(path("bad.csv"));
  text.replace(text.find(",lockstep,1,"), 12, ",lockstep,yes,");
  { std::ofstream(path("bad.csv"), std::ios::trunc) << text; }
  try {
    read_csv(path("bad.csv"));
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.csv:2: ok = 'yes'"), std::string::npos) << e.what();
  }
}

std::vector<RunRecord> two_sets() {
  // Sim 1: times 80, 82, 86 and one failed run; collisions 0, 1, 1, 3.
  // Sim 2 interleaved: times 59, 61.
  return {run("Sim 1", 0, 80, true, 0, 0, 2.5), run("Sim 2", 0, 59),
          run("Sim 1", 1, 82, true, 1, 0, 1.9), run("Sim 1", 2, 86, true, 0, 1, 3.0),
          run("Sim 2", 1, 61, true, 0, 0, 1.5), run("Sim 1", 3, kNaN, false, 2, 0, kNaN)};
}

TEST(Summary, MeanAndSampleStddevOverSuccessfulRuns) {
  auto records = two_sets();
  records[5].collisions_ground = 1;
  const auto s = summarize(records);
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[0].name, "Sim 1");  // order of first appearance
  EXPECT_EQ(s[1].name, "Sim 2");

  EXPECT_EQ(s[0].runs, 4);
  EXPECT_EQ(s[0].failures, 1);
  EXPECT_NEAR(s[0].mean_time_s, 248.0 / 3.0, 1e-12);
  // deviations -8/3, -2/3, 10/3: (64 + 4 + 100) / 9 / (3 - 1) = 28/3
  EXPECT_NEAR(s[0].stddev_time_s, std::sqrt(28.0 / 3.0), 1e-12);
  EXPECT_EQ(s[0].min_time_s, 80);
  EXPECT_EQ(s[0].max_time_s, 86);
  EXPECT_NEAR(s[0].mean_collisions, 5.0 / 4.0, 1e-12);  // 0 + 1 + 1 + (2 + 1)
  EXPECT_NEAR(s[0].mean_collisions_obstacle, 3.0 / 4.0, 1e-12);
  EXPECT_NEAR(s[0].mean_collisions_drone, 1.0 / 4.0, 1e-12);
  EXPECT_NEAR(s[0].mean_collisions_ground, 1.0 / 4.0, 1e-12);
  EXPECT_EQ(s[0].min_inter_drone_m, 1.9);  // the failed run's NaN is ignored
  EXPECT_EQ(s[0].drones, 6);
  EXPECT_EQ(s[0].d_int_m, 4);
  EXPECT_EQ(s[0].sensor_function, "fs1");
  EXPECT_TRUE(s[0].consistent);

  EXPECT_EQ(s[1].runs, 2);
  EXPECT_EQ(s[1].failures, 0);
  EXPECT_DOUBLE_EQ(s[1].mean_time_s, 60.0);
  EXPECT_DOUBLE_EQ(s[1].stddev_time_s, std::sqrt(2.0));
  EXPECT_EQ(s[1].mean_collisions, 0);
  EXPECT_EQ(s[1].min_inter_drone_m, 1.5);
}

TEST(Summary, SwarmMetricsPerSetOverTheRunsThatMeasuredThem) {
  auto records = two_sets();
  records[0] = measured(records[0], 0.9, 0.5, 2);
  records[2] = measured(records[2], 0.7, -0.1, 1, 3, 0.0);
  records[3] = measured(records[3], 0.8, 0.3, 0);
  // records[5] (Sim 1's failed run) measured nothing; Sim 2 none at all.
  const auto s = summarize(records);
  EXPECT_EQ(s[0].metrics_runs, 3);
  EXPECT_NEAR(s[0].mean_order, 0.8, 1e-12);
  EXPECT_EQ(s[0].min_order, -0.1);
  EXPECT_NEAR(s[0].mean_near_misses, 1.0, 1e-12);
  EXPECT_EQ(s[0].mean_speed_mps, 0.75);
  EXPECT_EQ(s[0].max_components, 3);
  EXPECT_EQ(s[0].min_lambda2, 0.0);
  EXPECT_EQ(s[1].metrics_runs, 0);
  EXPECT_TRUE(std::isnan(s[1].mean_order));
  EXPECT_TRUE(std::isnan(s[1].min_lambda2));
  EXPECT_EQ(metrics_table(s),
            "| | Sim 1 | Sim 2 |\n"
            "|---|---|---|\n"
            "| Avg. order | 0.800 | n/a |\n"
            "| Min. order | -0.100 | n/a |\n"
            "| Avg. speed | 0.75m/s | n/a |\n"
            "| Avg. near misses | 1.00 | n/a |\n"
            "| Max. components | 3 | n/a |\n"
            "| Min. algebraic connectivity | 0.00 | n/a |\n"
            "| Runs measured | 3/4 | 0/2 |\n");
  // Table 1 itself is unchanged by them.
  EXPECT_EQ(markdown_table(s), markdown_table(summarize(two_sets())));
  EXPECT_EQ(metrics_table(summarize(two_sets())), "");
}

TEST(Summary, TooFewRunsGiveNaNAndMixedSettingsAreFlagged) {
  auto records = std::vector<RunRecord>{run("Sim 1", 0, 80), run("Sim 1", 1, kNaN, false)};
  auto s = summarize(records);
  EXPECT_EQ(s[0].mean_time_s, 80);
  EXPECT_TRUE(std::isnan(s[0].stddev_time_s));
  records[0].ok = false;
  s = summarize(records);
  EXPECT_TRUE(std::isnan(s[0].mean_time_s));
  EXPECT_EQ(s[0].failures, 2);
  records[1].d_int_m = 6;
  EXPECT_FALSE(summarize(records)[0].consistent);
  EXPECT_TRUE(summarize({}).empty());
}

TEST(Summary, MarkdownTableHasTable1Layout) {
  const std::string md = markdown_table(summarize(two_sets()));
  EXPECT_EQ(md,
            "| | Sim 1 | Sim 2 |\n"
            "|---|---|---|\n"
            "| Drones nr | 6 | 6 |\n"
            "| Inter-distance | 4m | 6m |\n"
            "| Velocity | 0.8m/s | 1.2m/s |\n"
            "| Sensor Function | fs1 | fs2 |\n"
            "| Avg. task time | 82.7s | 60.0s |\n"
            "| Standard deviation | 3.06s | 1.41s |\n"
            "| Avg. collisions | 1.00 | 0.00 |\n"
            "| Min. inter-drone distance | 1.90m | 1.50m |\n"
            "| Failures | 1/4 | 0/2 |\n");
}

TEST(Summary, MarkdownTableMarksMissingValuesAndEscapesPipes) {
  auto records = std::vector<RunRecord>{run("a|b", 0, kNaN, false, 0, 0, kInf)};
  records[0].d_int_m = 5;
  records.push_back(records[0]);
  records[1].d_int_m = 4;
  const std::string md = markdown_table(summarize(records));
  EXPECT_NE(md.find("| | a\\|b |\n"), std::string::npos) << md;
  EXPECT_NE(md.find("| Avg. task time | n/a |"), std::string::npos) << md;
  EXPECT_NE(md.find("| Min. inter-drone distance | n/a |"), std::string::npos) << md;
  EXPECT_NE(md.find("| Inter-distance | 5m\\* |"), std::string::npos) << md;
  EXPECT_NE(md.find("\\* runs of this set used different values"), std::string::npos) << md;
}

TEST(Plots, StemsAreFileSafe) {
  EXPECT_EQ(plot_stem("Sim 1"), "sim_1");
  EXPECT_EQ(plot_stem("  Sim/2: fast!  "), "sim_2_fast");
  EXPECT_EQ(plot_stem("../.."), "set");
}

bool have_gnuplot() { return std::system("command -v gnuplot >/dev/null 2>&1") == 0; }

TEST_F(ReportTest, PlotsEveryRunOfEachSetAsPngAndSvg) {
  if (!have_gnuplot()) GTEST_SKIP() << "gnuplot is not installed";
  auto records = two_sets();
  records.push_back(run("sim_1", 0, kNaN, false));  // same stem as "Sim 1", no successful run
  const auto pngs = write_plots(records, path("plots"));
  ASSERT_EQ(pngs.size(), 4u) << "one plot per set, then the summary of all sets";
  EXPECT_EQ(pngs[0], path("plots/sim_1.png"));
  EXPECT_EQ(pngs[1], path("plots/sim_2.png"));
  EXPECT_EQ(pngs[2], path("plots/sim_1_2.png"));
  EXPECT_EQ(pngs[3], path("plots/summary.png"));
  // The summary has one bar per set, labelled with the set's name.
  const std::string summary = slurp(path("plots/summary.dat"));
  EXPECT_NE(summary.find("\"Sim 1\""), std::string::npos) << summary;
  EXPECT_NE(summary.find("\"Sim 2\""), std::string::npos) << summary;
  for (const std::string stem : {"sim_1", "sim_2", "sim_1_2", "summary"}) {
    SCOPED_TRACE(stem);
    const std::string base = path("plots/" + stem);
    EXPECT_EQ(slurp(base + ".png").substr(0, 8), "\x89PNG\r\n\x1a\n");
    EXPECT_NE(slurp(base + ".svg").find("<svg"), std::string::npos);
    EXPECT_TRUE(fs::exists(base + ".gp"));
    EXPECT_FALSE(fs::exists(base + ".log"));
  }
  // One data line per run: 4 runs of Sim 1, the failed one as NaN.
  const std::string dat = slurp(path("plots/sim_1.dat"));
  EXPECT_NE(dat.find("\n1 80 NaN 0 1\n2 82 82 1 1\n3 86 86 1 1\n4 NaN NaN 2 0\n"),
            std::string::npos)
      << dat;
}

TEST_F(ReportTest, MetricsPlotShowsOrderAndClosestApproachPerSet) {
  if (!have_gnuplot()) GTEST_SKIP() << "gnuplot is not installed";
  auto records = two_sets();
  records[0] = measured(records[0], 0.9, 0.5, 2);
  records[2] = measured(records[2], 0.7, -0.1, 1);
  records[1] = measured(records[1], 0.95, 0.8, 0);
  const auto pngs = write_plots(records, path("plots"));
  ASSERT_EQ(pngs.size(), 4u) << "one plot per set, the summary, then the metrics";
  EXPECT_EQ(pngs[3], path("plots/metrics.png"));
  EXPECT_EQ(slurp(path("plots/metrics.png")).substr(0, 8), "\x89PNG\r\n\x1a\n");
  EXPECT_NE(slurp(path("plots/metrics.svg")).find("<svg"), std::string::npos);
  // Sim 1: mean order of its 2 measured runs 0.8, lowest -0.1, closest 1.9 m,
  // 1.5 near misses per run; Sim 2: 0.95, 0.8, 1.5 m, 0.
  EXPECT_EQ(slurp(path("plots/metrics.dat")),
            "# index mean_order min_order min_inter_drone_m mean_near_misses name\n"
            "0 0.8 -0.1 1.9 1.5 \"Sim 1\"\n"
            "1 0.95 0.8 1.5 0 \"Sim 2\"\n");
}

// Every run failed (e.g. a swarm that never came up): each set's plot still
// shows its failed runs; the summary, with no mean to draw, is left out
// instead of failing the whole report.
TEST_F(ReportTest, EveryRunFailedPlotsTheSetsWithoutASummary) {
  if (!have_gnuplot()) GTEST_SKIP() << "gnuplot is not installed";
  const auto pngs =
      write_plots({run("Sim 1", 0, kNaN, false), run("Sim 2", 0, kNaN, false)}, path("plots"));
  ASSERT_EQ(pngs.size(), 2u);
  EXPECT_EQ(pngs[1], path("plots/sim_2.png"));
  EXPECT_FALSE(fs::exists(path("plots/summary.png")));
}

TEST_F(ReportTest, PlotFailureReportsGnuplotsMessage) {
  if (!have_gnuplot()) GTEST_SKIP() << "gnuplot is not installed";
  // A directory where the png should go makes gnuplot fail to open its output.
  fs::create_directories(path("plots/sim_1.png/blocker"));
  try {
    write_plots({run("Sim 1", 0, 80)}, path("plots"));
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("sim_1"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace ddswarm::gs
