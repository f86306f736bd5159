#pragma once
// Writes the swarm's state to CSV as it flies: one row per drone per traced tick.
#include <cstdio>
#include <memory>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/dds_config.hpp"

namespace ddswarm::msg {
class SwarmState;
}

namespace ddswarm::gs {

class SwarmTrace {
 public:
  /// every: keep one tick in `every`. Throws std::runtime_error if path cannot be written.
  SwarmTrace(const DdsConfig& dds, const std::string& path, int every);
  ~SwarmTrace();
  long rows() const;
  /// Traces until stop_requested() or duration_s (<= 0: until stopped). A
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
  double x = 0, y = 0, z = 0;   ///< m, ENU
  double speed_mps = 0;
  double nearest_peer_m = 0;    ///< m, distance to the nearest other drone
  int collisions = 0;
  std::string phase;
  std::string flags;            ///< "airborne", "failsafe", "no-agent", ...
};

struct SwarmSnapshot {
  std::uint64_t tick = 0;
  double sim_time_s = 0;
  std::vector<DroneRow> drones;
  double min_pair_m = 0;  ///< m, smallest pairwise distance
  double max_pair_m = 0;  ///< m, largest pairwise distance (the swarm's size, Eq. 3.1)
  std::string table() const;  ///< a per-drone table plus a summary line
};

/// The per-drone table and pairwise distances of one SwarmState sample.
SwarmSnapshot snapshot_of(const msg::SwarmState& s);

}  // namespace ddswarm::gs
