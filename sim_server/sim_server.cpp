#include "sim_server/sim_server.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <random>
#include <set>
#include <thread>

#include "common/convert.hpp"
#include "common/mission.hpp"
#include "common/participant.hpp"
#include "common/process.hpp"
#include "sim_server/agent_liveness.hpp"
#include "sim_server/command_gate.hpp"
#include "sim_server/mission_ring.hpp"
#include "sim_server/task_referee.hpp"

namespace ddswarm::sim {

void ServerConfig::validate() const {
  scenario.validate();
  sim.validate();
  quadrotor.validate();
  controller.validate();
  sensors.validate();
  scene.validate();
  // Nothing lies beyond the world's bounds: a longer ray is a typo (cm for m?).
  const double world_m = (scene.bounds_max - scene.bounds_min).norm();
  if (sensors.max_range_m > world_m)
    throw FieldError("sensors.max_range_m", to_text(sensors.max_range_m),
                     "must be <= the world's size (diagonal of scene.bounds_min..bounds_max, " +
                         to_text(world_m) + " m)");
  dds.validate();
  (void)scene.start_positions(scenario.drones, scenario.seed);
}

ServerConfig load_server_config(const std::string& path) {
  auto doc = load_scenario(path);
  ServerConfig c;
  doc.guard([&] {
    load(doc.section("scenario"), c.scenario);
    load(doc.section("sim"), c.sim);
    load(doc.section("quadrotor"), c.quadrotor);
    load(doc.section("controller"), c.controller);
    load(doc.section("sensors"), c.sensors);
    load(doc.section("scene"), c.scene);
    load(doc.section("dds"), c.dds);
    c.validate();
  });
  return c;
}

namespace {

using Clock = std::chrono::steady_clock;

bool flying_phase(Phase p) {
  return p == Phase::kHold || p == Phase::kMove || p == Phase::kTask || p == Phase::kSwarm ||
         p == Phase::kFollow;
}

/// What the server knows about one drone's agent and its last command.
struct Slot {
  VelocitySetpoint setpoint;   // last accepted command
  bool has_command = false;
  std::uint64_t command_tick = 0;
  bool answered = false;       // lockstep: answered the current tick
  bool answered_prev = false;  // real-time pipeline: answered the tick before it
  bool busy = false;
  Phase phase = Phase::kIdle;
  std::uint64_t owner = 0;     // agent instance flying this drone, 0 = none
  bool live = false;
  double last_heard_wall = -1e9;
  std::uint32_t mission_seq = 0;     // last mission command its agent accepted (relayed in SimStatus)
  std::uint64_t mission_issuer = 0;  // and its issuer
};

/// The part of a Slot that decides a drone's setpoint for one period.
struct CommandView {
  VelocitySetpoint setpoint;
  bool has_command = false;
  std::uint64_t command_tick = 0;
  bool live = false;
};

CommandView view_of(const Slot& s) { return {s.setpoint, s.has_command, s.command_tick, s.live}; }

}  // namespace

struct SimServer::Impl {
  ServerConfig cfg;
  const int n;
  const double period_s;
  const double dt_s;
  // Lockstep pipeline: physics for tick k -> k+1 runs while the agents answer
  // tick k, with the commands that answered k-1 (latched when k went out).
  const bool pipelined;
  const bool rt_pipelined;  // sim.realtime_pipeline in real time
  std::vector<Eigen::Vector3d> starts;
  PhysicsWorld world;
  std::vector<FlightController> controllers;
  std::vector<std::mt19937_64> sensor_rng;
  TaskReferee referee;

  Participant dds;
  Writer<msg::SwarmState> w_swarm;
  Writer<msg::DroneState> w_drone;
  Writer<msg::DistanceScan> w_scan;
  Writer<msg::Scene> w_scene;
  Writer<msg::SimStatus> w_status;
  Writer<msg::CollisionEvent> w_collision;
  Writer<msg::TaskStatus> w_task;

  // Shared with DDS callbacks: guarded by mu.
  std::mutex mu;
  std::condition_variable cv;
  std::vector<Slot> slots;
  std::deque<msg::MissionCommand> pending_missions;
  std::vector<msg::Beacon> pending_beacons;  // carried by accepted commands, forwarded next tick
  std::set<std::pair<std::uint64_t, std::uint32_t>> seen_missions;
  bool rejoin = false;  // run() ended on a rejoin request (rejoin_now)
  // Another server's scene on this domain (on_rival_scene): its instance, when
  // this one is the newcomer and leaves (set under mu, read without it by the
  // per-turn check); whether the log said so, when it stays.
  std::atomic<std::uint64_t> rival_instance{0};
  bool rival_logged = false;
  std::int64_t scene_published_ns = 0;  // system clock, as the scene's source timestamp
  SwarmSilence swarm_silence;  // expire_agents: whether, and since when, no agent was heard
  bool holding_lost = false;   // expire_agents: several agents past the limit at once, held
  std::set<std::pair<std::uint64_t, std::uint32_t>> released_missions;  // main thread
  std::uint64_t published_tick = 0;
  // What a ground station waits for changed since the last SimStatus: an
  // agent came online or was lost, accepted a new mission command, or changed
  // phase. Set under mu; atomic so the per-tick check in publish_status needs
  // no lock.
  std::atomic<bool> status_due{false};
  int unanswered = 0;  // live slots that have not answered published_tick (kept by the four places that change them)
  // Real-time pipeline: of the slots live at the publish, those that have not
  // answered the tick before it (kept by the same four places).
  int unanswered_prev = 0;
  double agent_d_int = 0;
  // Random per process: Scene and SimStatus carry it, so agents and ground
  // stations tell a restarted server (a new world) from the one they knew.
  const std::uint64_t instance = random_instance();
  msg::SimStatus counters;  // rejected_* and commands_* live here

