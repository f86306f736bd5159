// The server application: wires its parts to DDS and runs the real-time or
// lockstep loop. The inbox (server_inbox.hpp) takes in what DDS threads
// deliver; the main thread steps the swarm (swarm_physics.hpp) with the
// setpoints the failsafe policy picks, referees the task, and publishes
// through the outbox (server_outbox.hpp) what the message builders
// (messages.hpp) make.
#include "sim_server/sim_server.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <mutex>
#include <thread>

#include "common/mission.hpp"
#include "common/participant.hpp"
#include "common/process.hpp"
#include "sim_server/failsafe_policy.hpp"
#include "sim_server/messages.hpp"
#include "sim_server/server_inbox.hpp"
#include "sim_server/server_outbox.hpp"
#include "sim_server/swarm_physics.hpp"
#include "sim_server/task_referee.hpp"

namespace ddswarm::sim {
namespace {

using Clock = std::chrono::steady_clock;

bool flying_phase(Phase p) {
  return p == Phase::kHold || p == Phase::kMove || p == Phase::kTask || p == Phase::kSwarm ||
         p == Phase::kFollow;
}

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
  SwarmPhysics swarm;
  TaskReferee referee;

  Participant dds;
  ServerOutbox out;

  // Random per process: Scene and SimStatus carry it, so agents and ground
  // stations tell a restarted server (a new world) from the one they knew.
  const std::uint64_t instance = random_instance();
  ServerInbox in;       // shared with DDS callbacks: guarded by in.mu
  bool rejoin = false;  // run() ended on a rejoin request (rejoin_now)

  // Main thread only.
  std::uint64_t tick = 0;
  std::vector<VelocitySetpoint> applied;
  FailsafePolicy failsafe;
  CollisionCounts collisions;
  std::vector<float> cmd_age_s;
  msg::SwarmState swarm_msg;
  bool paused = false;
  std::string state_text = "starting";
  // Per-tick scratch, allocated once (publish_tick is on every tick's path).
  std::vector<float> ranges;
  std::vector<std::uint8_t> hits;
  CountedDrones counted;  // the drones that count for the task
  std::vector<char> tick_live;
  std::vector<Phase> tick_phase;

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
        swarm(cfg.scene, cfg.fleet(), starts, cfg.scenario.seed, cfg.wind, cfg.aero),
        referee(cfg.scene, cfg.sim.metrics()),
        dds(cfg.dds, kServerParticipantName),
        out(dds, cfg.sim),
        in(cfg, instance,
           pipelined      ? Pipeline::kLockstep
           : rt_pipelined ? Pipeline::kRealtime
                          : Pipeline::kNone),
        applied(n),
        failsafe(n, {period_s, cfg.sim.command_timeout_s, cfg.sim.failsafe_land_after_s}),
        collisions(n),
        cmd_age_s(n, 0.f),
        swarm_msg(swarm_state_frame(n, cfg.sensors)),
        tick_live(n, 0),
        tick_phase(n, Phase::kIdle) {
    counted.reserve(n);
    in.subscribe(dds);
    publish_scene();
  }

  /// Releases at most one new mission command onto this tick (MissionRelay)
  /// and starts, or aborts, the task it concerns. Call with in.mu held.
  void release_mission() {
    const auto m = in.missions.release(tick);
    if (!m) return;
    const auto type = static_cast<MissionType>(m->type());
    spdlog::info("tick {}: mission seq {} {} released", tick, m->seq(), to_string(type));
    // The inter-drone distance in force: commanded, else the agents' own, else 4 m.
    const double commanded = in.missions.distance_m();
    const double dint = commanded > 0 ? commanded : (in.agent_d_int > 0 ? in.agent_d_int : 4.0);
    referee.on_mission(type, m->seq(), m->value(), m->epsilon_m(), dint, sim_time(), n);
  }

  double sim_time() const { return static_cast<double>(tick) * period_s; }

  /// Chooses each drone's setpoint for the coming period: from the latest
  /// answers, or (pipelined) from those latched when the tick went out (in
  /// real time, with the late answers to the ticks before). Call with in.mu held.
  void select_setpoints() {
    for (int i = 0; i < n; ++i) {
      const CommandView c =
          pipelined || rt_pipelined ? in.agents.barrier().latched(i) : in.agents.view(i);
      const bool airborne =
          swarm.state(i).p_world.z() > cfg.scene.ground_z_m + cfg.sim.airborne_height_m;
      const SetpointChoice ch = failsafe.choose(i, c, tick, airborne, applied[i]);
      if (ch.change == SetpointChoice::Change::kResumed)
        spdlog::info("drone {}: commands resumed, leaving failsafe", i);
      if (ch.change == SetpointChoice::Change::kEntered)
        spdlog::warn("drone {}: no fresh command, failsafe (hover, land after {:.0f} s)", i,
                     cfg.sim.failsafe_land_after_s);
      applied[i] = ch.setpoint;
      if (!ch.fresh) continue;
      cmd_age_s[i] = ch.command_age_s;
      in.counters.commands_applied(in.counters.commands_applied() + 1);
    }
  }

