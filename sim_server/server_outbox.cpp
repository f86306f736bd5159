#include "sim_server/server_outbox.hpp"

#include <spdlog/spdlog.h>

#include "sim_server/messages.hpp"

namespace ddswarm::sim {

// The writers are made in this order, as the topics' entities always were.
ServerOutbox::ServerOutbox(Participant& dds, const SimConfig& sim)
    : sim_(sim),
      w_swarm_(dds.writer<msg::SwarmState>()),
      w_drone_(dds.writer<msg::DroneState>()),
      w_scan_(dds.writer<msg::DistanceScan>()),
      w_scene_(dds.writer<msg::Scene>()),
      w_status_(dds.writer<msg::SimStatus>()),
      w_collision_(dds.writer<msg::CollisionEvent>()),
      w_task_(dds.writer<msg::TaskStatus>()) {}

void ServerOutbox::start(double now_wall) {
  start_wall_ = now_wall;
  rtf_wall_ = now_wall;
}

void ServerOutbox::per_drone(const msg::SwarmState& m, bool scan_tick) {
  // Best-effort, volatile topics: with no reader matched (no recorder or
  // tool listening) the 2N writes would only serialize into the history.
  if (!sim_.publish_per_drone_topics) return;
  const bool drones = w_drone_.matched() > 0, scans = scan_tick && w_scan_.matched() > 0;
  for (std::size_t i = 0; i < m.drones().size() && (drones || scans); ++i) {
    if (drones) w_drone_.write(m.drones()[i]);
    if (scans) w_scan_.write(m.scans()[i]);
  }
}

void ServerOutbox::task(const TaskReport& r, bool changed, double now) {
  // The topic is latched (transient-local): it has a value from the first
  // tick, so a tool that joins before any task knows there is none at once
  // rather than after waiting out its patience for a sample.
  if (task_published_ && !changed &&
      !(r.phase == TaskPhase::kRunning && now - last_task_publish_wall_ > 0.5) &&
      r.phase == last_task_phase_)
    return;
  if (r.phase == TaskPhase::kRunning && last_task_phase_ != TaskPhase::kRunning)
    task_start_wall_ = now;
  task_published_ = true;
  last_task_phase_ = r.phase;
  last_task_publish_wall_ = now;
  w_task_.write(task_message(r, task_start_wall_ - start_wall_, now - task_start_wall_));
  if (changed && r.phase == TaskPhase::kComplete)
    spdlog::info(
        "task complete: {:.2f} s sim, {} obstacle / {} drone / {} ground collisions, "
        "min distance {:.2f} m, min clearance {:.2f} m",
        r.elapsed_s, r.collisions_obstacle, r.collisions_drone, r.collisions_ground,
        r.min_inter_drone_m, r.min_clearance_m);
  if (changed && r.phase == TaskPhase::kFailed) spdlog::warn("task failed: {}", r.reason);
}

bool ServerOutbox::status_due(bool force, bool due, double now, double sim_time_s) {
  if (!force && now - last_status_wall_ < 1.0 / sim_.status_rate_hz && !due) return false;
  double dw = now - rtf_wall_;
  if (dw >= 0.5) {
    rtf_ = (sim_time_s - rtf_sim_) / dw;
    rtf_wall_ = now;
    rtf_sim_ = sim_time_s;
  }
  last_status_wall_ = now;
  return true;
}

}  // namespace ddswarm::sim
