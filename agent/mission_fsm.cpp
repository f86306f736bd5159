#include "agent/mission_fsm.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace ddswarm::agent {
namespace {

constexpr std::size_t kHistoryDepth = 64;

bool same_command(const MissionCommand& a, const MissionCommand& b) {
  return a.seq == b.seq && a.type == b.type && a.target == b.target && a.velocity == b.velocity &&
         a.duration_s == b.duration_s && a.value == b.value && a.leader_id == b.leader_id &&
         a.epsilon_m == b.epsilon_m && a.issuer == b.issuer;
}

bool finite(const Eigen::Vector3d& v) { return v.allFinite(); }

/// "" when v is a usable velocity command, else why not.
std::string check_velocity(const Eigen::Vector3d& v, double max_speed_mps) {
  if (!finite(v)) return "velocity must be finite";
  if (v.norm() > max_speed_mps + 1e-9)
    return "speed " + to_text(v.norm()) + " m/s exceeds agent.max_speed_mps (" +
           to_text(max_speed_mps) + ")";
  return "";
}

}  // namespace

MissionFsm::MissionFsm(int drone_id, const AgentConfig& cfg, const ddswarm::SceneConfig& scene)
    : id_(drone_id), cfg_(cfg), scene_(scene), d_int_m_(cfg.inter_distance_m) {
  if (drone_id < 0) throw std::invalid_argument("MissionFsm: drone id must be >= 0");
  cfg_.validate();
  scene_.validate();
  cruise_z_m_ = scene_.ground_z_m + cfg_.takeoff_altitude_m;
}

bool MissionFsm::addressed_to_me(const MissionCommand& c) const {
  return c.target == -1 || c.target == id_;
}

double MissionFsm::clamp_cruise(double z) const {
  const double lo = scene_.ground_z_m + cfg_.min_altitude_m;
  const double hi = std::max(lo, scene_.bounds_max.z() - cfg_.min_altitude_m);
  return std::clamp(z, lo, hi);
}

MissionAck MissionFsm::apply(const MissionCommand& c, const Observation& o) {
  MissionAck ack;
  ack.drone_id = static_cast<std::uint16_t>(id_);
  ack.seq = c.seq;
  ack.tick = o.tick;
  if (!addressed_to_me(c)) {
    ack.reason = "addressed to drone " + std::to_string(c.target);
    ack.phase = phase_;
    return ack;
  }

  auto& log = history_[c.issuer];
  for (const auto& a : log)
    if (a.command.seq == c.seq && same_command(a.command, c)) return a.ack;
  auto high = highest_seq_.find(c.issuer);
  if (high != highest_seq_.end() && c.seq <= high->second) log.clear();  // issuer restarted
  highest_seq_[c.issuer] = c.seq;

  ack.reason = execute(c, o);
  ack.accepted = ack.reason.empty();
  ack.phase = phase_;
  log.push_back({c, ack});
  if (log.size() > kHistoryDepth) log.pop_front();
  return ack;
}

MissionAck MissionFsm::resume(const MissionCommand& c, double applied_at_s, const Observation& o) {
  MissionAck ack;
  ack.drone_id = static_cast<std::uint16_t>(id_);
  ack.seq = c.seq;
  ack.tick = o.tick;
  ack.phase = phase_;
  if (!addressed_to_me(c)) {
    ack.reason = "addressed to drone " + std::to_string(c.target);
    return ack;
  }
  auto& log = history_[c.issuer];
  for (const auto& a : log)
    if (a.command.seq == c.seq && same_command(a.command, c)) return a.ack;
  highest_seq_[c.issuer] = std::max(highest_seq_[c.issuer], c.seq);
  ack.reason = resume_execute(c, applied_at_s, o);
  ack.accepted = ack.reason.empty();
  ack.phase = phase_;
  log.push_back({c, ack});
  if (log.size() > kHistoryDepth) log.pop_front();
  return ack;
}