  void on_contact(const ContactEvent& e) {
    if (e.kind == ContactKind::kGround) {
      Phase p;
      {
        std::lock_guard<std::mutex> lock(in.mu);
        p = in.agents[e.drone].phase;
      }
      // Touching the ground is a collision only while the drone means to fly.
      if (!flying_phase(p) || failsafe.active(e.drone)) return;
    }
    collisions.add(e);
    const int kind = collision_kind(e.kind);
    referee.count_collision(kind);
    out.collision(collision_message(tick, sim_time(), e));
    spdlog::info("t={:.2f}s collision: drone {} with {} {}", sim_time(), e.drone,
                 kind == 0   ? "obstacle"
                 : kind == 1 ? "drone"
                             : "ground",
                 e.other);
  }

  void publish_scene() {
    const msg::Scene s = scene_message(cfg.scenario, cfg.sim, cfg.scene, cfg.quadrotor, cfg.sensors,
                                       starts, instance, cfg.wind);
    {
      std::lock_guard<std::mutex> lock(in.mu);
      in.arbiter.published(std::chrono::duration_cast<std::chrono::nanoseconds>(
                               std::chrono::system_clock::now().time_since_epoch())
                               .count());
    }
    out.scene(s);
  }

  void publish_tick() {
    const double t = sim_time();
    const bool scan_tick = tick % static_cast<std::uint64_t>(cfg.sim.sensor_every()) == 0;
    counted.clear();
    {
      std::lock_guard<std::mutex> lock(in.mu);
      // What the callbacks keep per drone, read once for the whole tick; and
      // the radio medium: beacons sent last tick, with the sender's true
      // position (below) for the receivers' range models.
      in.take_tick(tick_live, tick_phase, swarm_msg.beacons());
      release_mission();
      swarm_msg.recent_commands().assign(in.missions.ring().begin(), in.missions.ring().end());
      in.agents.publish(tick);
    }
    swarm_msg.tick(tick);
    swarm_msg.sim_time_s(t);
    for (int i = 0; i < n; ++i) {
      const DroneFacts f{.id = i,
                         .tick = tick,
                         .sim_time_s = t,
                         .state = swarm.state(i),
                         .rotor_rad_s = swarm.rotor_speeds(i),
                         .server_failsafe = failsafe.active(i),
                         .phase = tick_phase[i],
                         .agent_live = tick_live[i] != 0,
                         .motors_on = applied[i].motors_on,
                         .command_age_s = cmd_age_s[i]};
      fill_drone_state(swarm_msg.drones()[i], f, collisions, cfg.scene, cfg.sim.airborne_height_m);
      if (scan_tick) {
        swarm.cast_rays(i, cfg.sensors, ranges, hits);
        fill_scan(swarm_msg.scans()[i], tick, t, ranges, hits);
      }
      // A drone in failsafe (its agent lost, or its law faulted) no longer counts for the task.
      if (!f.server_failsafe && f.phase != Phase::kFailsafe)
        counted.add(i, f.state.p_world, f.state.v_world);
      else
        referee.note_lost(i);
    }
    for (auto& b : swarm_msg.beacons())
      b.true_position(swarm_msg.drones()[b.drone_id()].position());
    const bool task_changed = referee.update(t, counted.positions, counted.velocities, counted.ids,
                                             cfg.sim.task_timeout_s);
    out.swarm(swarm_msg);
    out.per_drone(swarm_msg, scan_tick);
    out.task(referee.report(), task_changed, wall_seconds());
  }

  // A tick published again says which agents are live now. Otherwise agents
  // that join while the swarm is paused at tick 0 read that tick, built before
  // they were heard, for as long as the pause lasts: each takes its drone's
  // missing DRONE_AGENT_LIVE for a server that does not hear it, and joins
  // again (agent/agent_app.cpp).
  void refresh_live_flags() {
    std::lock_guard<std::mutex> lock(in.mu);
    refresh_agent_live(swarm_msg.drones(), in.agents);
  }

  void publish_status(bool force) {
    double now = wall_seconds();
    // Who is live goes out at once: a ground station that has just heard
    // every agent's heartbeat must not get a latched status listing none.
    // So does a newly accepted mission command or a new phase: they confirm
    // the command, and its progress, to a ground station that never got that
    // agent's ack or heartbeats.
    if (!out.status_due(force, in.status_due.load(std::memory_order_relaxed), now, sim_time()))
      return;
    msg::SimStatus s;
    {
      std::lock_guard<std::mutex> lock(in.mu);
      s = in.counters;
      in.status_due = false;
      add_agents(s, in.agents);
    }
    s.rejected_malformed(static_cast<std::uint32_t>(malformed_samples().load()));
    s.tick(tick);
    s.sim_time_s(sim_time());
    s.wall_time_s(now - out.start_wall());
    s.state(state_text);
    s.real_time_factor(paused ? 0.0 : out.real_time_factor());
    add_swarm(s, swarm_msg.drones(), collisions);
    out.status(s);
  }