  // Main thread only.
  std::uint64_t tick = 0;
  std::vector<VelocitySetpoint> applied;
  std::vector<double> failsafe_since;  // sim time entered failsafe, <0 = not in failsafe
  std::vector<std::uint32_t> coll_obstacle, coll_drone, coll_ground;
  std::vector<float> cmd_age_s;
  std::vector<CommandView> latched;  // pipelined: the answers to the tick before the published one
  std::deque<msg::MissionCommand> recent;
  double d_int = 0;
  msg::SwarmState swarm_msg;
  bool paused = false;
  std::string state_text = "starting";
  double last_status_wall = -1e9, rtf_wall = 0, rtf_sim = 0, rtf = 0;
  double start_wall = 0;
  TaskPhase last_task_phase = TaskPhase::kNone;
  double task_start_wall = 0;
  // Per-tick scratch, allocated once (publish_tick is on every tick's path).
  std::vector<float> ranges;
  std::vector<std::uint8_t> hits;
  std::vector<Eigen::Vector3d> positions;   // the drones that count for the task
  std::vector<Eigen::Vector3d> velocities;  // theirs, in the same order
  std::vector<int> counted_ids;             // and their ids
  std::vector<char> tick_live;
  std::vector<Phase> tick_phase;
  double last_task_publish_wall = -1e9;

  // DDS callbacks touch the members below: stop them before anything is destroyed.
  ~Impl() { dds.close(); }

  explicit Impl(ServerConfig c)
      : cfg(std::move(c)),
        n(cfg.scenario.drones),
        period_s(1.0 / cfg.sim.control_rate_hz),
        dt_s(1.0 / cfg.sim.physics_rate_hz),
        pipelined(cfg.sim.lockstep_pipeline && cfg.scenario.mode == TimeMode::kLockstep),
        rt_pipelined(cfg.sim.realtime_pipeline && cfg.scenario.mode == TimeMode::kRealtime),
        starts(cfg.scene.start_positions(n, cfg.scenario.seed)),
        world(cfg.scene, cfg.quadrotor, starts, cfg.scene.start.yaw_rad),
        referee(cfg.scene, cfg.sim.metrics()),
        dds(cfg.dds, kServerParticipantName),
        w_swarm(dds.writer<msg::SwarmState>()),
        w_drone(dds.writer<msg::DroneState>()),
        w_scan(dds.writer<msg::DistanceScan>()),
        w_scene(dds.writer<msg::Scene>()),
        w_status(dds.writer<msg::SimStatus>()),
        w_collision(dds.writer<msg::CollisionEvent>()),
        w_task(dds.writer<msg::TaskStatus>()) {
    for (int i = 0; i < n; ++i) {
      controllers.emplace_back(cfg.quadrotor, cfg.controller);
      controllers.back().reset(cfg.scene.start.yaw_rad);
      // One generator per drone: a drone's noise does not depend on the others.
      sensor_rng.emplace_back(cfg.scenario.seed * 1000003ULL + static_cast<std::uint64_t>(i));
    }
    slots.resize(n);
    applied.resize(n);
    failsafe_since.assign(n, -1.0);
    coll_obstacle.assign(n, 0);
    coll_drone.assign(n, 0);
    coll_ground.assign(n, 0);
    cmd_age_s.assign(n, 0.f);
    latched.resize(n);
    tick_live.assign(n, 0);
    tick_phase.assign(n, Phase::kIdle);
    positions.reserve(n);
    velocities.reserve(n);
    counted_ids.reserve(n);
    swarm_msg.drones().resize(n);
    swarm_msg.scans().resize(n);
    for (int i = 0; i < n; ++i) {
      auto& sc = swarm_msg.scans()[i];
      sc.drone_id(static_cast<std::uint16_t>(i));
      sc.max_range_m(static_cast<float>(cfg.sensors.max_range_m));
      for (int k = 0; k < cfg.sensors.count; ++k)
        sc.angle_body_rad().push_back(
            static_cast<float>(cfg.sensors.yaw_offset_rad + 2.0 * M_PI * k / cfg.sensors.count));
    }
    counters.num_drones(static_cast<std::uint16_t>(n));
    counters.server_instance(instance);
    counters.mode(cfg.scenario.mode == TimeMode::kLockstep ? msg::MODE_LOCKSTEP : msg::MODE_REALTIME);

    // dds.best_effort_streams: the server need not acknowledge each command.
    // In real time a lost one is superseded one period later; in lockstep the
    // tick is published again after sim.lockstep_resend_s, and the agent
    // answers it again (run_lockstep).
    const Delivery commands = cfg.dds.best_effort_streams ? Delivery::kLatest : Delivery::kProfile;
    if (!dds.secure()) {
      dds.reader<msg::VelocityCommand>(
          [this](const msg::VelocityCommand& c, const fdds::SampleInfo&) { on_command(c); }, std::nullopt,
          commands);
    } else {
      // DDS Security: only agent-K may publish in partition drone/K, so one
      // reader per drone knows whose commands it hears; a command there for
      // another drone is an impostor's (docs/security.md).
      for (int k = 0; k < n; ++k)
        dds.reader<msg::VelocityCommand>(
            [this, k](const msg::VelocityCommand& c, const fdds::SampleInfo&) {
              if (c.drone_id() == k) return on_command(c);
              std::lock_guard<std::mutex> lock(mu);
              counters.rejected_impostor(counters.rejected_impostor() + 1);
            },
            drone_partition(k), commands);
    }
    dds.reader<msg::AgentStatus>(
        [this](const msg::AgentStatus& s, const fdds::SampleInfo&) { on_heartbeat(s); });
    dds.reader<msg::MissionCommand>(
        [this](const msg::MissionCommand& m, const fdds::SampleInfo&) { on_mission(m); });
    dds.reader<msg::Scene>([this](const msg::Scene& s, const fdds::SampleInfo& info) {
      if (s.server_instance() != instance)
        on_rival_scene(s.server_instance(), info.source_timestamp.to_ns());
    });
    dds.reader<msg::SimStatus>([this](const msg::SimStatus& s, const fdds::SampleInfo&) {
      if (s.server_instance() != instance) on_rival_status(s);
    });
    publish_scene();
  }

