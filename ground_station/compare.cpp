#include "ground_station/compare.hpp"

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

/// Successful runs' task times by seed, for one set.
std::map<std::uint64_t, double> times_by_seed(const std::vector<RunRecord>& records,
                                              const std::string& set) {
  std::map<std::uint64_t, double> out;
  for (const auto& r : records)
    if (r.set_name == set && r.ok && std::isfinite(r.task_time_s)) out[r.seed] = r.task_time_s;
  return out;
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
     << " | difference | Welch t (df) | at 5 % | same seed: mean (max) absolute difference "
        "| collisions per run | min inter-drone distance |\n"
     << "|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& c : sets) {
    const bool tested = std::isfinite(c.welch_t);
    md << "| " << md_text(c.name) << " | " << mean_sd(c.base) << " | " << mean_sd(c.other) << " | "
       << or_na(c.mean_diff_s, "{:+.2f} s") << " | "
       << (tested ? fmt::format("{:+.2f} ({:.0f})", c.welch_t, c.welch_df) : "n/a") << " | "
       << (tested ? (c.significant ? "**DIFFERENT**" : "same") : "n/a") << " | "
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
