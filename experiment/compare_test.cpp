#include "experiment/compare.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <utility>
#include <vector>

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
  EXPECT_TRUE(std::isnan(c[0].rank.p));
  EXPECT_NE(md.find("| A | 2.00 ± 1.00 s (3/3) | n/a (0/2) | n/a | n/a | n/a | n/a | n/a | none |"),
            std::string::npos)
      << md;
  EXPECT_NE(md.find("| B | 1.50 ± 0.71 s (2/2) | absent |"), std::string::npos) << md;
  EXPECT_NE(md.find("| C | absent | 5.50 ± 0.71 s (2/2) |"), std::string::npos) << md;
}

// Two-sided p of U for a and b by enumerating every split of the pooled
// values (no ties): the definition, against which the exact count is checked.
double brute_force_p(const std::vector<double>& a, const std::vector<double>& b) {
  std::vector<double> pooled = a;
  pooled.insert(pooled.end(), b.begin(), b.end());
  const std::size_t total = pooled.size(), m = a.size();
  const auto u_of = [&](unsigned mask) {
    double u = 0;
    for (std::size_t i = 0; i < total; ++i)
      for (std::size_t j = 0; j < total; ++j)
        if ((mask >> i & 1u) && !(mask >> j & 1u) && pooled[i] > pooled[j]) ++u;
    return u;
  };
  const double observed = u_of((1u << m) - 1);  // a is the first m
  double low = 0, high = 0, all = 0;
  for (unsigned mask = 0; mask < (1u << total); ++mask) {
    if (static_cast<std::size_t>(__builtin_popcount(mask)) != m) continue;
    const double u = u_of(mask);
    all += 1;
    if (u <= observed) low += 1;
    if (u >= observed) high += 1;
  }
  return std::min(1.0, 2 * std::min(low, high) / all);
}

TEST(Compare, RankTestExactForSmallSetsWithoutTies) {
  // Every value of b beats every value of a: U = 0, and only 2 of the
  // C(10, 5) = 252 splits are as extreme.
  const auto r = mann_whitney({1, 2, 3, 4, 5}, {6, 7, 8, 9, 10});
  EXPECT_TRUE(r.exact);
  EXPECT_DOUBLE_EQ(r.u, 0);
  EXPECT_NEAR(r.p, 2.0 / 252, 1e-12);
  for (const auto& [a, b] : std::vector<std::pair<std::vector<double>, std::vector<double>>>{
           {{1, 3, 5, 7, 9}, {2, 4, 6, 8, 10}},
           {{1.5, 9, 2.5, 7}, {3, 4, 6, 8, 10}},
           {{10, 20, 30, 31, 32, 33}, {1, 21, 22, 40, 41}},
           {{5}, {1, 2, 3, 4, 6, 7}}}) {
    const auto t = mann_whitney(a, b);
    EXPECT_TRUE(t.exact);
    EXPECT_NEAR(t.p, brute_force_p(a, b), 1e-12) << "U " << t.u;
    EXPECT_NEAR(mann_whitney(b, a).p, t.p, 1e-12);  // two-sided: the order does not matter
  }
}

TEST(Compare, RankTestWithTiesUsesTheCorrectedNormalApproximation) {
  // U = 4.5 (ties count half); variance 25/12 (11 - 90/90) = 22.083;
  // z = (|4.5 - 12.5| - 0.5) / sqrt(22.083) = 1.596, p = erfc(z / sqrt 2).
  const auto r = mann_whitney({1, 2, 2, 3, 4}, {2, 3, 5, 5, 6});
  EXPECT_FALSE(r.exact);
  EXPECT_DOUBLE_EQ(r.u, 4.5);
  EXPECT_NEAR(r.p, 0.110492, 1e-6);
  const auto same = mann_whitney({3, 3, 3}, {3, 3});
  EXPECT_DOUBLE_EQ(same.p, 1);
  EXPECT_TRUE(std::isnan(mann_whitney({}, {1, 2}).p));
}

// One run stuck for minutes inflates a set's spread so much that Welch's t
// sees nothing, while 15 of its 16 runs are slower than every run of the
// other: the rank test says so.
TEST(Compare, AnOutlierHidesADifferenceFromWelchButNotFromTheRankTest) {
  std::vector<double> fast, slow;
  for (int i = 0; i < 15; ++i) {
    fast.push_back(80 + 0.07 * i);
    slow.push_back(81.5 + 0.07 * i);
  }
  slow.push_back(400);
  const auto c = compare_sets(set_of("Sim 1", fast), set_of("Sim 1", slow));
  ASSERT_EQ(c.size(), 1u);
  EXPECT_FALSE(c[0].significant) << "Welch t " << c[0].welch_t;
  EXPECT_LT(c[0].rank.p, 1e-4);
  const std::string md = comparison_table(c, "a", "b");
  // Welch "same", then the rank test's p (6.65e-09) and "DIFFERENT".
  EXPECT_NE(md.find("| same | 6.65e-09 (exact) | **DIFFERENT** |"), std::string::npos) << md;
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