  /// Two servers on one domain would fly one swarm in two worlds: the agents
  /// follow whichever scene they heard first. One leaves (run() ends
  /// kRivalServer), the other says so once and stays:
  /// - a server that has accepted a mission command never leaves;
  /// - one that has not leaves when the other's status shows a mission
  ///   (on_rival_status), whatever the clocks say;
  /// - between two that have none, each scene's source timestamp (published
  ///   once, as the server joins) decides: the newer leaves, even if the
  ///   other swarm's agents already answer it. Hosts' clocks may differ; by
  ///   the rules above, a swarm in flight never yields to a newcomer.
  bool mission_begun() const { return !seen_missions.empty(); }  // call with mu held

  void on_rival_scene(std::uint64_t other, std::int64_t other_published_ns) {
    std::lock_guard<std::mutex> lock(mu);
    const std::int64_t own = scene_published_ns != 0 ? scene_published_ns : system_now_ns();
    if (!mission_begun() && other_published_ns < own) return yield_to(other);
    if (!std::exchange(rival_logged, true))
      spdlog::error(
          "another server (instance {:016x}) is on DDS domain {}: two swarms on one domain "
          "are one swarm; it should leave (this one stays: {})",
          other, cfg.dds.domain_id,
          mission_begun() ? "its swarm has a mission" : "it joined first");
  }

  void on_rival_status(const msg::SimStatus& s) {
    std::lock_guard<std::mutex> lock(mu);
    const auto& seqs = s.mission_seq();
    if (!mission_begun() && std::any_of(seqs.begin(), seqs.end(), [](auto q) { return q != 0; }))
      yield_to(s.server_instance());
  }

  void yield_to(std::uint64_t other) {  // call with mu held
    rival_instance = other;
    cv.notify_all();
  }

  // ---- DDS callbacks (Fast DDS threads) ----

  void on_command(const msg::VelocityCommand& c) {
    std::lock_guard<std::mutex> lock(mu);
    CommandFacts f{c.drone_id(), c.tick(), from_msg(c.velocity()), c.yaw_rate_rad_s(),
                   c.agent_instance()};
    GateContext g{n, published_tick, 0, 0, cfg.sim.max_command_speed_mps};
    if (c.drone_id() < n) {
      const Slot& s = slots[c.drone_id()];
      g.owner_instance = s.live ? s.owner : 0;
      g.oldest_ok_tick = cfg.scenario.mode == TimeMode::kLockstep
                             ? published_tick
                             : (s.has_command ? s.command_tick : 0);
      // An agent answers a tick published twice (run_lockstep) twice.
      if (cfg.scenario.mode == TimeMode::kLockstep && s.live && s.has_command)
        g.answered_tick = s.command_tick;
    }
    Verdict v = check_command(f, g);
    switch (v) {
      case Verdict::kAccept: break;
      case Verdict::kNonFinite: counters.rejected_non_finite(counters.rejected_non_finite() + 1); return;
      case Verdict::kAbsurd: counters.rejected_absurd(counters.rejected_absurd() + 1); return;
      case Verdict::kUnknownId: counters.rejected_unknown_id(counters.rejected_unknown_id() + 1); return;
      case Verdict::kImpostor: counters.rejected_impostor(counters.rejected_impostor() + 1); return;
      case Verdict::kStaleTick: counters.rejected_stale_tick(counters.rejected_stale_tick() + 1); return;
      case Verdict::kFutureTick: counters.rejected_future_tick(counters.rejected_future_tick() + 1); return;
      case Verdict::kRepeat: return;  // an answer already applied, to a tick published twice
    }
    Slot& s = slots[c.drone_id()];
    adopt(s, c.agent_instance(), c.drone_id());
    s.setpoint.v_world = f.velocity;
    s.setpoint.yaw_rate_rad_s = f.yaw_rate;
    s.setpoint.motors_on = c.motors_on();
    s.has_command = true;
    s.command_tick = c.tick();
    const Phase phase = static_cast<Phase>(std::min<int>(c.phase(), static_cast<int>(Phase::kFailsafe)));
    if (c.mission_seq() != s.mission_seq || c.mission_issuer() != s.mission_issuer || phase != s.phase) {
      s.mission_seq = c.mission_seq();
      s.mission_issuer = c.mission_issuer();
      status_due = true;
    }
    s.phase = phase;
    s.busy = c.busy();
    if (c.has_beacon() && c.own_beacon().drone_id() == c.drone_id() &&
        std::isfinite(c.own_beacon().position().x()) && std::isfinite(c.own_beacon().position().y()) &&
        std::isfinite(c.own_beacon().position().z())) {
      // One beacon per drone per tick: a repeated answer replaces, never duplicates.
      std::erase_if(pending_beacons, [&](const msg::Beacon& b) { return b.drone_id() == c.drone_id(); });
      pending_beacons.push_back(c.own_beacon());
    }
    // Real time: an answer to a state older than the newest arrived after the
    // step it was meant for (it is still the freshest, so it is applied).
    // Pipelined, that step comes after the next state goes out.
    if (c.tick() + (rt_pipelined ? 1 : 0) < published_tick)
      counters.commands_late(counters.commands_late() + 1);
    // Pipelined real time: a late answer still flies the coming step, but an
    // answer to the state just published waits for the step after it.
    if (rt_pipelined && c.tick() < published_tick) latched[c.drone_id()] = view_of(s);
    if (rt_pipelined && c.tick() + 1 == published_tick && !s.answered_prev) {
      s.answered_prev = true;
      if (--unanswered_prev == 0) cv.notify_all();
    }
    // One wake-up per tick: the main thread needs to run only when the last
    // live agent has answered (it also wakes on its own every 20 ms).
    if (c.tick() == published_tick && !s.answered) {
      s.answered = true;
      if (--unanswered == 0) cv.notify_all();
    }
  }