void MissionFsm::enter(Phase p) {
  if (phase_ == Phase::kTakeoff)
    after_takeoff_ = p;
  else
    phase_ = p;
}

std::string MissionFsm::takeoff_altitude(const MissionCommand& c, double* z) const {
  if (!std::isfinite(c.value) || c.value < 0) return "altitude must be >= 0 (0 = default)";
  const double alt = c.value > 0 ? c.value : cfg_.takeoff_altitude_m;
  if (alt < cfg_.min_altitude_m)
    return "altitude " + to_text(alt) + " m is below agent.min_altitude_m (" +
           to_text(cfg_.min_altitude_m) + ")";
  *z = scene_.ground_z_m + alt;
  if (*z > scene_.bounds_max.z() - cfg_.min_altitude_m)
    return "altitude " + to_text(alt) + " m is above the world bounds";
  return "";
}

std::string MissionFsm::resume_execute(const MissionCommand& c, double at_s, const Observation& o) {
  const bool flying_mission = phase_ != Phase::kIdle && phase_ != Phase::kLanding;
  switch (c.type) {
    case MissionType::kTakeoff: {
      double z = 0;
      if (auto bad = takeoff_altitude(c, &z); !bad.empty()) return bad;
      cruise_z_m_ = z;
      phase_ = Phase::kTakeoff;  // climbs (or settles) to the cruise altitude, then holds
      after_takeoff_ = Phase::kHold;
      return "";
    }
    case MissionType::kLand:
      phase_ = o.on_ground ? Phase::kIdle : Phase::kLanding;
      return "";
    case MissionType::kSetDistance:
      return execute(c, o);
    case MissionType::kMove: {
      if (auto bad = check_velocity(c.velocity, cfg_.max_speed_mps); !bad.empty()) return bad;
      if (!std::isfinite(c.duration_s) || c.duration_s <= 0) return "duration_s must be > 0";
      if (!flying_mission) return "not airborne";
      move_velocity_ = c.velocity;
      move_end_s_ = at_s + c.duration_s;
      enter(o.sim_time_s < move_end_s_ ? Phase::kMove : Phase::kHold);
      return "";
    }
    case MissionType::kTask: {
      if (!std::isfinite(c.value) || c.value < 0) return "speed must be >= 0 (0 = default)";
      if (c.value > cfg_.max_speed_mps) return "speed exceeds agent.max_speed_mps";
      if (!flying_mission) return "not airborne";
      task_speed_mps_ = c.value > 0 ? c.value : cfg_.task_speed_mps;
      enter(Phase::kTask);
      return "";
    }
    case MissionType::kFollowLeader:
      if (c.leader_id < 0) return "leader_id must be a drone id (>= 0)";
      if (!flying_mission) return "not airborne";
      leader_id_ = c.leader_id;
      teleop_velocity_.setZero();
      teleop_time_s_ = at_s;
      enter(Phase::kFollow);
      return "";
    case MissionType::kHold:
      if (!flying_mission) return "not airborne";
      hold_end_s_ = at_s + c.duration_s;
      enter(Phase::kHold);
      return "";
    case MissionType::kTeleop: {
      if (auto bad = check_velocity(c.velocity, cfg_.max_speed_mps); !bad.empty()) return bad;
      const bool following = phase_ == Phase::kFollow ||
                             (phase_ == Phase::kTakeoff && after_takeoff_ == Phase::kFollow);
      if (!following) return "not following a leader";
      teleop_velocity_ = c.velocity;
      teleop_time_s_ = at_s;
      return "";
    }
    case MissionType::kNone:
      break;
  }
  return "unknown command type";
}

