#include "ground_station/compare.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>

namespace ddswarm::gs {
namespace {

namespace fs = std::filesystem;

RunRecord run(const std::string& set, int index, double time, bool ok = true) {
  RunRecord r;
  r.set_name = set;
  r.run_index = index;
  r.seed = 1000 + static_cast<std::uint64_t>(index);
  r.drones = 6;
  r.ok = ok;
  r.task_time_s = ok ? time : std::nan("");
  return r;
}

std::vector<RunRecord> set_of(const std::string& set, const std::vector<double>& times) {
  std::vector<RunRecord> out;
  for (std::size_t i = 0; i < times.size(); ++i)
    out.push_back(run(set, static_cast<int>(i), times[i]));
  return out;
}

TEST(Compare, CriticalValuesMatchStudentsTable) {
  // Two-sided 5 %: the textbook table.
  EXPECT_NEAR(t_critical_5pct(1), 12.706, 0.001);  // two runs a side can give df near 1
  EXPECT_NEAR(t_critical_5pct(2), 4.303, 0.001);
  EXPECT_NEAR(t_critical_5pct(2.999), 3.182, 0.01);
  EXPECT_NEAR(t_critical_5pct(3), 3.182, 0.01);
  EXPECT_NEAR(t_critical_5pct(10), 2.228, 0.002);
  EXPECT_NEAR(t_critical_5pct(28), 2.048, 0.001);
  EXPECT_NEAR(t_critical_5pct(1e6), 1.960, 0.001);
  EXPECT_TRUE(std::isnan(t_critical_5pct(0)));
}

TEST(Compare, WelchTOfAKnownPair) {
  // a: mean 2, variance 1 (n 3); b: mean 5, variance 1 (n 3): t = 3 / sqrt(2/3), df = 4.
  const auto c = compare_sets(set_of("S", {1, 2, 3}), set_of("S", {4, 5, 6}));
  ASSERT_EQ(c.size(), 1u);
  EXPECT_DOUBLE_EQ(c[0].mean_diff_s, 3);
  EXPECT_NEAR(c[0].welch_t, 3 / std::sqrt(2.0 / 3), 1e-12);
  EXPECT_NEAR(c[0].welch_df, 4, 1e-12);
  EXPECT_TRUE(c[0].significant);  // 3.67 > 2.776
  EXPECT_EQ(c[0].paired_runs, 3);
  EXPECT_DOUBLE_EQ(c[0].paired_mean_abs_s, 3);
  EXPECT_DOUBLE_EQ(c[0].paired_max_abs_s, 3);
}

// A swarm is chaotic: single runs move by seconds while the mean stays put.
// That is "same", and the table says how far single runs moved.
TEST(Compare, ShuffledRunsAreTheSameSetWithLargePairedMoves) {
  const std::vector<double> a = {80, 82, 81, 79, 83, 80.5, 81.5, 82.5};
  const std::vector<double> b = {83, 79, 80.5, 82.5, 80, 82, 81, 81.5};
  const auto c = compare_sets(set_of("Sim 1", a), set_of("Sim 1", b));
  ASSERT_EQ(c.size(), 1u);
  EXPECT_NEAR(c[0].mean_diff_s, 0, 1e-9);
  EXPECT_FALSE(c[0].significant);
  EXPECT_GT(c[0].paired_max_abs_s, 3);
  const std::string md = comparison_table(c, "1 kHz", "250 Hz");
  EXPECT_NE(
      md.find(
          "| Sim 1 | 81.19 ± 1.33 s (8/8) | 81.19 ± 1.33 s (8/8) | +0.00 s | +0.00 (14) | same |"),
      std::string::npos)
      << md;
}

TEST(Compare, ASetMissingOrWithoutSuccessfulRunsIsNotTested) {
  auto base = set_of("A", {1, 2, 3});
  auto b = set_of("B", {1, 2});
  base.insert(base.end(), b.begin(), b.end());
  std::vector<RunRecord> other = {run("A", 0, 0, false), run("A", 1, 0, false)};
  auto c2 = set_of("C", {5, 6});
  other.insert(other.end(), c2.begin(), c2.end());
  const auto c = compare_sets(base, other);
  ASSERT_EQ(c.size(), 3u);
  EXPECT_EQ(c[0].name, "A");
  EXPECT_TRUE(std::isnan(c[0].mean_diff_s));
  EXPECT_TRUE(std::isnan(c[0].welch_t));
  EXPECT_FALSE(c[0].significant);
  EXPECT_EQ(c[0].paired_runs, 0);
  EXPECT_EQ(c[1].name, "B");
  EXPECT_EQ(c[1].other.runs, 0);
  EXPECT_EQ(c[2].name, "C");  // only in the second, listed last
  EXPECT_EQ(c[2].base.runs, 0);
  const std::string md = comparison_table(c, "base", "other");
  EXPECT_NE(md.find("| A | 2.00 ± 1.00 s (3/3) | n/a (0/2) | n/a | n/a | n/a | none |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| B | 1.50 ± 0.71 s (2/2) | absent |"), std::string::npos) << md;
  EXPECT_NE(md.find("| C | absent | 5.50 ± 0.71 s (2/2) |"), std::string::npos) << md;
}

TEST(Compare, PlotsEverySetOfEveryExperiment) {
  const fs::path dir =
      fs::temp_directory_path() / ("gs_compare_test_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const auto a = summarize(set_of("Sim 1", {80, 82, 81}));
  auto bruns = set_of("Sim 1", {70, 72});
  auto b2 = set_of("Sim 2", {50, 52});
  bruns.insert(bruns.end(), b2.begin(), b2.end());
  const auto b = summarize(bruns);
  EXPECT_THROW(write_comparison_plot({a, b}, {"one"}, dir.string(), "cmp"), std::invalid_argument);
  const std::string png = write_comparison_plot({a, b}, {"1 kHz", "250 Hz"}, dir.string(), "cmp");
  EXPECT_EQ(png, (dir / "cmp.png").string());
  EXPECT_GT(fs::file_size(png), 1000u);
  EXPECT_GT(fs::file_size(dir / "cmp.svg"), 1000u);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace ddswarm::gs