  void on_heartbeat(const msg::AgentStatus& a) {
    std::lock_guard<std::mutex> lock(mu);
    if (a.drone_id() >= n) {
      counters.rejected_unknown_id(counters.rejected_unknown_id() + 1);
      return;
    }
    Slot& s = slots[a.drone_id()];
    if (s.live && s.owner != a.agent_instance()) {
      counters.rejected_impostor(counters.rejected_impostor() + 1);
      return;
    }
    const bool new_agent = adopt(s, a.agent_instance(), a.drone_id());
    if (std::isfinite(a.inter_distance_m()) && a.inter_distance_m() > 0)
      agent_d_int = std::max(agent_d_int, a.inter_distance_m());
    // Only a new agent changes what the main loop waits for (and its status
    // goes out at once). Waking it for every heartbeat, 4 a second from each
    // agent, woke it 0.7 extra times per tick at 64 drones in lockstep.
    if (new_agent) cv.notify_all();
  }

  /// Marks the slot heard; true when this made its agent live.
  bool adopt(Slot& s, std::uint64_t instance, int id) {
    const bool was_live = s.live;
    if (!s.live) {
      spdlog::info("drone {}: agent {:016x} online", id, instance);
      s.live = true;
      s.owner = instance;
      s.answered = false;
      ++unanswered;
      s.answered_prev = true;  // owes no answer to a tick published before it was heard
      status_due = true;
    }
    s.last_heard_wall = wall_seconds();
    return !was_live;
  }

  void on_mission(const msg::MissionCommand& m) {
    std::lock_guard<std::mutex> lock(mu);
    std::string problem = mission_problem(m);
    if (!problem.empty()) {
      counters.rejected_mission(counters.rejected_mission() + 1);
      spdlog::warn("mission command seq {} rejected: {}", m.seq(), problem);
      return;
    }
    // Addressed to a server that is gone (e.g. a ground station's
    // transient-local history meeting a restarted server): the mission it
    // belonged to ended with that world.
    if (m.server_instance() != 0 && m.server_instance() != instance) {
      counters.rejected_stale_mission(counters.rejected_stale_mission() + 1);
      spdlog::warn("mission command seq {} from {} was for server {:016x}, not this one: ignored",
                   m.seq(), m.issuer().to_string(), m.server_instance());
      return;
    }
    // A repeat (the ground station lost an ack, or re-sent its history to a
    // restarted server) is forwarded again: agents re-acknowledge it and do not re-apply it.
    if (!seen_missions.insert({m.issuer_instance(), m.seq()}).second)
      spdlog::info("mission seq {} repeated: forwarding again for acknowledgement", m.seq());
    pending_missions.push_back(m);
    cv.notify_all();
  }

  // ---- main loop ----

  /// Marks agents silent for longer than agent_silence_limit as lost (in
  /// mp_fault_agent_kill a server stall once made the five agents still
  /// flying all lost at once). Call with mu held.
  void expire_agents() {
    const double now = wall_seconds();
    double newest = -1e9;
    for (const auto& s : slots)
      if (s.live) newest = std::max(newest, s.last_heard_wall);
    if (newest <= -1e9) return;  // no live agent
    const bool was_silent = swarm_silence.silent();
    const double timeout = swarm_silence.limit(now, newest, cfg.sim.agent_timeout_s);
    if (swarm_silence.silent() && !was_silent)
      spdlog::warn("no agent heard for {:.1f} s: waiting up to {:.1f} s before declaring any lost "
                   "(the silence may be this server's)",
                   now - newest, timeout);
    // A live agent's silence as this check counts it (SwarmSilence).
    auto silence = [&](const Slot& s) { return now - swarm_silence.silent_since(s.last_heard_wall); };
    int past = 0;
    double longest = 0;
    for (const auto& s : slots)
      if (s.live && silence(s) > timeout) {
        ++past;
        longest = std::max(longest, silence(s));
      }
    if (!declare_lost_now(past, longest, timeout)) {
      if (!holding_lost)
        spdlog::warn(
            "{} agents silent past {:.1f} s at once: waiting up to {:.1f} s more before declaring "
            "any lost (their writes may be stalled on this server's port)",
            past, timeout, kPortLockTimeoutS);
      holding_lost = true;
      return;
    }
    holding_lost = false;
    for (int i = 0; i < n; ++i) {
      Slot& s = slots[i];
      if (s.live && silence(s) > timeout) {
        s.live = false;
        s.owner = 0;
        if (!s.answered) --unanswered;
        if (!s.answered_prev) --unanswered_prev;
        s.answered_prev = true;
        status_due = true;
        counters.lockstep_timeouts(counters.lockstep_timeouts() + 1);
        spdlog::warn("drone {}: agent lost (silent for {:.1f} s); drone enters failsafe", i,
                     now - s.last_heard_wall);
      }
    }
  }

  /// Puts a command into the ring carried by every SwarmState, stamped with this tick.
  void forward(msg::MissionCommand m) {
    m.apply_tick(tick);
    // One entry per command in the ring, or agents would see it alternate between apply ticks.
    std::erase_if(recent, [&](const msg::MissionCommand& r) {
      return r.issuer_instance() == m.issuer_instance() && r.seq() == m.seq();
    });
    recent.push_back(m);
    trim_recent(recent, 8);
  }

