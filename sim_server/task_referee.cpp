#include "sim_server/task_referee.hpp"

#include <algorithm>
#include <limits>

namespace ddswarm::sim {

void TaskReferee::start(std::uint32_t seq, double t, double epsilon_m, double speed_mps,
                        int drones) {
  r_ = TaskReport{};
  r_.seq = seq;
  r_.phase = TaskPhase::kRunning;
  r_.start_sim_time_s = t;
  r_.epsilon_m = epsilon_m;
  r_.speed_mps = speed_mps;
  r_.drones = drones;
  r_.min_inter_drone_m = std::numeric_limits<double>::infinity();
  r_.min_clearance_m = std::numeric_limits<double>::infinity();
  metrics_.reset();
  r_.metrics = metrics_.summary();
}

void TaskReferee::on_mission(MissionType type, std::uint32_t seq, double speed_mps,
                             double epsilon_m, double d_int_m, double sim_time_s, int drones) {
  if (running() && (type == MissionType::kLand || type == MissionType::kTask ||
                    type == MissionType::kMove || type == MissionType::kFollowLeader))
    fail(std::string("aborted by ") + to_string(type) + " command");
  if (type == MissionType::kTask)
    start(seq, sim_time_s, epsilon_m > 0 ? epsilon_m : default_epsilon(d_int_m), speed_mps, drones);
}

void TaskReferee::fail(const std::string& reason) {
  if (r_.phase != TaskPhase::kRunning) return;
  r_.phase = TaskPhase::kFailed;
  r_.reason = reason;
}

void TaskReferee::note_lost(int id) {
  if (r_.phase != TaskPhase::kRunning) return;
  auto it = std::lower_bound(r_.lost_drones.begin(), r_.lost_drones.end(), id);
  if (it == r_.lost_drones.end() || *it != id) r_.lost_drones.insert(it, id);
}

void TaskReferee::count_collision(int kind) {
  if (r_.phase != TaskPhase::kRunning) return;
  if (kind == 0) ++r_.collisions_obstacle;
  if (kind == 1) ++r_.collisions_drone;
  if (kind == 2) ++r_.collisions_ground;
}

bool TaskReferee::update(double t, const std::vector<Eigen::Vector3d>& p,
                         const std::vector<Eigen::Vector3d>& v, const std::vector<int>& ids,
                         double timeout_s) {
  if (r_.phase != TaskPhase::kRunning) return false;
  r_.elapsed_s = t - r_.start_sim_time_s;
  r_.drones = static_cast<int>(p.size());
  // One pass over the pairs gives the thesis's distances and the metrics.
  const SwarmTickMetrics tick = swarm_tick_metrics(p, v, metrics_options_);
  metrics_.add(tick, ids);
  r_.metrics = metrics_.summary();
  r_.order = tick.order;
  r_.lambda2 = tick.lambda2;
  r_.components = tick.components;
  const double max_pair = tick.max_distance_m;
  r_.min_inter_drone_m = std::min(r_.min_inter_drone_m, tick.min_distance_m);
  for (const auto& q : p) r_.min_clearance_m = std::min(r_.min_clearance_m, scene_.clearance(q));
  r_.max_pair_distance_m = max_pair;
  r_.past_finish =
      static_cast<int>(std::count_if(p.begin(), p.end(), [&](const Eigen::Vector3d& q) {
        return scene_.past_finish(q.head<2>());
      }));
  if (p.empty()) {
    r_.phase = TaskPhase::kFailed;
    r_.reason = "no drone left";
    return true;
  }
  if (r_.past_finish == static_cast<int>(p.size()) && max_pair < r_.epsilon_m) {
    r_.phase = TaskPhase::kComplete;
    return true;
  }
  if (r_.elapsed_s > timeout_s) {
    r_.phase = TaskPhase::kFailed;
    r_.reason = "timeout after " + std::to_string(static_cast<int>(timeout_s)) + " s (" +
                std::to_string(r_.past_finish) + "/" + std::to_string(p.size()) + " past finish)";
    return true;
  }
  return false;
}

}  // namespace ddswarm::sim
