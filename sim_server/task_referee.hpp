#pragma once
// Referees the thesis task (§3.1, §3.6) exactly, at every control tick.
//
// The task starts at the tick its command is applied and completes at the
// first tick where every counted drone is past the finish line and every
// pairwise distance is below epsilon (Eq. 3.1). It also tracks what Table 1
// reports: collisions by kind, the minimum inter-drone distance and the
// minimum clearance to obstacles. Pure: positions in, status out.
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "common/scene.hpp"

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
};

class TaskReferee {
 public:
  explicit TaskReferee(const SceneConfig& scene) : scene_(scene) {}

  void start(std::uint32_t seq, double sim_time_s, double epsilon_m, double speed_mps, int drones);
  /// Stops a running task as failed with reason (e.g. "aborted by land").
  void fail(const std::string& reason);
  /// One tick: positions of the drones that count (lost drones excluded by
  /// the caller), and the time limit. Returns true when the phase changed.
  bool update(double sim_time_s, const std::vector<Eigen::Vector3d>& positions, double timeout_s);
  /// Counts a collision that began during the task.
  void count_collision(int kind);  // 0 obstacle, 1 drone, 2 ground
  /// Records that drone id's agent was lost (failsafe) while the task runs.
  void note_lost(int id);

  bool running() const { return r_.phase == TaskPhase::kRunning; }
  const TaskReport& report() const { return r_; }

 private:
  const SceneConfig& scene_;
  TaskReport r_;
};

}  // namespace ddswarm::sim