  /// Releases at most one new pending mission command onto this tick; repeats
  /// go into the ring too but take no slot, so a re-sent command never delays
  /// the next one (lockstep determinism). Call with mu held.
  void release_mission() {
    while (!pending_missions.empty() &&
           released_missions.count({pending_missions.front().issuer_instance(), pending_missions.front().seq()})) {
      forward(pending_missions.front());
      pending_missions.pop_front();
    }
    if (pending_missions.empty()) return;
    msg::MissionCommand m = pending_missions.front();
    pending_missions.pop_front();
    forward(m);
    auto type = static_cast<MissionType>(m.type());
    spdlog::info("tick {}: mission seq {} {} released", tick, m.seq(), to_string(type));
    released_missions.insert({m.issuer_instance(), m.seq()});
    if (type == MissionType::kSetDistance) d_int = m.value();
    if (referee.running() && (type == MissionType::kLand || type == MissionType::kTask ||
                              type == MissionType::kMove || type == MissionType::kFollowLeader))
      referee.fail(std::string("aborted by ") + to_string(type) + " command");
    if (type == MissionType::kTask) {
      double dint = d_int > 0 ? d_int : (agent_d_int > 0 ? agent_d_int : 4.0);
      double eps = m.epsilon_m() > 0 ? m.epsilon_m() : default_epsilon(dint);
      referee.start(m.seq(), sim_time(), eps, m.value(), n);
    }
  }

  double sim_time() const { return static_cast<double>(tick) * period_s; }

  /// Chooses each drone's setpoint for the coming period: from the latest
  /// answers, or (pipelined) from those latched when the tick went out (in
  /// real time, with the late answers to the ticks before). Call with mu held.
  void select_setpoints() {
    const double t = sim_time();
    for (int i = 0; i < n; ++i) {
      const CommandView s = pipelined || rt_pipelined ? latched[i] : view_of(slots[i]);
      bool fresh = s.has_command && s.live &&
                   (static_cast<double>(tick - std::min(tick, s.command_tick)) * period_s <=
                    cfg.sim.command_timeout_s);
      if (fresh) {
        if (failsafe_since[i] >= 0) spdlog::info("drone {}: commands resumed, leaving failsafe", i);
        failsafe_since[i] = -1;
        applied[i] = s.setpoint;
        cmd_age_s[i] = static_cast<float>((tick - std::min(tick, s.command_tick)) * period_s);
        counters.commands_applied(counters.commands_applied() + 1);
        continue;
      }
      // Failsafe: hover in place, land after a while (PX4's offboard-loss behaviour).
      bool airborne = world.state(i).p_world.z() > cfg.scene.ground_z_m + cfg.sim.airborne_height_m;
      if (failsafe_since[i] < 0) {
        if (!airborne && !applied[i].motors_on) continue;  // idle on the ground: not a failsafe
        failsafe_since[i] = t;
        spdlog::warn("drone {}: no fresh command, failsafe (hover, land after {:.0f} s)", i,
                     cfg.sim.failsafe_land_after_s);
      }
      VelocitySetpoint sp;
      sp.motors_on = airborne || (t - failsafe_since[i] < cfg.sim.failsafe_land_after_s);
      if (t - failsafe_since[i] >= cfg.sim.failsafe_land_after_s) sp.v_world = {0, 0, -0.5};
      if (!airborne && t - failsafe_since[i] >= cfg.sim.failsafe_land_after_s) sp.motors_on = false;
      applied[i] = sp;
    }
  }

  void step_physics() {
    const int substeps = cfg.sim.substeps();
    for (int k = 0; k < substeps; ++k) {
      for (int i = 0; i < n; ++i) {
        auto omega = controllers[i].update(world.state(i), applied[i], dt_s);
        world.set_rotor_commands(i, omega);
      }
      world.step(dt_s);
    }
    for (const auto& e : world.take_contact_events()) on_contact(e);
  }

  void on_contact(const ContactEvent& e) {
    int kind = e.kind == ContactKind::kObstacle ? 0 : e.kind == ContactKind::kDrone ? 1 : 2;
    if (kind == 2) {
      Phase p;
      {
        std::lock_guard<std::mutex> lock(mu);
        p = slots[e.drone].phase;
      }
      // Touching the ground is a collision only while the drone means to fly.
      if (!flying_phase(p) || failsafe_since[e.drone] >= 0) return;
      ++coll_ground[e.drone];
    } else if (kind == 0) {
      ++coll_obstacle[e.drone];
    } else {
      ++coll_drone[e.drone];
      if (e.other >= 0 && e.other < n) ++coll_drone[e.other];
    }
    referee.count_collision(kind);
    msg::CollisionEvent m;
    m.tick(tick);
    m.sim_time_s(sim_time());
    m.drone_id(static_cast<std::uint16_t>(e.drone));
    m.kind(static_cast<std::uint8_t>(kind));
    m.other(e.other);
    m.where(to_msg(e.where_world));
    w_collision.write(m);
    spdlog::info("t={:.2f}s collision: drone {} with {} {}", sim_time(), e.drone,
                 kind == 0 ? "obstacle" : kind == 1 ? "drone" : "ground", e.other);
  }

  void publish_scene() {
    msg::Scene s = to_msg(cfg.scene);
    s.name(cfg.scenario.name.substr(0, 127));
    s.seed(cfg.scenario.seed);
    s.server_instance(instance);
    s.num_drones(static_cast<std::uint16_t>(n));
    s.mode(cfg.scenario.mode == TimeMode::kLockstep ? msg::MODE_LOCKSTEP : msg::MODE_REALTIME);
    s.physics_rate_hz(cfg.sim.physics_rate_hz);
    s.control_rate_hz(cfg.sim.control_rate_hz);
    for (const auto& p : starts) s.start_positions().push_back(to_msg(p));
    s.drone_radius_m(cfg.quadrotor.collision_radius_m);
    s.arm_length_m(cfg.quadrotor.arm_length_m);
    s.sensor_count(static_cast<std::uint16_t>(cfg.sensors.count));
    s.sensor_max_range_m(static_cast<float>(cfg.sensors.max_range_m));
    {
      std::lock_guard<std::mutex> lock(mu);
      scene_published_ns = system_now_ns();
    }
    w_scene.write(s);
  }

