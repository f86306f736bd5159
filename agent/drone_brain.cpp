#include "agent/drone_brain.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <exception>

#include "agent/law_frame.hpp"
#include "agent/law_registry.hpp"
#include "common/config_error.hpp"

namespace ddswarm::agent {

namespace {
/// Commands remembered per brain, so the ring's repeats are handled once.
constexpr std::size_t kSeenMissions = 1024;

BrainNote note(BrainNote::Level level, std::string text) { return {level, std::move(text)}; }
}  // namespace

DroneBrain::DroneBrain(int id, std::uint64_t instance, const AgentConfig& agent,
                       const CommConfig& comm, int num_drones)
    : id_(id),
      instance_(instance),
      agent_(agent),
      comm_(comm),
      num_drones_(num_drones),
      law_cfg_(&agent.law_for(id)),
      truth_(id) {}

DroneBrain::~DroneBrain() = default;

Phase DroneBrain::phase() const {
  if (!law_fault_.empty()) return Phase::kFailsafe;
  return fsm_ ? fsm_->phase() : Phase::kIdle;
}

double DroneBrain::inter_distance_m() const {
  return fsm_ ? fsm_->inter_distance_m() : agent_.inter_distance_m;
}

std::vector<BrainNote> DroneBrain::start(const SceneConfig& scene, double control_rate_hz,
                                         std::uint64_t seed) {
  TickAnswer a;  // its notes
  control_period_s_ = 1.0 / control_rate_hz;
  ground_z_m_ = scene.ground_z_m;
  goal_xy_ = scene.goal_xy;
  fsm_ = std::make_unique<MissionFsm>(id_, agent_, scene);
  law::LawContext ctx;
  ctx.drone_id = id_;
  ctx.num_drones = num_drones_;
  ctx.inter_distance_m = agent_.inter_distance_m;
  ctx.max_speed_mps = agent_.max_speed_mps;
  ctx.control_period_s = control_period_s_;
  try {
    law_ = make_law(*law_cfg_, ctx, law::Rng(law_seed(seed, id_)), agent_);
  } catch (const std::exception& e) {
    // Checked when the config was read; a law can still fail on what only
    // the scene says (its control rate).
    fault(std::string("could not be built: ") + e.what(), 0.0, a);
  }
  if (!comm_.ideal()) {
    modelled_ = std::make_unique<ModelledPeerSource>(comm_, seed, id_, control_period_s_);
    peers_ = modelled_.get();
  }
  return std::move(a.notes);
}

void DroneBrain::reset() {
  fsm_.reset();
  law_.reset();
  modelled_.reset();
  peers_ = &truth_;
  seen_missions_.clear();
  seen_order_.clear();
  fed_tick_ = ~0ULL;
  caught_up_ = false;
  last_answer_.reset();
}

void DroneBrain::fault(const std::string& why, double t, TickAnswer& a) {
  ++law_faults_;
  if (!law_fault_.empty()) return;
  law_fault_ = one_line(why);
  law_fault_at_s_ = t;
  a.notes.push_back(
      note(BrainNote::Level::kError,
           fmt::format("drone {}: the {} law faulted at sim time {:.2f} s: {}; the "
                       "drone hovers {:.0f} s, then lands, and takes no mission command",
                       id_, law_cfg_->name(), t, law_fault_, kLawFaultHoverS)));
}

/// A faulted law's drone: hovers where it is, then lands through its mission
/// machine; the law is not asked again.
void DroneBrain::fly_fault(LawInput& in, MissionOutput& out, const Observation& obs) {
  in.swarm_enabled = false;
  if (out.phase == Phase::kIdle || out.phase == Phase::kLanding) return;
  if (obs.sim_time_s - law_fault_at_s_ < kLawFaultHoverS) {
    in.mission_velocity.setZero();
    out.busy = true;
    return;
  }
  if (!fault_landing_) {
    fault_landing_ = true;
    MissionCommand land;
    land.type = MissionType::kLand;
    land.target = id_;
    land.seq = 1;
    land.issuer = "law-fault";
    fsm_->apply(land, obs);
    out = fsm_->step(obs);
    set_mission(in, out);
    in.swarm_enabled = false;
  }
}

void DroneBrain::handle_missions(const SwarmTick& t, const Observation& obs, TickAnswer& a) {
  // The first tick after joining: commands the swarm applied before this
  // agent was here are caught up with (a restarted agent rejoins its mission).
  const bool joining = !caught_up_;
  caught_up_ = true;
  const auto id16 = static_cast<std::uint16_t>(id_);
  for (const auto& m : t.missions) {
    const MissionCommand& c = m.command;
    const auto key = std::make_pair(m.issuer_instance, c.seq);
    auto it = seen_missions_.find(key);
    // Same command at the same apply tick: already handled (the ring repeats every tick).
    if (it != seen_missions_.end() && it->second == m.apply_tick) continue;
    if (it == seen_missions_.end()) {
      seen_order_.push_back(key);
      if (seen_order_.size() > kSeenMissions) {
        seen_missions_.erase(seen_order_.front());
        seen_order_.pop_front();
      }
    }
    // A new apply tick for a known command is a repeat: the mission machine
    // returns the ack it gave then and changes nothing, so it is acknowledged
    // again, applied once.
    seen_missions_[key] = m.apply_tick;
    if (!m.problem.empty()) {
      ++rejected_;
      a.acks.push_back({{id16, c.seq, false, m.problem, fsm_->phase(), t.tick}, m.issuer_instance});
      continue;
    }
    if (!fsm_->addressed_to_me(c)) continue;
    if (!law_fault_.empty()) {
      a.acks.push_back(
          {{id16, c.seq, false, "swarm law faulted: " + law_fault_, fsm_->phase(), t.tick},
           m.issuer_instance});
      continue;
    }
    const bool caught_up = joining && m.apply_tick < t.tick;
    MissionAck ack =
        caught_up ? fsm_->resume(c, static_cast<double>(m.apply_tick) * control_period_s_, obs)
                  : fsm_->apply(c, obs);
    if (ack.accepted) {  // relayed by the server (SimStatus.mission_seq, mission_issuer)
      last_mission_seq_ = c.seq;
      last_mission_issuer_ = m.issuer_instance;
    }
    const std::string why = ack.accepted ? "" : ": " + ack.reason;
    a.notes.push_back(note(
        BrainNote::Level::kInfo,
        caught_up
            ? fmt::format("drone {}: joined mid-mission: caught up with {} seq {} of tick {}{}",
                          id_, to_string(c.type), c.seq, m.apply_tick, why)
            : fmt::format("drone {}: {} seq {} {} at tick {}{}", id_, to_string(c.type), c.seq,
                          ack.accepted ? "accepted" : "rejected", t.tick, why)));
    a.acks.push_back({std::move(ack), m.issuer_instance});
  }
}

/// Each tick's truth and beacons go to the peer source once, even when the
/// server sends the same tick again while it waits. own_p: the drone's own
/// position as its law knows it.
void DroneBrain::feed_peers(const SwarmTick& t, const DroneRow& me, bool new_tick,
                            Eigen::Vector3d& own_p) {
  own_p = me.p_world;
  if (!modelled_) {
    if (new_tick) peers_->on_truth(t.sim_time_s, t.roster);  // skips its own id
    return;
  }
  if (new_tick) {
    modelled_->set_tick(t.tick, t.sim_time_s, me.p_world);
    modelled_->on_truth(t.sim_time_s, t.roster);  // skips its own id
    for (const auto& bc : t.beacons) {
      if (bc.sender == id_ || bc.sender < 0 ||
          static_cast<std::size_t>(bc.sender) >= t.drones.size())
        continue;
      modelled_->on_beacon(bc, me.p_world);
    }
  }
  own_p = modelled_->channel().noisy_own_position(me.p_world, t.tick);
}

/// What the law is shown: its own state as it knows it, the peers its source
/// delivers (in.peers_world, in the source's order), the scan.
law::Observation DroneBrain::observe(const LawInput& in, const MissionOutput& out,
                                     const Observation& obs, const SwarmTick& t) {
  law::Observation o;
  o.drone_id = id_;
  o.tick = t.tick;
  o.sim_time_s = t.sim_time_s;
  o.dt_s = control_period_s_;
  o.p_world = in.p_world;
  o.v_world = obs.v_world;
  o.q_world_body = in.q_world_body;
  law_peers_.clear();
  auto add = [&](std::size_t k, const PeerObservation& h) {
    const Eigen::Vector3d p = k < in.peers_world.size() ? in.peers_world[k] : h.p_world;
    law_peers_.push_back({h.id, p, h.v_world, t.sim_time_s - h.stamp_s});
  };
  if (modelled_) {
    const auto heard = modelled_->heard(t.sim_time_s);
    for (std::size_t k = 0; k < heard.size(); ++k) add(k, heard[k]);
  } else {
    std::size_t k = 0;
    for (const auto& r : t.roster)
      if (r.id != id_) add(k++, r);
  }
  law_rays_.clear();
  for (std::size_t k = 0; k < in.ray_range_m.size(); ++k)
    law_rays_.push_back({in.ray_range_m[k], in.ray_hit[k] != 0, in.ray_yaw_body_rad[k],
                         in.ray_elevation_body_rad.empty() ? 0.0 : in.ray_elevation_body_rad[k]});
  o.peers = law_peers_;
  o.rays = law_rays_;
  o.phase = static_cast<law::Phase>(out.phase);
  o.mission_velocity = in.mission_velocity;
  if (out.phase == Phase::kTask || out.phase == Phase::kSwarm)
    o.goal_world = Eigen::Vector3d(goal_xy_.x(), goal_xy_.y(), out.altitude_target_m);
  o.inter_distance_m = in.inter_distance_m;
  o.altitude_target_m = in.altitude_target_m;
  o.max_speed_mps = agent_.max_speed_mps;
  return o;
}

/// This tick's command: the drone's law inside the framework (step_law). A
/// law that throws or answers a non-finite number faults here, and its drone
/// starts to hover this very tick.
LawTerms DroneBrain::command(LawInput& in, MissionOutput& out, const Observation& obs,
                             const SwarmTick& t, TickAnswer& a) {
  // The thesis's own law, as configured by default: evaluate_law from the
  // peer positions the brain already holds. Through the interface it gives
  // the same command bit for bit (agent_law_frame_test), but building its
  // Observation copies every peer twice a tick: 260,000 copies a tick in a
  // 512-drone agent host.
  if (law_cfg_->plain_thesis()) return evaluate_law(in, agent_);
  law::SwarmLaw* l = law_fault_.empty() ? law_.get() : nullptr;
  LawStep r = l && in.swarm_enabled ? step_law(l, observe(in, out, obs, t), in, agent_)
                                    : step_law(nullptr, {}, in, agent_);
  if (!r.fault.empty()) {
    fault(r.fault, obs.sim_time_s, a);
    fly_fault(in, out, obs);
    r = step_law(nullptr, {}, in, agent_);
  }
  yaw_rate_rad_s_ = r.yaw_rate_rad_s;
  return r.terms;
}

TickAnswer DroneBrain::tick(const SwarmTick& t) {
  TickAnswer a;
  if (!fsm_) return a;
  const DroneRow* me = t.row(id_);
  if (!me || !me->valid) {
    ++rejected_;
    return a;
  }
  if (last_answer_ && last_answer_->tick == t.tick) {
    a.kind = TickAnswer::Kind::kRepeat;
    a.command = *last_answer_;
    return a;
  }
  a.kind = TickAnswer::Kind::kFresh;

  Observation obs;
  obs.sim_time_s = t.sim_time_s;
  obs.tick = t.tick;
  obs.p_world = me->p_world;
  obs.v_world = me->v_world;
  obs.on_ground = obs.p_world.z() < ground_z_m_ + 0.15 && obs.v_world.norm() < 0.5;
  handle_missions(t, obs, a);

  const bool new_tick = t.tick != fed_tick_;
  fed_tick_ = t.tick;
  Eigen::Vector3d own_p;
  feed_peers(t, *me, new_tick, own_p);

  MissionOutput out = fsm_->step(obs);
  LawInput in;
  in.p_world = own_p;
  in.q_world_body = me->q_world_body.normalized();
  const auto& peer_pos = peers_->peers(t.sim_time_s);
  if (modelled_ && comm_.range_measurements) {
    // A law that uses distances: direction from the position estimates,
    // magnitude from the (noisy) UWB range to that peer.
    ranged_.clear();
    for (const auto& h : modelled_->heard(t.sim_time_s)) {
      const Eigen::Vector3d d = h.p_world - own_p;
      const auto r = modelled_->range_to(h.id);
      ranged_.push_back(r && d.norm() > 1e-6 ? Eigen::Vector3d(own_p + d.normalized() * *r)
                                             : h.p_world);
    }
    in.peers_world = ranged_;
  } else {
    in.peers_world = peer_pos;
  }
  std::size_t rays = me->ray_range_m.size();
  bool sound = me->ray_hit.size() == rays && me->ray_yaw_body_rad.size() == rays &&
               me->ray_elevation_body_rad.size() == rays;
  for (std::size_t j = 0; sound && j < rays; ++j)
    sound = std::isfinite(me->ray_yaw_body_rad[j]) && std::isfinite(me->ray_elevation_body_rad[j]);
  if (!sound) {  // which ray points where is unknown: none is flown from
    rays = 0;
    ++rejected_;
  }
  ranges_.assign(me->ray_range_m.begin(), me->ray_range_m.begin() + rays);
  hits_.assign(me->ray_hit.begin(), me->ray_hit.begin() + rays);
  angles_.assign(me->ray_yaw_body_rad.begin(), me->ray_yaw_body_rad.begin() + rays);
  elevations_.assign(me->ray_elevation_body_rad.begin(), me->ray_elevation_body_rad.begin() + rays);
  for (std::size_t j = 0; j < rays; ++j)
    if (!std::isfinite(ranges_[j])) {
      hits_[j] = 0;
      ++rejected_;
    }
  in.ray_range_m = ranges_;
  in.ray_hit = hits_;
  in.ray_yaw_body_rad = angles_;
  in.ray_elevation_body_rad = elevations_;
  set_mission(in, out);
  if (!law_fault_.empty()) fly_fault(in, out, obs);
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  if (out.motors_on) v = command(in, out, obs, t, a).velocity;
  if (!law_fault_.empty()) out.phase = Phase::kFailsafe;

  DroneCommand& cmd = a.command;
  cmd.drone_id = id_;
  cmd.tick = t.tick;
  cmd.sim_time_s = t.sim_time_s;
  cmd.velocity = v;
  cmd.yaw_rate_rad_s = yaw_rate_rad_s_;
  cmd.motors_on = out.motors_on;
  cmd.phase = out.phase;
  cmd.busy = out.busy;
  cmd.mission_seq = last_mission_seq_;
  cmd.mission_issuer = last_mission_issuer_;
  cmd.agent_instance = instance_;
  if (modelled_ && comm_.source == PeerSourceType::kBeacons && modelled_->beacon_due(t.tick)) {
    cmd.beacon = modelled_->beacon(t.tick, t.sim_time_s, obs.p_world);
    cmd.beacon_velocity = me->v_world;
    a.publish_beacon = new_tick;
  }
  last_answer_ = cmd;
  ++sent_;
  return a;
}

}  // namespace ddswarm::agent
