#pragma once
// Referees the thesis task (§3.1, §3.6) exactly, at every control tick.
//
// The task starts at the tick its command is applied and completes at the
// first tick where every counted drone is past the finish line and every
// pairwise distance is below epsilon (Eq. 3.1). It also tracks what Table 1
// reports: collisions by kind, the minimum inter-drone distance and the
// minimum clearance to obstacles; and the swarm metrics of every tick
// (common/swarm_metrics.hpp), which only observe. Pure: positions and
// velocities in, status out.
#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "common/mission.hpp"
#include "common/scene.hpp"
#include "common/swarm_metrics.hpp"

namespace ddswarm::sim {

enum class TaskPhase : std::uint8_t { kNone = 0, kRunning = 1, kComplete = 2, kFailed = 3 };

struct TaskReport {
  std::uint32_t seq = 0;
  TaskPhase phase = TaskPhase::kNone;
  std::string reason;
  double start_sim_time_s = 0;
  double elapsed_s = 0;
  double epsilon_m = 0;
  double speed_mps = 0;
  int drones = 0;
  int past_finish = 0;
  double max_pair_distance_m = 0;
  double min_inter_drone_m = 0;
  double min_clearance_m = 0;
  std::uint32_t collisions_obstacle = 0, collisions_drone = 0, collisions_ground = 0;
  std::vector<int> lost_drones;  ///< drones whose agent was lost while the task ran, ascending
  SwarmTaskMetrics metrics;      ///< the swarm metrics over the task's ticks so far
  /// The latest tick's φ_corr, λ₂ and components (NaN, NaN, 0 before the first).
  double order = std::numeric_limits<double>::quiet_NaN();
  double lambda2 = std::numeric_limits<double>::quiet_NaN();
  int components = 0;
};

/// The drones that count for the task at one tick, gathered drone by drone
/// into vectors kept across ticks (cleared, never freed).
struct CountedDrones {
  std::vector<Eigen::Vector3d> positions;   ///< m, world ENU
  std::vector<Eigen::Vector3d> velocities;  ///< m/s, world ENU
  std::vector<int> ids;                     ///< drone ids, in the same order
  void reserve(int n) {
    positions.reserve(n);
    velocities.reserve(n);
    ids.reserve(n);
  }
  void clear() {
    positions.clear();
    velocities.clear();
    ids.clear();
  }
  void add(int id, const Eigen::Vector3d& p_world, const Eigen::Vector3d& v_world) {
    positions.push_back(p_world);
    velocities.push_back(v_world);
    ids.push_back(id);
  }
};

class TaskReferee {
 public:
  /// metrics: the communication range, near-miss distance and λ₂ size limit
  /// of the swarm metrics.
  explicit TaskReferee(const SceneConfig& scene, const SwarmMetricsOptions& metrics = {})
      : scene_(scene), metrics_options_(metrics), metrics_(metrics) {}

  void start(std::uint32_t seq, double sim_time_s, double epsilon_m, double speed_mps, int drones);
  /// A mission command released at sim_time_s: a land, task, move or follow
  /// command aborts a running task; a task command (seq) starts one over the
  /// drones at speed_mps, within epsilon_m (m; 0: default_epsilon of d_int_m,
  /// the inter-drone distance in force).
  void on_mission(MissionType type, std::uint32_t seq, double speed_mps, double epsilon_m,
                  double d_int_m, double sim_time_s, int drones);
  /// Stops a running task as failed with reason (e.g. "aborted by land").
  void fail(const std::string& reason);
  /// One tick: the drones that count (lost drones excluded by the caller),
  /// drone ids[k] at positions[k] (m) flying velocities[k] (m/s), world ENU,
  /// all three the same size; and the time limit. Returns true when the phase
  /// changed.
  bool update(double sim_time_s, const std::vector<Eigen::Vector3d>& positions,
              const std::vector<Eigen::Vector3d>& velocities, const std::vector<int>& ids,
              double timeout_s);
  /// Counts a collision that began during the task.
  void count_collision(int kind);  // 0 obstacle, 1 drone, 2 ground
  /// Records that drone id's agent was lost (failsafe) while the task runs.
  void note_lost(int id);

  bool running() const { return r_.phase == TaskPhase::kRunning; }
  const TaskReport& report() const { return r_; }

 private:
  const SceneConfig& scene_;
  SwarmMetricsOptions metrics_options_;
  SwarmMetricsAccumulator metrics_;
  TaskReport r_;
};

}  // namespace ddswarm::sim