  void publish_tick() {
    const double t = sim_time();
    const bool scan_tick = tick % static_cast<std::uint64_t>(cfg.sim.sensor_every()) == 0;
    positions.clear();
    velocities.clear();
    counted_ids.clear();
    {
      std::lock_guard<std::mutex> lock(mu);
      // What the callbacks keep per drone, read once for the whole tick.
      for (int i = 0; i < n; ++i) {
        tick_live[i] = slots[i].live;
        tick_phase[i] = slots[i].phase;
      }
      release_mission();
      swarm_msg.recent_commands().assign(recent.begin(), recent.end());
      // The radio medium: beacons sent last tick, in drone order, with the
      // sender's true position for the receivers' range models.
      std::sort(pending_beacons.begin(), pending_beacons.end(),
                [](const msg::Beacon& a, const msg::Beacon& b) { return a.drone_id() < b.drone_id(); });
      swarm_msg.beacons() = std::move(pending_beacons);
      pending_beacons.clear();
      published_tick = tick;
      unanswered = 0;
      unanswered_prev = 0;
      for (int i = 0; i < n; ++i) {
        Slot& s = slots[i];
        if (pipelined || rt_pipelined) latched[i] = view_of(s);
        s.answered_prev = s.answered;
        unanswered_prev += s.live && !s.answered;
        s.answered = false;
        unanswered += s.live;
      }
    }
    swarm_msg.tick(tick);
    swarm_msg.sim_time_s(t);
    for (int i = 0; i < n; ++i) {
      RigidState st = world.state(i);
      auto omega = world.rotor_speeds(i);
      auto& d = swarm_msg.drones()[i];
      d.drone_id(static_cast<std::uint16_t>(i));
      d.tick(tick);
      d.sim_time_s(t);
      d.position(to_msg(st.p_world));
      d.orientation(to_msg(st.q_world_body));
      d.velocity(to_msg(st.v_world));
      d.angular_velocity(to_msg(st.w_body));
      for (int k = 0; k < 4; ++k) d.motor_speed_rad_s()[k] = static_cast<float>(omega[k]);
      d.collisions_obstacle(coll_obstacle[i]);
      d.collisions_drone(coll_drone[i]);
      d.collisions_ground(coll_ground[i]);
      std::uint16_t flags = 0;
      bool airborne = st.p_world.z() > cfg.scene.ground_z_m + cfg.sim.airborne_height_m;
      if (airborne) flags |= msg::DRONE_AIRBORNE;
      const Phase phase = tick_phase[i];
      // In failsafe: the server flies it (its agent is lost), or its agent
      // does (the drone's swarm law faulted).
      if (failsafe_since[i] >= 0 || phase == Phase::kFailsafe) flags |= msg::DRONE_FAILSAFE;
      if (tick_live[i]) flags |= msg::DRONE_AGENT_LIVE;
      if ((st.p_world.array() < cfg.scene.bounds_min.array()).any() ||
          (st.p_world.array() > cfg.scene.bounds_max.array()).any())
        flags |= msg::DRONE_OUT_OF_BOUNDS;
      if (cfg.scene.past_finish(st.p_world.head<2>())) flags |= msg::DRONE_PAST_FINISH;
      if (applied[i].motors_on) flags |= msg::DRONE_MOTORS_ON;
      d.flags(flags);
      d.phase(static_cast<std::uint8_t>(phase));
      d.command_age_s(cmd_age_s[i]);
      if (scan_tick) {
        auto& sc = swarm_msg.scans()[i];
        world.cast_rays(i, cfg.sensors, sensor_rng[i], ranges, hits);
        sc.tick(tick);
        sc.sim_time_s(t);
        sc.range_m().assign(ranges.begin(), ranges.end());
        sc.hit().assign(hits.begin(), hits.end());
      }
      // A drone in failsafe (its agent lost, or its law faulted) no longer counts for the task.
      if (failsafe_since[i] < 0 && phase != Phase::kFailsafe) {
        positions.push_back(st.p_world);
        velocities.push_back(st.v_world);
        counted_ids.push_back(i);
      } else {
        referee.note_lost(i);
      }
    }
    for (auto& b : swarm_msg.beacons()) b.true_position(swarm_msg.drones()[b.drone_id()].position());
    bool task_changed =
        referee.update(t, positions, velocities, counted_ids, cfg.sim.task_timeout_s);
    w_swarm.write(swarm_msg);
    // Best-effort, volatile topics: with no reader matched (no recorder or
    // tool listening) the 2N writes would only serialize into the history.
    if (cfg.sim.publish_per_drone_topics) {
      const bool drones = w_drone.matched() > 0, scans = scan_tick && w_scan.matched() > 0;
      for (int i = 0; i < n && (drones || scans); ++i) {
        if (drones) w_drone.write(swarm_msg.drones()[i]);
        if (scans) w_scan.write(swarm_msg.scans()[i]);
      }
    }
    publish_task(task_changed);
  }