std::string MissionFsm::execute(const MissionCommand& c, const Observation& o) {
  // Shared gate for the commands that need the drone up and free.
  auto gate = [&]() -> std::string {
    if (phase_ == Phase::kIdle) return "not airborne";
    if (phase_ == Phase::kTakeoff) return "still taking off";
    if (phase_ == Phase::kLanding) return "landing";
    return "";
  };

  switch (c.type) {
    case MissionType::kTakeoff: {
      double z = 0;
      if (auto bad = takeoff_altitude(c, &z); !bad.empty()) return bad;
      if (phase_ != Phase::kIdle && phase_ != Phase::kLanding) return "already airborne";
      cruise_z_m_ = z;
      phase_ = Phase::kTakeoff;
      after_takeoff_ = Phase::kHold;
      return "";
    }
    case MissionType::kMove: {
      if (auto bad = check_velocity(c.velocity, cfg_.max_speed_mps); !bad.empty()) return bad;
      if (!std::isfinite(c.duration_s) || c.duration_s <= 0) return "duration_s must be > 0";
      if (auto no = gate(); !no.empty()) return no;
      move_velocity_ = c.velocity;
      move_end_s_ = o.sim_time_s + c.duration_s;
      phase_ = Phase::kMove;
      return "";
    }
    case MissionType::kSetDistance: {
      if (!std::isfinite(c.value) || c.value <= 0) return "distance must be > 0";
      if (cfg_.activation.cutoff_m > 0 && c.value >= cfg_.activation.cutoff_m)
        return "distance must be below agent.activation.cutoff_m (" +
               to_text(cfg_.activation.cutoff_m) + ")";
      d_int_m_ = c.value;
      return "";
    }
    case MissionType::kLand:
      if (phase_ != Phase::kIdle) phase_ = Phase::kLanding;
      return "";
    case MissionType::kFollowLeader: {
      if (c.leader_id < 0) return "leader_id must be a drone id (>= 0)";
      if (auto no = gate(); !no.empty()) return no;
      leader_id_ = c.leader_id;
      teleop_velocity_.setZero();
      teleop_time_s_ = o.sim_time_s;
      phase_ = Phase::kFollow;
      return "";
    }
    case MissionType::kTask: {
      if (!std::isfinite(c.value) || c.value < 0) return "speed must be >= 0 (0 = default)";
      if (c.value > cfg_.max_speed_mps)
        return "speed " + to_text(c.value) + " m/s exceeds agent.max_speed_mps (" +
               to_text(cfg_.max_speed_mps) + ")";
      if (auto no = gate(); !no.empty()) return no;
      task_speed_mps_ = c.value > 0 ? c.value : cfg_.task_speed_mps;
      phase_ = Phase::kTask;
      return "";
    }
    case MissionType::kHold:
      if (phase_ == Phase::kIdle) return "not airborne";
      if (phase_ == Phase::kTakeoff) return "still taking off";
      if (phase_ == Phase::kLanding) cruise_z_m_ = clamp_cruise(o.p_world.z());
      phase_ = Phase::kHold;
      hold_end_s_ = o.sim_time_s + c.duration_s;
      return "";
    case MissionType::kTeleop: {
      if (auto bad = check_velocity(c.velocity, cfg_.max_speed_mps); !bad.empty()) return bad;
      if (phase_ != Phase::kFollow) return "not following a leader";
      teleop_velocity_ = c.velocity;
      teleop_time_s_ = o.sim_time_s;
      return "";
    }
    case MissionType::kNone:
      break;
  }
  return "unknown command type";
}

