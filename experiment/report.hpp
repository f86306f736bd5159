#pragma once
// Experiment results: one CSV row per run, summaries per parameter set, the
// thesis's Table 1 as Markdown and its Fig. 13-16 (task time per run) as
// gnuplot plots. No DDS here: the runner fills RunRecords, this writes them.
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "common/swarm_metrics.hpp"

namespace ddswarm::gs {

/// One simulated run of one parameter set.
struct RunRecord {
  std::string set_name;          ///< e.g. "Sim 1"
  int run_index = 0;             ///< 0-based index within the set
  std::uint64_t seed = 0;        ///< scenario seed used for this run
  int drones = 0;                ///< number of drones
  double d_int_m = 0;            ///< m, wanted inter-drone distance D_int
  double speed_mps = 0;          ///< m/s, wanted task speed
  std::string sensor_function;   ///< e.g. "fs1"
  std::string mode;              ///< e.g. "lockstep"
  bool ok = false;               ///< the task completed within the time limit
  std::string failure_reason;    ///< empty when ok
  double task_time_s = 0;        ///< s of sim time from task start to swarm condition (NaN: none)
  double wall_time_s = 0;        ///< s of wall-clock time the run took
  int collisions_obstacle = 0;   ///< drone-obstacle collisions during the run
  int collisions_drone = 0;      ///< drone-drone collisions (each pair counted once)
  int collisions_ground = 0;     ///< unplanned ground contacts
  double min_inter_drone_m = 0;  ///< m, smallest distance between two drones (inf: none)
  double min_clearance_m = 0;    ///< m, smallest drone-obstacle clearance (inf: none)
  std::map<std::string, std::string> params;  ///< other settings worth keeping (overrides)
  /// The task's swarm metrics (NaN, 0: not measured, e.g. the swarm never
  /// came up, or a CSV written before them).
  SwarmTaskMetrics metrics;

