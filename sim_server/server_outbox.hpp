#pragma once
// What the server publishes on DDS, and when: the Scene once, every tick's
// SwarmState (and the per-drone topics while someone listens), SimStatus at
// its rate or at once when due, TaskStatus on a change or twice a second
// while the task runs, and each CollisionEvent. Times are wall s
// (wall_seconds()) unless named sim.
#include "CollisionEvent.h"
#include "DistanceScan.h"
#include "DroneState.h"
#include "Scene.h"
#include "SimStatus.h"
#include "SwarmState.h"
#include "TaskStatus.h"
#include "common/participant.hpp"
#include "sim_server/sim_config.hpp"
#include "sim_server/task_referee.hpp"

namespace ddswarm::sim {

class ServerOutbox {
 public:
  ServerOutbox(Participant& dds, const SimConfig& sim);

  /// The run starts at now_wall: the origin of SimStatus.wall_time_s and of
  /// TaskStatus.start_wall_time_s.
  void start(double now_wall);
  double start_wall() const { return start_wall_; }

  void scene(const msg::Scene& s) { w_scene_.write(s); }
  void collision(const msg::CollisionEvent& m) { w_collision_.write(m); }
  /// The tick's SwarmState, or the published one again (a lockstep resend).
  void swarm(const msg::SwarmState& m) { w_swarm_.write(m); }
  /// Each drone's DroneState, and with scan_tick its DistanceScan, from m;
  /// only while a reader is matched (sim.publish_per_drone_topics).
  void per_drone(const msg::SwarmState& m, bool scan_tick);

  /// The referee's report, when it changed, has a new phase, or (running)
  /// went out over 0.5 s ago; logs the task's end.
  void task(const TaskReport& r, bool changed, double now_wall);

  /// Whether a SimStatus goes out at now_wall: forced, due (something a
  /// ground station waits for changed), or a period of sim.status_rate_hz
  /// since the last. If so it counts as sent, and the real-time factor is
  /// measured against sim_time_s when 0.5 s have passed since last measured.
  bool status_due(bool force, bool due, double now_wall, double sim_time_s);
  /// Sim s per wall s, as last measured.
  double real_time_factor() const { return rtf_; }
  void status(const msg::SimStatus& s) { w_status_.write(s); }
  /// The next SimStatus goes out at the next check.
  void status_soon() { last_status_wall_ = -1e9; }

 private:
  const SimConfig& sim_;
  Writer<msg::SwarmState> w_swarm_;
  Writer<msg::DroneState> w_drone_;
  Writer<msg::DistanceScan> w_scan_;
  Writer<msg::Scene> w_scene_;
  Writer<msg::SimStatus> w_status_;
  Writer<msg::CollisionEvent> w_collision_;
  Writer<msg::TaskStatus> w_task_;
  double start_wall_ = 0;
  double last_status_wall_ = -1e9, rtf_wall_ = 0, rtf_sim_ = 0, rtf_ = 0;
  TaskPhase last_task_phase_ = TaskPhase::kNone;
  bool task_published_ = false;
  double task_start_wall_ = 0;
  double last_task_publish_wall_ = -1e9;
};

}  // namespace ddswarm::sim
