#pragma once
// Writes the swarm's state to CSV as it flies: one row per drone per traced
// tick, and, with a metrics file, one row of swarm metrics per traced tick.
#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/dds_config.hpp"
#include "common/swarm_metrics.hpp"

namespace ddswarm::msg {
class SwarmState;
}

namespace ddswarm::gs {

/// `ddswarm-gs trace --metrics`: where the per-tick swarm metrics go, and how
/// they are computed.
struct TraceMetrics {
  std::string path;             ///< CSV, one row per traced tick ("" = none)
  SwarmMetricsOptions options;  ///< range, near-miss distance, λ₂ size limit
};

class SwarmTrace {
 public:
  /// every: keep one tick in `every`. Throws std::runtime_error if path (or
  /// metrics.path) cannot be written.
  SwarmTrace(const DdsConfig& dds, const std::string& path, int every,
             const TraceMetrics& metrics = {});
  ~SwarmTrace();
  long rows() const;
  long metrics_rows() const;  ///< rows written to the metrics file
  /// Ends run() from any thread (within 0.25 s), as SIGINT would.
  void stop();
  /// Traces until stop(), stop_requested() or duration_s (<= 0: until stopped). A
  /// process stopped (Ctrl-Z) longer than its DDS lease could stay deaf, so
  /// then it leaves DDS and joins again as a new participant (LeaseWatch);
  /// a tick already written is not written again.
  void run(double duration_s);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// One drone at one tick, as the ground station sees it.
struct DroneRow {
  int id = 0;
  double x = 0, y = 0, z = 0;  ///< m, ENU
  double speed_mps = 0;
  double nearest_peer_m = 0;  ///< m, distance to the nearest other drone
  int collisions = 0;
  std::string phase;
  std::string flags;  ///< "airborne", "failsafe", "no-agent", ...
};

struct SwarmSnapshot {
  std::uint64_t tick = 0;
  double sim_time_s = 0;
  std::vector<DroneRow> drones;
  double min_pair_m = 0;      ///< m, smallest pairwise distance
  double max_pair_m = 0;      ///< m, largest pairwise distance (the swarm's size, Eq. 3.1)
  std::string table() const;  ///< a per-drone table plus a summary line
};

/// The per-drone table and pairwise distances of one SwarmState sample.
SwarmSnapshot snapshot_of(const msg::SwarmState& s);

/// The header of the metrics file (no newline).
inline constexpr const char* kTraceMetricsHeader =
    "tick,sim_time_s,drones,order,mean_speed_mps,min_distance_m,near_pairs,components,lambda2";

/// One row of the metrics file (no newline): the metrics of s over its drones
/// not in failsafe (DRONE_FAILSAFE), the drones the task referee counts.
/// Undefined values print as nan (order, lambda2) or inf (min_distance_m).
std::string trace_metrics_row(const msg::SwarmState& s, const SwarmMetricsOptions& o);

/// The metrics options the server's referee takes from the scenario file at
/// path (sim.metrics_range_m, sim.near_miss_m, sim.metrics_lambda2_max_drones),
/// the defaults for those it does not set; path "" = the defaults. Throws
/// ConfigError "file:line: field = value: reason" on a bad value.
SwarmMetricsOptions scenario_metrics_options(const std::string& path);

}  // namespace ddswarm::gs