  /// Steps the world one period with the setpoints select_setpoints picks.
  void step() {
    {
      std::lock_guard<std::mutex> lock(in.mu);
      select_setpoints();
    }
    for (const auto& e : swarm.step(applied, cfg.sim.substeps(), dt_s)) on_contact(e);
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

  /// SIGUSR1 (from a user, or from ddswarm-launch when its discovery server
  /// dropped this participant's endpoints, so no agent will ever match them):
  /// leave DDS and start again as a new server, but only before any mission command came.
  bool rejoin_now() {
    if (in.rival_instance.load() != 0) return true;
    if (!take_rejoin_request() || !in.may_rejoin()) return false;
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
        std::unique_lock<std::mutex> lock(in.mu);
        in.expire_agents(wall_seconds());
        // A live agent a little late (descheduled for a moment) still gets
        // its answer into this step; the deadline of the next period stays.
        const TickBarrier& b = in.agents.barrier();
        if (b.waiting() > 0 && grace.count() > 0)
          in.cv.wait_until(lock, next + grace,
                           [&] { return b.waiting() == 0 || stop_requested(); });
      }
      if (rt_pipelined)
        step();
      else
        advance();
    }
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
        std::unique_lock<std::mutex> lock(in.mu);
        in.expire_agents(wall_seconds());
        // Lockstep: every live agent has answered the published tick.
        bool answered = in.agents.barrier().waiting() == 0;
        bool idle = cfg.sim.pause_when_idle && answered && in.agents.idle() &&
                    !in.missions.pending() && !referee.running();
        bool was_paused = paused;
        paused = idle;
        state_text = paused ? "paused: swarm idle" : answered ? "running" : "waiting for agents";
        go = answered && !idle;
        if (!go) in.cv.wait_for(lock, std::chrono::milliseconds(paused ? 50 : 20));
        if (paused != was_paused) out.status_soon();
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
        out.swarm(swarm_msg);
        last_republish = wall_seconds();
        if (!paused) {
          std::lock_guard<std::mutex> lock(in.mu);
          in.counters.lockstep_resends(in.counters.lockstep_resends() + 1);
        }
      }
      publish_status(false);
    }
  }

  SimServer::End run(double duration_s) {
    out.start(wall_seconds());
    double deadline = duration_s > 0 ? out.start_wall() + duration_s : 1e300;
    spdlog::info(
        "ddswarm-sim: scenario '{}', {} drones, {} mode{}, physics {} Hz, control {} Hz, seed {}",
        cfg.scenario.name, n, to_string(cfg.scenario.mode),
        pipelined || rt_pipelined ? " (pipelined: commands act one tick later)" : "",
        cfg.sim.physics_rate_hz, cfg.sim.control_rate_hz, cfg.scenario.seed);
    spdlog::info("ddswarm-sim: airframes: {}", fleet_summary(cfg.fleet()));
    if (!cfg.generated_world.empty())
      spdlog::info("ddswarm-sim: generated world: {}", cfg.generated_world);
    if (!cfg.scene.meshes.empty()) {
      std::size_t triangles = 0;
      for (const auto& m : cfg.scene.meshes) triangles += m.triangle_count;
      spdlog::info("ddswarm-sim: {} mesh obstacle(s), {} triangles", cfg.scene.meshes.size(),
                   triangles);
    }
    if (cfg.sensors.rows > 1)
      spdlog::info("ddswarm-sim: sensors: {} rows of {} rays over {} deg of elevation ({} a scan)",
                   cfg.sensors.rows, cfg.sensors.count, cfg.sensors.vertical_fov_deg,
                   cfg.sensors.rays());
    if (cfg.wind.enabled())
      spdlog::info("ddswarm-sim: wind {:.1f} m/s{}{}", cfg.wind.steady_mps.norm(),
                   cfg.wind.turbulence ? ", Dryden turbulence" : "",
                   cfg.wind.gusts_per_minute > 0 ? ", gusts" : "");
    if (cfg.aero.enabled())
      spdlog::info("ddswarm-sim: aerodynamics:{}{}{}",
                   cfg.aero.ground_effect ? " ground effect" : "",
                   cfg.aero.downwash ? " downwash" : "", cfg.aero.rotor_drag ? " rotor drag" : "");
    if (cfg.scenario.mode == TimeMode::kLockstep)
      run_lockstep(deadline);
    else
      run_realtime(deadline);
    state_text = "stopping";
    publish_status(true);
    spdlog::info("ddswarm-sim: stopped at tick {} (sim {:.2f} s)", tick, sim_time());
    if (in.rival_instance.load() != 0) return SimServer::End::kRivalServer;
    return rejoin ? SimServer::End::kRejoinRequested : SimServer::End::kStopped;
  }
};

SimServer::SimServer(ServerConfig cfg) : impl_(std::make_unique<Impl>(std::move(cfg))) {}
SimServer::~SimServer() = default;
SimServer::End SimServer::run(double duration_s) { return impl_->run(duration_s); }
std::uint64_t SimServer::rival_instance() const { return impl_->in.rival_instance.load(); }

}  // namespace ddswarm::sim
