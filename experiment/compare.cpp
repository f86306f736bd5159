#include "experiment/compare.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

namespace ddswarm::gs {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// A successful run of set, with a task time.
bool succeeded_in(const RunRecord& r, const std::string& set) {
  return r.set_name == set && r.ok && std::isfinite(r.task_time_s);
}

/// Successful runs' task times by seed, for one set.
std::map<std::uint64_t, double> times_by_seed(const std::vector<RunRecord>& records,
                                              const std::string& set) {
  std::map<std::uint64_t, double> out;
  for (const auto& r : records)
    if (succeeded_in(r, set)) out[r.seed] = r.task_time_s;
  return out;
}

/// Successful runs' task times of one set, every run.
std::vector<double> successful_times(const std::vector<RunRecord>& records,
                                     const std::string& set) {
  std::vector<double> out;
  for (const auto& r : records)
    if (succeeded_in(r, set)) out.push_back(r.task_time_s);
  return out;
}

/// P(U <= u) for samples of m and n values without ties, every arrangement
/// of the pooled ranks equally likely. count[i][k]: the arrangements of i
/// values of the first sample and j of the second with U = k, built up over
/// j (the largest value is either the first's, beating all j, or not).
double exact_u_cdf(std::size_t m, std::size_t n, double u) {
  const std::size_t top = m * n;
  std::vector<std::vector<double>> count(m + 1, std::vector<double>(top + 1, 0.0));
  for (auto& c : count) c[0] = 1;  // j = 0: one arrangement, U = 0
  for (std::size_t j = 1; j <= n; ++j)
    for (std::size_t i = 1; i <= m; ++i)
      for (std::size_t k = top + 1; k-- > j;) count[i][k] += count[i - 1][k - j];
  double below = 0, all = 0;
  for (std::size_t k = 0; k <= top; ++k) {
    all += count[m][k];
    if (static_cast<double>(k) <= u + 1e-9) below += count[m][k];
  }
  return below / all;
}

/// A test's verdict at 5 % in the table: "n/a" when it could not be run.
const char* verdict(bool tested, bool different) {
  return !tested ? "n/a" : different ? "**DIFFERENT**" : "same";
}

std::string mean_sd(const SetSummary& s) {
  if (s.runs == 0) return "absent";
  const int ok = s.successes;
  if (!std::isfinite(s.mean_time_s)) return fmt::format("n/a ({}/{})", ok, s.runs);
  if (!std::isfinite(s.stddev_time_s))
    return fmt::format("{:.2f} s ({}/{})", s.mean_time_s, ok, s.runs);
  return fmt::format("{:.2f} ± {:.2f} s ({}/{})", s.mean_time_s, s.stddev_time_s, ok, s.runs);
}

std::string or_na(double v, const char* format) {
  return std::isfinite(v) ? fmt::format(fmt::runtime(format), v) : "n/a";
}

std::string md_text(const std::string& s) {
  std::string out;
  for (char c : s) out += (c == '|') ? std::string("\\|") : std::string(1, c == '\n' ? ' ' : c);
  return out;
}

}  // namespace

double t_critical_5pct(double df) {
  if (!(df > 0)) return kNaN;
  // Below 3 degrees of freedom (two runs a side) the expansion is far too
  // low: the table's values, linear in 1/df between them.
  if (df < 3) {
    const double inv = 1 / std::max(df, 1.0);
    return inv >= 0.5 ? 4.303 + (inv - 0.5) / 0.5 * (12.706 - 4.303)
                      : 3.182 + (inv - 1.0 / 3) / (0.5 - 1.0 / 3) * (4.303 - 3.182);
  }
  // Cornish–Fisher expansion of Student's t quantile around the normal one.
  const double z = 1.959963984540054, z2 = z * z;
  const double g1 = (z2 * z + z) / 4;
  const double g2 = (5 * z2 * z2 * z + 16 * z2 * z + 3 * z) / 96;
  const double g3 = (3 * std::pow(z, 7) + 19 * std::pow(z, 5) + 17 * z2 * z - 15 * z) / 384;
  const double g4 = (79 * std::pow(z, 9) + 776 * std::pow(z, 7) + 1482 * std::pow(z, 5) -
                     1920 * z2 * z - 945 * z) /
                    92160;
  return z + g1 / df + g2 / (df * df) + g3 / std::pow(df, 3) + g4 / std::pow(df, 4);
}

