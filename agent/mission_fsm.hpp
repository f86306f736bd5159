#pragma once
// One drone's mission state machine, pure: commands and observations in,
// phase and mission velocity out. No I/O, no clock of its own (it reads the
// simulation time from each Observation).
//
// Phases (common/mission.hpp):
//   idle --takeoff--> takeoff --(within altitude_tolerance_m)--> hold
//   hold --move--> move --(duration_s of sim time)--> hold
//   hold --task--> task --(past the finish line)--> swarm
//   hold --follow--> follow;  any airborne --land--> landing --(on ground)--> idle
// kFailsafe is never entered here: the app reports it when the server is silent.
//
// Which command is accepted where (rejections carry the quoted reason):
//   takeoff:          idle, landing (go around) -> takeoff; else "already airborne"
//   move/task/follow: hold, move, task, swarm, follow -> that phase;
//                     idle "not airborne", takeoff "still taking off", landing "landing"
//   hold:             as move, but from landing too (holds the current altitude)
//   land:             any airborne phase -> landing; idle and landing: accepted, no-op
//   set distance:     every phase; the phase is unchanged
//   teleop:           follow (only the leader uses it); else "not following a leader"
//   any other type:   "unknown command type"
// Bad arguments are rejected in any phase, e.g. "duration_s must be > 0".
//
// Vertical motion: while altitude hold is on, the altitude target (world z)
// is the cruise altitude set by takeoff; a move's (or the leader's teleop)
// vertical velocity moves the cruise altitude with it, kept within
// [ground + min_altitude_m, scene.bounds_max.z - min_altitude_m]. Takeoff
// always climbs through the altitude loop (rate-limited to takeoff_speed_mps);
// landing descends at landing_speed_mps with altitude hold off.
#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <map>
#include <string>

#include "agent/agent_config.hpp"
#include "agent/swarm_law.hpp"
#include "common/mission.hpp"
#include "common/scene.hpp"

namespace ddswarm::agent {

/// What the drone knows about itself at one control tick.
struct Observation {
  double sim_time_s = 0;             ///< s, simulation time of the sample
  std::uint64_t tick = 0;            ///< lockstep tick, copied into acks
  Eigen::Vector3d p_world{0, 0, 0};  ///< m, ENU
  Eigen::Vector3d v_world{0, 0, 0};  ///< m/s, ENU
  bool on_ground = true;             ///< touching the ground (z low, resting)
};

/// What the mission asks of the laws this tick (see LawInput).
struct MissionOutput {
  Phase phase = Phase::kIdle;
  Eigen::Vector3d mission_velocity{0, 0, 0};  ///< m/s, world
  bool motors_on = false;                     ///< false only in idle
  bool swarm_enabled = false;                 ///< include R&A (airborne, off the ground)
  bool obstacle_avoidance_enabled = false;    ///< include the sensor term (same rule)
  double altitude_target_m = 0;               ///< m, world z for the altitude loop
  bool altitude_hold = false;                 ///< run the altitude loop (takeoff: always)
  bool busy = false;                          ///< the lockstep clock is needed (see step())
  bool swarm_horizontal_only = false;  ///< landing: the swarm term keeps drones apart sideways only
  double inter_distance_m = 4.0;       ///< m, D_int in force
};

class MissionFsm {
 public:
  /// Throws FieldError if cfg or scene is invalid, std::invalid_argument if drone_id < 0.
  MissionFsm(int drone_id, const AgentConfig& cfg, const ddswarm::SceneConfig& scene);

  /// True when c.target is -1 or this drone's id.
  bool addressed_to_me(const MissionCommand& c) const;

  /// Applies a command and returns its ack (drone_id, seq, phase after, o.tick).
  /// A command not addressed to this drone is rejected and changes nothing.
  /// A command identical to one applied recently (same issuer, seq and
  /// content; the last 64 per issuer are kept) returns the ack it got then and changes
  /// nothing, so a command repeated after a lost ack is applied once. A
  /// different command under an old seq means its issuer restarted: it is
  /// applied and that issuer's history is forgotten.
  MissionAck apply(const MissionCommand& c, const Observation& o);

  /// Catches up with a command the swarm applied at sim time applied_at_s,
  /// before this agent (re)joined: the state it leaves is the one the drone
  /// would be in had it applied c then (a move's end and a timed hold's end
  /// count from applied_at_s). The gates of apply() do not hold, because the
  /// drone may be anywhere (hovering or landed by the server's failsafe): a
  /// flying phase entered while the drone is off its cruise altitude is
  /// entered through takeoff, which climbs first. Idempotent like apply().
  MissionAck resume(const MissionCommand& c, double applied_at_s, const Observation& o);

  /// Advances timed transitions and returns this tick's mission output. Call
  /// every control tick. busy: false in idle; true in takeoff, move, task,
  /// follow and landing; in hold only until a timed hold (duration_s) ends; false in
  /// swarm (the server keeps its clock running while it referees the task).
  MissionOutput step(const Observation& o);

  Phase phase() const { return phase_; }
  double inter_distance_m() const { return d_int_m_; }  ///< m; kSetDistance changes it
  int drone_id() const { return id_; }
  int leader_id() const { return leader_id_; }  ///< -1 unless following

 private:
  struct Applied {
    MissionCommand command;
    MissionAck ack;
  };

  /// Empty when accepted (state changed), else the rejection reason (state unchanged).
  std::string execute(const MissionCommand& c, const Observation& o);
  std::string resume_execute(const MissionCommand& c, double at_s, const Observation& o);
  /// Enters a flying phase now, or after the climb when taking off.
  void enter(Phase p);
  /// "" and *z when c's takeoff altitude is usable, else why not.
  std::string takeoff_altitude(const MissionCommand& c, double* z) const;
  double clamp_cruise(double z) const;
  bool airborne() const { return phase_ != Phase::kIdle; }

  int id_;
  AgentConfig cfg_;
  ddswarm::SceneConfig scene_;
  Phase phase_ = Phase::kIdle;
  Phase after_takeoff_ = Phase::kHold;  // the phase a finished climb enters
  double d_int_m_;
  double cruise_z_m_ = 0;  // world z held by the altitude loop
  double move_end_s_ = 0;  // sim time a move ends
  double hold_end_s_ = 0;  // sim time a timed hold ends (the lockstep clock runs until then)
  Eigen::Vector3d move_velocity_{0, 0, 0};
  double task_speed_mps_ = 0;
  int leader_id_ = -1;
  Eigen::Vector3d teleop_velocity_{0, 0, 0};
  double teleop_time_s_ = 0;  // sim time of the latest teleop
  bool have_time_ = false;
  double last_time_s_ = 0;
  std::map<std::string, std::deque<Applied>> history_;  // per issuer, newest last
  std::map<std::string, std::uint32_t> highest_seq_;
};

/// Copies the mission part of out into in (mission velocity, D_int, enables,
/// altitude loop); the caller fills position, attitude, peers and rays.
void set_mission(LawInput& in, const MissionOutput& out);

}  // namespace ddswarm::agent
