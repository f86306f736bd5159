#pragma once
// Two experiments side by side (`ddswarm-gs compare`): did a change (a
// physics rate, a law, a build) move a set's results beyond the spread of its
// runs? Per set: the mean task time of each, Welch's t of the difference and
// whether it passes the two-sided 5 % level; the Mann–Whitney rank test of
// the same times, which needs no normal distribution (a run stuck behind a
// pillar is an outlier that moves a mean and its spread a lot, a rank little);
// and, for runs with the same
// seed in both, how far single runs moved (a swarm is chaotic: a run can move
// by seconds while the set's mean stays put). No DDS, no files but the plot.
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "experiment/report.hpp"

namespace ddswarm::gs {

/// The Mann–Whitney U test of two samples, two-sided.
struct RankTest {
  /// U of the first sample: the pairs it wins, ties counting half.
  double u = std::numeric_limits<double>::quiet_NaN();
  double p = std::numeric_limits<double>::quiet_NaN();  ///< two-sided p (NaN: a sample is empty)
  bool exact = false;  ///< p from the exact distribution of U, not the normal approximation
};

/// Exact p when there are no ties and at most kExactRankTestMax values a
/// side; otherwise the normal approximation with the tie and continuity
/// corrections.
inline constexpr std::size_t kExactRankTestMax = 50;
RankTest mann_whitney(const std::vector<double>& a, const std::vector<double>& b);

struct SetComparison {
  std::string name;
  SetSummary base;         ///< the set in the first experiment (runs == 0: absent there)
  SetSummary other;        ///< the set in the second (runs == 0: absent there)
  double mean_diff_s = 0;  ///< s, other − base mean task time (NaN: a side has no successful run)
  double welch_t = 0;  ///< Welch's t of mean_diff_s (NaN: < 2 successful runs a side, or no spread)
  double welch_df = 0;           ///< its Welch–Satterthwaite degrees of freedom (NaN likewise)
  bool significant = false;      ///< |welch_t| above the two-sided 5 % critical value at welch_df
  RankTest rank;                 ///< Mann–Whitney of the successful runs' task times
  int paired_runs = 0;           ///< runs with the same seed, successful in both
  double paired_mean_abs_s = 0;  ///< s, mean |other − base| task time over those (NaN: none)
  double paired_max_abs_s = 0;   ///< s, the largest such (NaN: none)
};

/// The two-sided 5 % critical value of Student's t with df degrees of freedom
/// (Cornish–Fisher expansion: within 0.3 % of the table from df = 3 up;
/// below 3, the table's values at 1, 2 and 3, linear in 1/df between them).
double t_critical_5pct(double df);

/// Every set of base, in its order, then the sets only other has.
std::vector<SetComparison> compare_sets(const std::vector<RunRecord>& base,
                                        const std::vector<RunRecord>& other);

/// A Markdown table, one row per set: both means ± standard deviations
/// (successful/all runs), the difference, t (df), "same" or "DIFFERENT" at
/// the 5 % level, the rank test's p and its verdict at 5 %, paired runs'
/// mean and largest |difference|, collisions per
/// run and the smallest inter-drone distance of each.
std::string comparison_table(const std::vector<SetComparison>& sets, const std::string& base_label,
                             const std::string& other_label);

/// <dir>/<stem>.png and .svg: per set, each experiment's mean task time with
/// its standard deviation, side by side (one colour per experiment, labels[i]
/// in the key). experiments[i] are summarize() results; sets are placed in
/// the order of the first experiment, then any new ones. Returns the png path;
/// throws std::runtime_error as render_gnuplot() does.
std::string write_comparison_plot(const std::vector<std::vector<SetSummary>>& experiments,
                                  const std::vector<std::string>& labels, const std::string& dir,
                                  const std::string& stem);

}  // namespace ddswarm::gs