RankTest mann_whitney(const std::vector<double>& a, const std::vector<double>& b) {
  RankTest r;
  const std::size_t m = a.size(), n = b.size();
  if (m == 0 || n == 0) return r;
  // Pooled ranks, ties sharing their mean rank.
  std::vector<std::pair<double, bool>> pooled;  // value, from a
  for (double v : a) pooled.emplace_back(v, true);
  for (double v : b) pooled.emplace_back(v, false);
  std::sort(pooled.begin(), pooled.end(),
            [](const auto& x, const auto& y) { return x.first < y.first; });
  const double total = static_cast<double>(m + n);
  double rank_sum_a = 0, tie_term = 0;  // tie_term: the sum of t^3 - t over groups of t ties
  for (std::size_t i = 0; i < pooled.size();) {
    std::size_t j = i;
    while (j < pooled.size() && pooled[j].first == pooled[i].first) ++j;
    const double t = static_cast<double>(j - i);
    const double mean_rank = (static_cast<double>(i + 1) + static_cast<double>(j)) / 2;
    for (std::size_t k = i; k < j; ++k)
      if (pooled[k].second) rank_sum_a += mean_rank;
    tie_term += t * t * t - t;
    i = j;
  }
  const double dm = static_cast<double>(m), dn = static_cast<double>(n);
  r.u = rank_sum_a - dm * (dm + 1) / 2;
  if (tie_term == 0 && m <= kExactRankTestMax && n <= kExactRankTestMax) {
    // The distribution of U is symmetric about mn/2: P(U >= u) = P(U <= mn - u).
    const double lower = exact_u_cdf(m, n, std::min(r.u, dm * dn - r.u));
    r.p = std::min(1.0, 2 * lower);
    r.exact = true;
    return r;
  }
  const double mu = dm * dn / 2;
  const double var = dm * dn / 12 * ((total + 1) - tie_term / (total * (total - 1)));
  if (!(var > 0)) {  // every value the same: nothing tells the samples apart
    r.p = 1;
    return r;
  }
  const double z = std::max(0.0, std::abs(r.u - mu) - 0.5) / std::sqrt(var);
  r.p = std::min(1.0, std::erfc(z / std::sqrt(2.0)));
  return r;
}

std::vector<SetComparison> compare_sets(const std::vector<RunRecord>& base,
                                        const std::vector<RunRecord>& other) {
  const auto sb = summarize(base), so = summarize(other);
  std::vector<std::string> names;
  for (const auto& s : sb) names.push_back(s.name);
  for (const auto& s : so)
    if (std::find(names.begin(), names.end(), s.name) == names.end()) names.push_back(s.name);
  std::vector<SetComparison> out;
  for (const auto& name : names) {
    SetComparison c;
    c.name = name;
    for (const auto& s : sb)
      if (s.name == name) c.base = s;
    for (const auto& s : so)
      if (s.name == name) c.other = s;
    // The statistics summarize() already took of each side's successful runs.
    const auto mean = [](const SetSummary& x) { return x.successes > 0 ? x.mean_time_s : kNaN; };
    const double na = c.base.successes, nb = c.other.successes;
    c.mean_diff_s = mean(c.other) - mean(c.base);  // NaN when either side has none
    c.welch_t = c.welch_df = kNaN;
    if (na >= 2 && nb >= 2) {
      const double va = c.base.stddev_time_s * c.base.stddev_time_s / na;
      const double vb = c.other.stddev_time_s * c.other.stddev_time_s / nb;
      if (va + vb > 0) {
        c.welch_t = c.mean_diff_s / std::sqrt(va + vb);
        c.welch_df = (va + vb) * (va + vb) / (va * va / (na - 1) + vb * vb / (nb - 1));
        c.significant = std::abs(c.welch_t) > t_critical_5pct(c.welch_df);
      }
    }
    c.rank = mann_whitney(successful_times(base, name), successful_times(other, name));
    const auto tb = times_by_seed(base, name), to = times_by_seed(other, name);
    double sum = 0, most = 0;
    for (const auto& [seed, t] : tb) {
      auto it = to.find(seed);
      if (it == to.end()) continue;
      ++c.paired_runs;
      sum += std::abs(it->second - t);
      most = std::max(most, std::abs(it->second - t));
    }
    c.paired_mean_abs_s = c.paired_runs ? sum / c.paired_runs : kNaN;
    c.paired_max_abs_s = c.paired_runs ? most : kNaN;
    out.push_back(c);
  }
  return out;
}