  int collisions() const { return collisions_obstacle + collisions_drone + collisions_ground; }
};

/// Appends one row to the CSV file at path, writing the header first when the
/// file is new or empty. The row reaches the disk (written with one append,
/// flushed, fsync'd) before this returns; concurrent appenders are serialised
/// by a file lock. Throws std::runtime_error naming path when the file cannot
/// be written or its header is not this version's.
/// Format: RFC 4180 (fields with , " CR LF or edge spaces are quoted, quotes
/// doubled); numbers in shortest round-trip form ("nan", "inf" allowed);
/// ok as 1/0; params as key=value pairs joined by ';' with '\' escaping '\', ';', '='.
/// The swarm metrics come after params (order_mean, order_min, speed_mean_mps,
/// near_misses, components_max, lambda2_min, metrics_range_m, near_miss_m), so
/// that every older column keeps its position.
void append_csv(const std::string& path, const RunRecord& record);

/// Reads every row written by append_csv. Columns are found by header name
/// (extra columns are ignored; the swarm metrics' may be missing, as in files
/// written before them, and read as not measured). Throws std::runtime_error "path:line: reason"
/// on a missing file, missing column or malformed value.
std::vector<RunRecord> read_csv(const std::string& path);

/// Statistics of one parameter set (one column of Table 1).
struct SetSummary {
  std::string name;
  int drones = 0;               ///< from the set's first run
  double d_int_m = 0;           ///< m, from the set's first run
  double speed_mps = 0;         ///< m/s, from the set's first run
  std::string sensor_function;  ///< from the set's first run
  std::string mode;             ///< from the set's first run
  int runs = 0;                 ///< runs recorded
  int failures = 0;             ///< runs with ok == false
  int successes = 0;         ///< runs with ok and a finite task time (what the time statistics use)
  double mean_time_s = 0;    ///< s, mean task time of successful runs (NaN: none)
  double stddev_time_s = 0;  ///< s, sample standard deviation (n-1) of the same (NaN: < 2)
  double min_time_s = 0;     ///< s, over successful runs (NaN: none)
  double max_time_s = 0;     ///< s, over successful runs (NaN: none)
  double mean_collisions = 0;  ///< all collisions per run, over every run
  double mean_collisions_obstacle = 0;
  double mean_collisions_drone = 0;
  double mean_collisions_ground = 0;
  double min_inter_drone_m = 0;  ///< m, smallest over every run (inf: none recorded)
  double min_clearance_m = 0;    ///< m, smallest over every run (inf: none recorded)
  double mean_wall_time_s = 0;   ///< s, mean wall-clock time per run
  // Swarm metrics, over the runs that measured them (metrics_runs; NaN: none).
  int metrics_runs = 0;         ///< runs with a measured order_mean
  double mean_order = 0;        ///< mean of the runs' order_mean
  double min_order = 0;         ///< smallest order_min of a run
  double mean_speed_mps = 0;    ///< m/s, mean of the runs' speed_mean_mps
  double mean_near_misses = 0;  ///< near misses per run
  int max_components = 0;       ///< most components of a run (0: none measured)
  double min_lambda2 = 0;       ///< smallest lambda2_min of a run
  bool consistent = true;       ///< false when runs disagree on drones/D_int/speed/sensor/mode
};

/// One summary per set name, in the order sets first appear in records.
std::vector<SetSummary> summarize(const std::vector<RunRecord>& records);

/// Table 1 of the thesis as a Markdown table: one column per set (its name as
/// header), rows Drones nr, Inter-distance, Velocity, Sensor Function,
/// Avg. task time, Standard deviation, Avg. collisions, Min. inter-drone
/// distance, Failures ("failures/runs"). Missing statistics print as "n/a".
std::string markdown_table(const std::vector<SetSummary>& sets);

/// The swarm metrics per set as a Markdown table, laid out like
/// markdown_table: rows Avg. order, Min. order, Avg. speed, Avg. near misses,
/// Max. components, Min. algebraic connectivity, Runs measured. "" when no set
/// measured them.
std::string metrics_table(const std::vector<SetSummary>& sets);

/// File stem used for a set's plot files: lowercase letters, digits and '_'
/// (e.g. "Sim 1" -> "sim_1"); never empty.
std::string plot_stem(const std::string& set_name);

/// For each set: out_dir/<stem>.dat (run, task time, collisions, ok),
/// <stem>.gp (the gnuplot script) and the plot of task time per run, like the
/// thesis's Fig. 13-16, as <stem>.png (pngcairo, or png without cairo) and
/// <stem>.svg. Creates out_dir. Stems that collide get a numeric suffix.
/// Returns the png paths. Throws std::runtime_error when gnuplot is missing or
/// fails (with its message), or a file cannot be written.
/// Writes <dir>/summary.png and .svg: one bar per set, mean task time with its
/// standard deviation (the sweep at a glance). Returns the png path; throws
/// std::runtime_error when gnuplot fails. write_plots() calls it for 2+ sets.
std::string write_summary_plot(const std::vector<SetSummary>& sets, const std::string& dir);

/// Writes <dir>/metrics.png and .svg (and metrics.dat): per set, above, the
/// order (bar: mean of the runs' order_mean; point: smallest order_min) and,
/// below, the smallest inter-drone distance with the mean near misses per run
/// written on it. Returns the png path; throws std::runtime_error when gnuplot
/// fails. write_plots() calls it when some set measured the swarm metrics.
std::string write_metrics_plot(const std::vector<SetSummary>& sets, const std::string& dir);

/// s as a gnuplot single-quoted string (quotes doubled, line breaks as spaces).
std::string gnuplot_string(const std::string& s);

/// Writes <dir>/<stem>.gp: `plot` (gnuplot commands that draw one figure)
/// rendered to <stem>.png (pngcairo, or png without cairo) and <stem>.svg at
/// width x height; runs gnuplot in dir. Returns the png path; throws
/// std::runtime_error when gnuplot is missing, fails or writes no png or svg.
std::string render_gnuplot(const std::string& dir, const std::string& stem, const std::string& plot,
                           int width, int height);

std::vector<std::string> write_plots(const std::vector<RunRecord>& records,
                                     const std::string& out_dir);

}  // namespace ddswarm::gs