  void publish_task(bool changed) {
    const auto& r = referee.report();
    double now = wall_seconds();
    if (!changed && !(r.phase == TaskPhase::kRunning && now - last_task_publish_wall > 0.5) &&
        r.phase == last_task_phase)
      return;
    if (r.phase == TaskPhase::kRunning && last_task_phase != TaskPhase::kRunning)
      task_start_wall = now;
    last_task_phase = r.phase;
    last_task_publish_wall = now;
    msg::TaskStatus m;
    m.seq(r.seq);
    m.phase(static_cast<std::uint8_t>(r.phase));
    m.reason(r.reason.substr(0, 127));
    m.start_sim_time_s(r.start_sim_time_s);
    m.elapsed_s(r.elapsed_s);
    m.start_wall_time_s(task_start_wall - start_wall);
    m.wall_elapsed_s(now - task_start_wall);
    m.epsilon_m(r.epsilon_m);
    m.speed_mps(r.speed_mps);
    m.drones(static_cast<std::uint16_t>(r.drones));
    m.past_finish(static_cast<std::uint16_t>(r.past_finish));
    m.max_pair_distance_m(r.max_pair_distance_m);
    m.min_inter_drone_m(std::isfinite(r.min_inter_drone_m) ? r.min_inter_drone_m : -1);
    m.min_clearance_m(std::isfinite(r.min_clearance_m) ? r.min_clearance_m : -1);
    m.collisions_obstacle(r.collisions_obstacle);
    m.collisions_drone(r.collisions_drone);
    m.collisions_ground(r.collisions_ground);
    for (int id : r.lost_drones) m.lost_drones().push_back(static_cast<std::uint16_t>(id));
    m.order(r.order);
    m.order_mean(r.metrics.order_mean);
    m.order_min(r.metrics.order_min);
    m.speed_mean_mps(r.metrics.speed_mean_mps);
    m.near_misses(r.metrics.near_misses);
    m.components(static_cast<std::uint16_t>(r.components));
    m.components_max(static_cast<std::uint16_t>(r.metrics.components_max));
    m.lambda2(r.lambda2);
    m.lambda2_min(r.metrics.lambda2_min);
    m.metrics_range_m(r.metrics.range_m);
    m.near_miss_m(r.metrics.near_miss_m);
    w_task.write(m);
    if (changed && r.phase == TaskPhase::kComplete)
      spdlog::info("task complete: {:.2f} s sim, {} obstacle / {} drone / {} ground collisions, "
                   "min distance {:.2f} m, min clearance {:.2f} m",
                   r.elapsed_s, r.collisions_obstacle, r.collisions_drone, r.collisions_ground,
                   r.min_inter_drone_m, r.min_clearance_m);
    if (changed && r.phase == TaskPhase::kFailed) spdlog::warn("task failed: {}", r.reason);
  }
  // A tick published again says which agents are live now. Otherwise agents
  // that join while the swarm is paused at tick 0 read that tick, built before
  // they were heard, for as long as the pause lasts: each takes its drone's
  // missing DRONE_AGENT_LIVE for a server that does not hear it, and joins
  // again (agent/agent_app.cpp).
  void refresh_live_flags() {
    std::lock_guard<std::mutex> lock(mu);
    for (std::size_t i = 0; i < std::min<std::size_t>(n, swarm_msg.drones().size()); ++i) {
      auto& d = swarm_msg.drones()[i];
      const std::uint16_t others = d.flags() & ~static_cast<std::uint16_t>(msg::DRONE_AGENT_LIVE);
      d.flags(static_cast<std::uint16_t>(others | (slots[i].live ? msg::DRONE_AGENT_LIVE : 0)));
    }
  }

  void publish_status(bool force) {
    double now = wall_seconds();
    // Who is live goes out at once: a ground station that has just heard
    // every agent's heartbeat must not get a latched status listing none.
    // So does a newly accepted mission command or a new phase: they confirm
    // the command, and its progress, to a ground station that never got that
    // agent's ack or heartbeats.
    if (!force && now - last_status_wall < 1.0 / cfg.sim.status_rate_hz &&
        !status_due.load(std::memory_order_relaxed))
      return;
    double dw = now - rtf_wall;
    if (dw >= 0.5) {
      rtf = (sim_time() - rtf_sim) / dw;
      rtf_wall = now;
      rtf_sim = sim_time();
    }
    last_status_wall = now;
    msg::SimStatus s;
    {
      std::lock_guard<std::mutex> lock(mu);
      s = counters;
      status_due = false;
      s.mission_seq().resize(static_cast<std::size_t>(n));
      s.mission_issuer().resize(static_cast<std::size_t>(n));
      s.phase().resize(static_cast<std::size_t>(n));
      for (int i = 0; i < n; ++i) {
        const auto k = static_cast<std::size_t>(i);
        if (slots[i].live) s.live_agents().push_back(static_cast<std::uint16_t>(i));
        s.mission_seq()[k] = slots[i].mission_seq;
        s.mission_issuer()[k] = slots[i].mission_issuer;
        s.phase()[k] = static_cast<std::uint8_t>(slots[i].phase);
      }
      s.agents_live(static_cast<std::uint16_t>(s.live_agents().size()));
    }
    s.rejected_malformed(static_cast<std::uint32_t>(malformed_samples().load()));
    s.tick(tick);
    s.sim_time_s(sim_time());
    s.wall_time_s(now - start_wall);
    s.state(state_text);
    s.real_time_factor(paused ? 0.0 : rtf);
    int airborne = 0, failsafe = 0;
    std::uint32_t co = 0, cd = 0, cg = 0;
    for (int i = 0; i < n; ++i) {
      airborne += swarm_msg.drones()[i].flags() & msg::DRONE_AIRBORNE ? 1 : 0;
      failsafe += (swarm_msg.drones()[i].flags() & msg::DRONE_FAILSAFE) ? 1 : 0;
      co += coll_obstacle[i];
      cd += coll_drone[i];
      cg += coll_ground[i];
    }
    s.airborne(static_cast<std::uint16_t>(airborne));
    s.failsafe(static_cast<std::uint16_t>(failsafe));
    s.collisions_obstacle(co);
    s.collisions_drone(cd / 2);  // each drone-drone contact counted on both drones
    s.collisions_ground(cg);
    w_status.write(s);
  }

  /// Steps the world one period with the setpoints select_setpoints picks.
  void step() {
    {
      std::lock_guard<std::mutex> lock(mu);
      select_setpoints();
    }
    step_physics();
  }

  /// Publishes the next tick (the world already stepped to it).
  void publish_next() {
    ++tick;
    publish_tick();
    publish_status(false);
  }

  void advance() {
    step();
    publish_next();
  }

