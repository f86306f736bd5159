#include "agent/agent_app.hpp"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cmath>
#include <mutex>
#include <optional>
#include <random>
#include <deque>
#include <map>
#include <set>

#include "agent/comm_model.hpp"
#include "agent/mission_fsm.hpp"
#include "agent/peer_source.hpp"
#include "agent/swarm_law.hpp"
#include "common/convert.hpp"
#include "common/participant.hpp"
#include "common/process.hpp"

namespace ddswarm::agent {

void AgentAppConfig::validate() const {
  scenario.validate();
  agent.validate();
  comm.validate();
  dds.validate();
  if (drone_id < 0 || drone_id >= scenario.drones)
    throw FieldError("--id", std::to_string(drone_id),
                     "must be in [0, " + std::to_string(scenario.drones - 1) + "]");
}

AgentAppConfig load_agent_config(const std::string& path) {
  auto doc = load_scenario(path);
  AgentAppConfig c;
  doc.guard([&] {
    load(doc.section("scenario"), c.scenario);
    load(doc.section("agent"), c.agent);
    load(doc.section("comm"), c.comm);
    load(doc.section("dds"), c.dds);
    c.scenario.validate();
    c.agent.validate();
    c.comm.validate();
    c.dds.validate();
  });
  return c;
}

namespace {

SceneConfig scene_from_msg(const msg::Scene& s) {
  SceneConfig c;
  c.ground_z_m = s.ground_z_m();
  for (const auto& cy : s.cylinders())
    c.cylinders.push_back({Eigen::Vector2d(cy.x(), cy.y()), cy.radius_m(), cy.height_m()});
  for (const auto& b : s.boxes()) c.boxes.push_back({from_msg(b.center()), from_msg(b.size()), b.yaw_rad()});
  c.bounds_min = from_msg(s.bounds_min());
  c.bounds_max = from_msg(s.bounds_max());
  c.finish_a = from_msg(s.finish_a()).head<2>();
  c.finish_b = from_msg(s.finish_b()).head<2>();
  c.goal_xy = from_msg(s.goal()).head<2>();
  c.start.center_xy = from_msg(s.start_center()).head<2>();
  return c;
}

bool finite(const msg::Vec3& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

}  // namespace

struct AgentApp::Impl {
  AgentAppConfig cfg;
  const int id;
  const std::uint64_t instance;
  Participant dds;
  Writer<msg::VelocityCommand> w_cmd;
  Writer<msg::AgentStatus> w_status;
  Writer<msg::MissionAck> w_ack;
  Writer<msg::Beacon> w_beacon;

  std::mutex mu;  // guards everything below (DDS callbacks run on Fast DDS threads)
  std::optional<SceneConfig> scene;
  eprosima::fastrtps::rtps::GuidPrefix_t server;  // the scene's publisher
  std::uint64_t server_instance = 0;              // its Scene.server_instance
  double control_period_s = 0.02;
  bool caught_up = false;  // the mission in force (the ring) was taken from the first sample
  std::unique_ptr<MissionFsm> fsm;
  TruthPeerSource truth;
  std::unique_ptr<ModelledPeerSource> modelled;  // when comm asks for more than exact truth
  PeerSource* peers = &truth;
  std::uint64_t fed_tick = ~0ULL;  // the tick whose truth and beacons the peer source has taken
  // (issuer, seq) -> the apply_tick it came with; oldest first for pruning.
  std::map<std::pair<std::uint64_t, std::uint32_t>, std::uint64_t> seen_missions;
  std::deque<std::pair<std::uint64_t, std::uint32_t>> seen_order;
  std::uint32_t last_mission_seq = 0;
  std::uint64_t last_tick = 0;
  bool have_tick = false;
  double last_sample_wall = -1e9;
  bool server_lost = false;
  bool flying = false;  // passed the duplicate probe
  std::uint64_t rejected = 0, sent = 0;
  std::uint64_t rival = 0;  // another instance heard on our id
  std::string rival_where;
  std::vector<PeerObservation> others;
  std::vector<Eigen::Vector3d> ranged;
  std::vector<float> ranges, angles;
  std::vector<std::uint8_t> hits;