MissionOutput MissionFsm::step(const Observation& o) {
  const double dt = have_time_ ? std::max(0.0, o.sim_time_s - last_time_s_) : 0.0;
  have_time_ = true;
  last_time_s_ = o.sim_time_s;

  switch (phase_) {
    case Phase::kTakeoff:
      if (std::abs(o.p_world.z() - cruise_z_m_) <= cfg_.altitude_tolerance_m) {
        phase_ = after_takeoff_;
        after_takeoff_ = Phase::kHold;
      }
      break;
    case Phase::kMove:
      if (o.sim_time_s >= move_end_s_) phase_ = Phase::kHold;
      break;
    case Phase::kTask:
      if (scene_.past_finish(o.p_world.head<2>())) phase_ = Phase::kSwarm;
      break;
    case Phase::kLanding:
      if (o.on_ground) phase_ = Phase::kIdle;
      break;
    default:
      break;
  }
  if (phase_ != Phase::kFollow) leader_id_ = -1;

  MissionOutput out;
  out.phase = phase_;
  out.inter_distance_m = d_int_m_;
  out.motors_on = phase_ != Phase::kIdle;
  out.swarm_enabled = out.motors_on && !o.on_ground;
  out.obstacle_avoidance_enabled = out.swarm_enabled;
  out.altitude_target_m = cruise_z_m_;
  out.altitude_hold = cfg_.altitude_hold;

  switch (phase_) {
    case Phase::kIdle:
      out.altitude_target_m = o.p_world.z();
      out.altitude_hold = false;
      break;
    case Phase::kTakeoff:
      out.altitude_hold = true;
      out.busy = true;
      break;
    // Waiting for the operator: the lockstep clock may pause, so the next
    // command lands on a tick the simulation chose, not the operator's wall clock.
    case Phase::kHold:
      out.busy = o.sim_time_s < hold_end_s_;
      break;
    case Phase::kSwarm: {
      // Gather around the goal (thesis §3.1: "reaches it, and swarms around
      // it"), so the swarm settles past the line rather than straddling it.
      const Eigen::Vector2d to_goal = scene_.goal_xy - o.p_world.head<2>();
      Eigen::Vector2d v = cfg_.goal_gain * to_goal;
      if (v.norm() > task_speed_mps_) v *= task_speed_mps_ / v.norm();
      out.mission_velocity = Eigen::Vector3d(v.x(), v.y(), 0.0);
      break;
    }
    case Phase::kMove:
      out.mission_velocity = move_velocity_;
      out.busy = true;
      break;
    case Phase::kTask: {
      const Eigen::Vector2d dir = scene_.task_direction();
      out.mission_velocity = Eigen::Vector3d(dir.x(), dir.y(), 0.0) * task_speed_mps_;
      out.busy = true;
      break;
    }
    case Phase::kFollow:
      if (leader_id_ == id_) {
        // The leader is the pilot's drone (the thesis's RC drone): it flies the
        // teleop velocity, not pulled back by its followers; obstacles still count.
        out.swarm_enabled = false;
        if (o.sim_time_s - teleop_time_s_ <= cfg_.teleop_timeout_s)
          out.mission_velocity = teleop_velocity_;
      }
      out.busy = true;
      break;
    case Phase::kLanding:
      out.mission_velocity = Eigen::Vector3d(0, 0, -cfg_.landing_speed_mps);
      out.swarm_horizontal_only = true;
      out.altitude_hold = false;
      out.altitude_target_m = scene_.ground_z_m;
      out.busy = true;
      break;
    case Phase::kFailsafe:
      break;
  }
  // A vertical mission velocity carries the cruise altitude along with it.
  if (out.altitude_hold && phase_ != Phase::kTakeoff && out.mission_velocity.z() != 0.0) {
    cruise_z_m_ = clamp_cruise(cruise_z_m_ + out.mission_velocity.z() * dt);
    out.altitude_target_m = cruise_z_m_;
  }
  return out;
}

void set_mission(LawInput& in, const MissionOutput& out) {
  in.mission_velocity = out.mission_velocity;
  in.inter_distance_m = out.inter_distance_m;
  in.swarm_enabled = out.swarm_enabled;
  in.obstacle_avoidance_enabled = out.obstacle_avoidance_enabled;
  in.altitude_hold = out.altitude_hold;
  in.altitude_target_m = out.altitude_target_m;
  in.swarm_horizontal_only = out.swarm_horizontal_only;
}

}  // namespace ddswarm::agent