  static std::int64_t system_now_ns() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::system_clock::now().time_since_epoch())
        .count();
  }

  /// SIGUSR1 (from a user, or from ddswarm-launch when its discovery server
  /// dropped this participant's endpoints, so no agent will ever match them):
  /// leave DDS and start again as a new server, but only before any mission command came.
  bool rejoin_now() {
    if (rival_instance.load() != 0) return true;
    if (!take_rejoin_request()) return false;
    std::lock_guard<std::mutex> lock(mu);
    if (!seen_missions.empty()) {
      spdlog::warn("asked to join DDS again (SIGUSR1), but a mission has begun: staying");
      return false;
    }
    spdlog::warn("asked to join DDS again (SIGUSR1, as ddswarm-launch sends when its discovery "
                 "server dropped this participant); starting again as a new server");
    rejoin = true;
    return true;
  }

  /// Real time: each period, wait up to the grace for live agents' late
  /// answers, then step and publish. Pipelined (sim.realtime_pipeline), each
  /// state goes out on its period's edge, computed by the step before; then
  /// the world steps with the answers to the state before it, waiting up to
  /// the grace for late ones. An agent has a whole period plus the grace to
  /// answer, instead of the period less the step; every command acts one
  /// period later.
  void run_realtime(double deadline_wall) {
    state_text = "running";
    publish_tick();
    if (rt_pipelined) step();
    auto next = Clock::now();
    const auto period =
        std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(period_s));
    const auto grace = std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(period_s * cfg.sim.realtime_grace));
    while (!stop_requested() && !rejoin_now() && wall_seconds() < deadline_wall) {
      next += period;
      auto now = Clock::now();
      if (next < now - 10 * period) {
        spdlog::warn("real time slipped by {:.0f} ms; resynchronising",
                     std::chrono::duration<double, std::milli>(now - next).count());
        next = now;
      }
      std::this_thread::sleep_until(next);
      if (rt_pipelined) publish_next();
      {
        std::unique_lock<std::mutex> lock(mu);
        expire_agents();
        // A live agent a little late (descheduled for a moment) still gets
        // its answer into this step; the deadline of the next period stays.
        int& waiting = rt_pipelined ? unanswered_prev : unanswered;
        if (waiting > 0 && grace.count() > 0)
          cv.wait_until(lock, next + grace, [&] { return waiting == 0 || stop_requested(); });
      }
      if (rt_pipelined)
        step();
      else
        advance();
    }
  }

  /// Lockstep: true when every live agent has answered the published tick.
  bool all_answered() const { return unanswered == 0; }
  bool swarm_idle() {
    for (const auto& s : slots)
      if (s.live && s.busy) return false;
    return true;
  }

  void run_lockstep(double deadline_wall) {
    publish_tick();
    double last_republish = wall_seconds();
    bool ahead = false;  // pipelined: the world has stepped past the published tick
    while (!stop_requested() && !rejoin_now() && wall_seconds() < deadline_wall) {
      // Pipelined: step now, while the agents compute their answers to the
      // published tick; those answers fly the step after this one.
      if (pipelined && !ahead) {
        step();
        ahead = true;
      }
      bool go = false;
      {
        std::unique_lock<std::mutex> lock(mu);
        expire_agents();
        bool answered = all_answered();
        bool idle = cfg.sim.pause_when_idle && answered && swarm_idle() &&
                    pending_missions.empty() && !referee.running();
        bool was_paused = paused;
        paused = idle;
        state_text = paused ? "paused: swarm idle" : answered ? "running" : "waiting for agents";
        go = answered && !idle;
        if (!go) cv.wait_for(lock, std::chrono::milliseconds(paused ? 50 : 20));
        if (paused != was_paused) last_status_wall = -1e9;
      }
      if (go) {
        if (pipelined) {
          publish_next();
          ahead = false;
        } else {
          advance();
        }
        last_republish = wall_seconds();
        continue;
      }
      // Waiting: a late joiner, or a sample lost on a best-effort stream (the
      // state, or an answer), must not stall the loop. Every agent answers the
      // tick again; a repeat of an answer already in is dropped (kRepeat).
      // Paused, the same write tells late joiners where the swarm is.
      if (wall_seconds() - last_republish > (paused ? 0.25 : cfg.sim.lockstep_resend_s)) {
        refresh_live_flags();
        w_swarm.write(swarm_msg);
        last_republish = wall_seconds();
        if (!paused) {
          std::lock_guard<std::mutex> lock(mu);
          counters.lockstep_resends(counters.lockstep_resends() + 1);
        }
      }
      publish_status(false);
    }
  }

  SimServer::End run(double duration_s) {
    start_wall = wall_seconds();
    rtf_wall = start_wall;
    double deadline = duration_s > 0 ? start_wall + duration_s : 1e300;
    spdlog::info(
        "ddswarm-sim: scenario '{}', {} drones, {} mode{}, physics {} Hz, control {} Hz, seed {}",
        cfg.scenario.name, n, to_string(cfg.scenario.mode),
        pipelined || rt_pipelined ? " (pipelined: commands act one tick later)" : "",
        cfg.sim.physics_rate_hz, cfg.sim.control_rate_hz, cfg.scenario.seed);
    if (cfg.scenario.mode == TimeMode::kLockstep)
      run_lockstep(deadline);
    else
      run_realtime(deadline);
    state_text = "stopping";
    publish_status(true);
    spdlog::info("ddswarm-sim: stopped at tick {} (sim {:.2f} s)", tick, sim_time());
    if (rival_instance.load() != 0) return SimServer::End::kRivalServer;
    return rejoin ? SimServer::End::kRejoinRequested : SimServer::End::kStopped;
  }
};

SimServer::SimServer(ServerConfig cfg) : impl_(std::make_unique<Impl>(std::move(cfg))) {}
SimServer::~SimServer() = default;
SimServer::End SimServer::run(double duration_s) { return impl_->run(duration_s); }
std::uint64_t SimServer::rival_instance() const { return impl_->rival_instance.load(); }

}  // namespace ddswarm::sim