  // DDS callbacks touch the members below: stop them before anything is destroyed.
  ~Impl() { dds.close(); }

  explicit Impl(AgentAppConfig c)
      : cfg(std::move(c)),
        id(cfg.drone_id),
        instance(random_instance()),
        dds(cfg.dds, "ddswarm-agent-" + std::to_string(cfg.drone_id)),
        // Under DDS Security only agent-K may publish in drone K's partition.
        w_cmd(dds.writer<msg::VelocityCommand>(cfg.dds.secure() ? drone_partition(cfg.drone_id) : "")),
        w_status(dds.writer<msg::AgentStatus>()),
        w_ack(dds.writer<msg::MissionAck>()),
        w_beacon(dds.writer<msg::Beacon>()) {
    dds.reader<msg::AgentStatus>([this](const msg::AgentStatus& s, const fdds::SampleInfo&) {
      if (s.drone_id() != id || s.agent_instance() == instance) return;
      std::lock_guard<std::mutex> lock(mu);
      rival = s.agent_instance();
      rival_where = s.host().to_string() + " pid " + std::to_string(s.pid());
    });
    dds.reader<msg::Scene>([this](const msg::Scene& s, const fdds::SampleInfo& info) {
      std::lock_guard<std::mutex> lock(mu);
      // The participant that announces the scene is the server: swarm samples
      // are taken from it alone. A restarted server announces itself again.
      server = info.sample_identity.writer_guid().guidPrefix;
      if (s.num_drones() <= id) {
        spdlog::error("drone {}: the server flies only {} drones", id, s.num_drones());
        return;
      }
      if (fsm && s.server_instance() == server_instance) return;  // a re-announcement: keep the mission
      if (fsm) {
        // A restarted server is a new world: the drone is back at its start,
        // so the old mission no longer applies. Start over and catch up with
        // whatever the new server's ring says.
        spdlog::warn("drone {}: new server instance {:016x} (was {:016x}): mission reset", id,
                     s.server_instance(), server_instance);
        fsm.reset();
        modelled.reset();
        peers = &truth;
        seen_missions.clear();
        seen_order.clear();
        have_tick = false;
        fed_tick = ~0ULL;
      }
      server_instance = s.server_instance();
      control_period_s = 1.0 / s.control_rate_hz();
      caught_up = false;
      scene = scene_from_msg(s);
      fsm = std::make_unique<MissionFsm>(id, cfg.agent, *scene);
      if (!cfg.comm.ideal()) {
        const double tick_s = 1.0 / s.control_rate_hz();
        const double ticks_per_beacon = s.control_rate_hz() / cfg.comm.beacon_rate_hz;
        if (cfg.comm.source == PeerSourceType::kBeacons &&
            std::abs(ticks_per_beacon - std::round(ticks_per_beacon)) > 1e-9)
          spdlog::warn("drone {}: comm.beacon_rate_hz {} does not divide the control rate {} Hz; "
                       "beacons go every {} ticks",
                       id, cfg.comm.beacon_rate_hz, s.control_rate_hz(), std::round(ticks_per_beacon));
        modelled = std::make_unique<ModelledPeerSource>(cfg.comm, s.seed(), id, tick_s);
        peers = modelled.get();
        spdlog::info("drone {}: peers from {} through the communication model", id,
                     cfg.comm.source == PeerSourceType::kBeacons ? "beacons" : "truth");
      }
      spdlog::info("drone {}: scene '{}' received", id, s.name().to_string());
      const double reach = sensor_range_m(cfg.agent.sensor_function);
      if (reach > s.sensor_max_range_m() + 1e-6)
        spdlog::warn("drone {}: agent.sensor_function reacts up to {:.1f} m but the sensors "
                     "(sensors.max_range_m) see only {:.1f} m: the reaction jumps when an obstacle "
                     "comes into view",
                     id, reach, s.sensor_max_range_m());
    });
    // Listen before speaking: refuse to fly a drone another agent already flies.
    wait_for_stop(std::chrono::duration<double>(cfg.duplicate_probe_s));
    {
      std::lock_guard<std::mutex> lock(mu);
      if (rival)
        throw DuplicateAgent("drone " + std::to_string(id) + " is already flown by agent " +
                             fmt::format("{:016x}", rival) + " (" + rival_where + ")");
      flying = true;
    }
    publish_status();
    dds.reader<msg::SwarmState>([this](const msg::SwarmState& s, const fdds::SampleInfo& info) {
      on_swarm(s, info.sample_identity.writer_guid().guidPrefix);
    });
  }