std::string comparison_table(const std::vector<SetComparison>& sets, const std::string& base_label,
                             const std::string& other_label) {
  std::ostringstream md;
  md << "| set | " << md_text(base_label) << " | " << md_text(other_label)
     << " | difference | Welch t (df) | at 5 % | Mann–Whitney p | at 5 % "
        "| same seed: mean (max) absolute difference "
        "| collisions per run | min inter-drone distance |\n"
     << "|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& c : sets) {
    const bool tested = std::isfinite(c.welch_t);
    md << "| " << md_text(c.name) << " | " << mean_sd(c.base) << " | " << mean_sd(c.other) << " | "
       << or_na(c.mean_diff_s, "{:+.2f} s") << " | "
       << (tested ? fmt::format("{:+.2f} ({:.0f})", c.welch_t, c.welch_df) : "n/a") << " | "
       << verdict(tested, c.significant) << " | "
       << (std::isfinite(c.rank.p)
               ? fmt::format("{:.3g}{}", c.rank.p, c.rank.exact ? " (exact)" : "")
               : "n/a")
       << " | " << verdict(std::isfinite(c.rank.p), c.rank.p < 0.05) << " | "
       << (c.paired_runs ? fmt::format("{:.2f} ({:.2f}) s, {} runs", c.paired_mean_abs_s,
                                       c.paired_max_abs_s, c.paired_runs)
                         : "none")
       << " | "
       << (c.base.runs && c.other.runs
               ? fmt::format("{:.2f} → {:.2f}", c.base.mean_collisions, c.other.mean_collisions)
               : "n/a")
       << " | "
       << (c.base.runs && c.other.runs
               ? fmt::format("{} → {}", or_na(c.base.min_inter_drone_m, "{:.2f} m"),
                             or_na(c.other.min_inter_drone_m, "{:.2f} m"))
               : "n/a")
       << " |\n";
  }
  return md.str();
}

std::string write_comparison_plot(const std::vector<std::vector<SetSummary>>& experiments,
                                  const std::vector<std::string>& labels, const std::string& dir,
                                  const std::string& stem) {
  if (experiments.empty() || labels.size() != experiments.size())
    throw std::invalid_argument("write_comparison_plot: one label per experiment");
  std::vector<std::string> names;
  for (const auto& e : experiments)
    for (const auto& s : e)
      if (std::find(names.begin(), names.end(), s.name) == names.end()) names.push_back(s.name);
  std::filesystem::create_directories(dir);
  // One data block per experiment: set index (offset so the series sit side
  // by side), mean, standard deviation, set name.
  const double k = static_cast<double>(experiments.size());
  const double width = 0.7 / k;
  std::ostringstream dat;
  for (std::size_t e = 0; e < experiments.size(); ++e) {
    dat << "# " << labels[e] << "\n";
    for (std::size_t i = 0; i < names.size(); ++i) {
      const SetSummary* s = nullptr;
      for (const auto& x : experiments[e])
        if (x.name == names[i]) s = &x;
      const double x = static_cast<double>(i) - 0.35 + width * (static_cast<double>(e) + 0.5);
      const bool has = s && std::isfinite(s->mean_time_s);
      dat << x << ' ' << (has ? fmt::format("{}", s->mean_time_s) : "NaN") << ' '
          << (has && std::isfinite(s->stddev_time_s) ? fmt::format("{}", s->stddev_time_s) : "0")
          << '\n';
    }
    dat << "\n\n";
  }
  const std::string data = dir + "/" + stem + ".dat";  // gnuplot reads it from dir
  {
    std::ofstream f(data, std::ios::trunc);
    f << dat.str();
    if (!f) throw std::runtime_error(data + ": cannot write");
  }
  std::ostringstream gp;
  gp << "data = " << gnuplot_string(stem + ".dat") << "\n"
     << "set title 'Task time per set, mean and standard deviation of the successful runs'\n"
     << "set ylabel 'Time to complete [s]'\nset grid ytics\nset offsets 0, 0, 2, 2\n"
     << "set key outside top center horizontal\nset xrange [-0.6:" << names.size() - 0.4 << "]\n"
     << "set xtics (";
  for (std::size_t i = 0; i < names.size(); ++i) {
    std::string n = names[i];
    std::replace(n.begin(), n.end(), '"', '\'');
    gp << (i ? ", " : "") << gnuplot_string(n) << ' ' << i;
  }
  gp << ")\nplot ";
  for (std::size_t e = 0; e < experiments.size(); ++e) {
    // Points with error bars, the y axis fitted to them: a difference of a
    // second must show, which bars from zero would hide.
    gp << (e ? ", \\\n     " : "") << "data index " << e
       << " using 1:2:3 with yerrorbars pt 7 ps 1.2 lw 2 lc " << e + 1 << " title "
       << gnuplot_string(labels[e]);
  }
  gp << "\n";
  return render_gnuplot(dir, stem, gp.str(), 900, 500);
}

}  // namespace ddswarm::gs