  void publish_status() {
    msg::AgentStatus s;
    {
      std::lock_guard<std::mutex> lock(mu);
      s.drone_id(static_cast<std::uint16_t>(id));
      s.agent_instance(instance);
      char host[64] = {};
      gethostname(host, sizeof host - 1);
      s.host(host);
      s.pid(getpid());
      s.phase(static_cast<std::uint8_t>(fsm ? fsm->phase() : Phase::kIdle));
      s.server_lost(server_lost);
      s.last_tick(last_tick);
      s.inter_distance_m(fsm ? fsm->inter_distance_m() : cfg.agent.inter_distance_m);
      s.rejected_samples(static_cast<std::uint32_t>(rejected + malformed_samples().load()));
      s.commands_sent(static_cast<std::uint32_t>(sent));
    }
    w_status.write(s);
  }

  /// One server tick: check the sample, apply new mission commands, run the law, answer.
  void on_swarm(const msg::SwarmState& s, const eprosima::fastrtps::rtps::GuidPrefix_t& from) {
    std::lock_guard<std::mutex> lock(mu);
    if (!fsm) return;  // no scene yet
    if (from != server) {  // not the server that announced the scene
      ++rejected;
      return;
    }
    if (s.drones().size() <= static_cast<std::size_t>(id) || s.drones()[id].drone_id() != id) {
      ++rejected;
      return;
    }
    const auto& me = s.drones()[id];
    if (!finite(me.position()) || !finite(me.velocity()) || !std::isfinite(s.sim_time_s())) {
      ++rejected;
      return;
    }
    if (have_tick && s.tick() < last_tick) {
      if (!server_lost) {  // a restarted server starts again from 0; anything else is stale
        ++rejected;
        return;
      }
    }
    last_sample_wall = wall_seconds();
    if (server_lost) {
      spdlog::info("drone {}: server samples resumed at tick {}", id, s.tick());
      server_lost = false;
    }
    have_tick = true;
    last_tick = s.tick();

    Observation obs;
    obs.sim_time_s = s.sim_time_s();
    obs.tick = s.tick();
    obs.p_world = from_msg(me.position());
    obs.v_world = from_msg(me.velocity());
    obs.on_ground = obs.p_world.z() < scene->ground_z_m + 0.15 && obs.v_world.norm() < 0.5;

    // The first sample after joining: commands the swarm applied before this
    // agent was here are caught up with (a restarted agent rejoins its mission).
    const bool joining = !caught_up;
    caught_up = true;
    for (const auto& m : s.recent_commands()) {
      const auto key = std::make_pair(m.issuer_instance(), m.seq());
      auto it = seen_missions.find(key);
      // Same command at the same apply tick: already handled (the ring repeats every tick).
      if (it != seen_missions.end() && it->second == m.apply_tick()) continue;
      if (it == seen_missions.end()) {
        seen_order.push_back(key);
        if (seen_order.size() > 1024) {
          seen_missions.erase(seen_order.front());
          seen_order.pop_front();
        }
      }
      // A new apply tick for a known command is a repeat: the FSM returns the
      // ack it gave then and changes nothing, so it is acknowledged again, applied once.
      seen_missions[key] = m.apply_tick();
      MissionCommand c = from_msg(m);
      if (!mission_problem(m).empty()) {
        ++rejected;
        MissionAck a{static_cast<std::uint16_t>(id), m.seq(), false, mission_problem(m), fsm->phase(), s.tick()};
        w_ack.write(to_msg(a, m.issuer_instance()));
        continue;
      }
      if (!fsm->addressed_to_me(c)) continue;
      if (joining && m.apply_tick() < s.tick()) {
        MissionAck a = fsm->resume(c, static_cast<double>(m.apply_tick()) * control_period_s, obs);
        last_mission_seq = m.seq();
        w_ack.write(to_msg(a, m.issuer_instance()));
        spdlog::info("drone {}: joined mid-mission: caught up with {} seq {} of tick {}{}", id,
                     to_string(c.type), c.seq, m.apply_tick(), a.accepted ? "" : ": " + a.reason);
        continue;
      }
      MissionAck a = fsm->apply(c, obs);
      last_mission_seq = m.seq();
      w_ack.write(to_msg(a, m.issuer_instance()));
      spdlog::info("drone {}: {} seq {} {} at tick {}{}", id, to_string(c.type), c.seq,
                   a.accepted ? "accepted" : "rejected", s.tick(), a.accepted ? "" : ": " + a.reason);
    }

    others.clear();
    for (const auto& d : s.drones()) {
      if (d.drone_id() == id) continue;
      // A drone without a live agent (lost: the server's failsafe flies it,
      // hovering then landing) is no member of the swarm: no attraction to
      // it, or the swarm would stay tied to a wreck. The distance sensors
      // still see it as an obstacle.
      if (!(d.flags() & msg::DRONE_AGENT_LIVE) || (d.flags() & msg::DRONE_FAILSAFE)) continue;
      if (!finite(d.position())) {
        ++rejected;
        continue;
      }
      others.push_back({d.drone_id(), from_msg(d.position()), d.sim_time_s()});
    }
    // Each tick's truth and beacons go to the peer source once, even when the
    // server re-sends the same tick while it waits.
    const bool new_tick = s.tick() != fed_tick;
    fed_tick = s.tick();
    Eigen::Vector3d own_p = obs.p_world;
    if (modelled) {
      if (new_tick) {
        modelled->set_tick(s.tick(), s.sim_time_s(), obs.p_world);
        modelled->on_truth(s.sim_time_s(), others);
        for (const auto& b : s.beacons()) {
          if (b.drone_id() == id || b.drone_id() >= s.drones().size()) continue;
          PeerMessage pm{b.drone_id(), b.tick(), b.stamp_s(), from_msg(b.position()), from_msg(b.true_position())};
          modelled->on_beacon(pm, obs.p_world);
        }
      }
      own_p = modelled->channel().noisy_own_position(obs.p_world, s.tick());
    } else if (new_tick) {
      peers->on_truth(s.sim_time_s(), others);
    }

    MissionOutput out = fsm->step(obs);
    LawInput in;
    in.p_world = own_p;
    in.q_world_body = from_msg(me.orientation()).normalized();
    const auto& peer_pos = peers->peers(s.sim_time_s());
    ranged.clear();
    if (modelled && cfg.comm.range_measurements) {
      // A law that uses distances: direction from the position estimates,
      // magnitude from the (noisy) UWB range to that peer.
      for (const auto& h : modelled->heard(s.sim_time_s())) {
        Eigen::Vector3d d = h.p_world - own_p;
        auto r = modelled->range_to(h.id);
        ranged.push_back(r && d.norm() > 1e-6 ? Eigen::Vector3d(own_p + d.normalized() * *r) : h.p_world);
      }
      in.peers_world = ranged;
    } else {
      in.peers_world = peer_pos;
    }
    if (s.scans().size() > static_cast<std::size_t>(id)) {
      const auto& sc = s.scans()[id];
      std::size_t k = std::min({sc.range_m().size(), sc.hit().size(), sc.angle_body_rad().size()});
      ranges.assign(sc.range_m().begin(), sc.range_m().begin() + k);
      hits.assign(sc.hit().begin(), sc.hit().begin() + k);
      angles.assign(sc.angle_body_rad().begin(), sc.angle_body_rad().begin() + k);
      for (std::size_t j = 0; j < k; ++j)
        if (!std::isfinite(ranges[j])) {
          hits[j] = 0;
          ++rejected;
        }
    }
    in.ray_range_m = ranges;
    in.ray_hit = hits;
    in.ray_yaw_body_rad = angles;
    in.mission_velocity = out.mission_velocity;
    in.inter_distance_m = out.inter_distance_m;
    in.swarm_enabled = out.swarm_enabled;
    in.obstacle_avoidance_enabled = out.obstacle_avoidance_enabled;
    in.altitude_hold = out.altitude_hold;
    in.swarm_horizontal_only = out.swarm_horizontal_only;
    in.altitude_target_m = out.altitude_target_m;
    Eigen::Vector3d v = out.motors_on ? control_velocity(in, cfg.agent) : Eigen::Vector3d::Zero();

    msg::VelocityCommand cmd;
    cmd.drone_id(static_cast<std::uint16_t>(id));
    cmd.tick(s.tick());
    cmd.sim_time_s(s.sim_time_s());
    cmd.velocity(to_msg(v));
    cmd.yaw_rate_rad_s(0.0);  // heading held: the sensors keep their layout (thesis)
    cmd.motors_on(out.motors_on);
    cmd.phase(static_cast<std::uint8_t>(out.phase));
    cmd.busy(out.busy);
    cmd.mission_seq(last_mission_seq);
    cmd.agent_instance(instance);
    if (modelled && cfg.comm.source == PeerSourceType::kBeacons && modelled->beacon_due(s.tick())) {
      PeerMessage b = modelled->beacon(s.tick(), s.sim_time_s(), obs.p_world);
      msg::Beacon& m = cmd.own_beacon();
      m.drone_id(static_cast<std::uint16_t>(id));
      m.tick(s.tick());
      m.stamp_s(b.stamp_s);
      m.position(to_msg(b.reported_p));
      m.velocity(me.velocity());
      cmd.has_beacon(true);
      if (new_tick) w_beacon.write(m);
    }
    w_cmd.write(cmd);
    ++sent;
  }

  void run(double duration_s) {
    double end = duration_s > 0 ? wall_seconds() + duration_s : 1e300;
    spdlog::info("drone {}: agent {:016x} flying (pid {})", id, instance, getpid());
    while (!stop_requested() && wall_seconds() < end) {
      publish_status();
      {
        std::lock_guard<std::mutex> lock(mu);
        double silent = wall_seconds() - last_sample_wall;
        if (have_tick && !server_lost && silent > cfg.agent.server_timeout_s) {
          server_lost = true;
          spdlog::warn("drone {}: no server samples for {:.1f} s; holding commands until it returns",
                       id, silent);
        }
        if (rival) {
          spdlog::warn("drone {}: another agent ({}) claims this drone; the server keeps the first",
                       id, rival_where);
          rival = 0;
        }
      }
      wait_for_stop(std::chrono::milliseconds(250));
    }
  }
};

AgentApp::AgentApp(AgentAppConfig cfg) : impl_(std::make_unique<Impl>(std::move(cfg))) {}
AgentApp::~AgentApp() = default;
void AgentApp::run(double duration_s) { impl_->run(duration_s); }

}  // namespace ddswarm::agent
