#include "agent/agent_app.hpp"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <exception>
#include <map>
#include <mutex>
#include <optional>
#include <random>
#include <set>
#include <utility>

#include "agent/drone_brain.hpp"
#include "common/config_error.hpp"
#include "common/convert.hpp"
#include "common/participant.hpp"
#include "common/process.hpp"
#include "common/scene.hpp"

namespace ddswarm::agent {

namespace {

/// Why a scene cannot be flown (empty when it can): the checks the scene
/// file gets (SceneConfig::validate), and the control rates a server flies.
/// A broken or hostile Scene sample is refused before anything of it is applied.
std::string scene_problem(const msg::Scene& s) {
  try {
    check_range("scene.control_rate_hz", s.control_rate_hz(), kMinControlRateHz, kMaxControlRateHz);
    from_msg(s).validate();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

bool finite(const msg::Vec3& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

}  // namespace

/// One drone this process flies: its brain (the pure part) and what only
/// the DDS edge knows of it.
struct Drone {
  DroneBrain brain;
  std::uint64_t rival = 0;  // another instance heard on this id during the start-up probe
  std::string rival_where;
  // Wall time of the first swarm state, since this brain began answering,
  // whose row for this drone says the server hears no live agent for it
  // (no DRONE_AGENT_LIVE); -1 while the server hears it.
  double unheard_since = -1;

  Drone(int id, const AgentAppConfig& c)
      : brain(id, random_instance(), c.agent, c.comm, c.scenario.drones) {}
};

namespace {

/// The command as the wire carries it.
msg::VelocityCommand command_msg(const DroneCommand& c) {
  msg::VelocityCommand m;
  m.drone_id(static_cast<std::uint16_t>(c.drone_id));
  m.tick(c.tick);
  m.sim_time_s(c.sim_time_s);
  m.velocity(to_msg(c.velocity));
  m.yaw_rate_rad_s(c.yaw_rate_rad_s);
  m.motors_on(c.motors_on);
  m.phase(static_cast<std::uint8_t>(c.phase));
  m.busy(c.busy);
  m.mission_seq(c.mission_seq);
  m.mission_issuer(c.mission_issuer);
  m.agent_instance(c.agent_instance);
  if (c.beacon) {
    msg::Beacon& b = m.own_beacon();
    b.drone_id(static_cast<std::uint16_t>(c.drone_id));
    b.tick(c.tick);
    b.stamp_s(c.beacon->stamp_s);
    b.position(to_msg(c.beacon->reported_p));
    b.velocity(to_msg(c.beacon_velocity));
    m.has_beacon(true);
  }
  return m;
}

void log_note(const BrainNote& n) {
  switch (n.level) {
    case BrainNote::Level::kInfo:
      spdlog::info("{}", n.text);
      break;
    case BrainNote::Level::kWarn:
      spdlog::warn("{}", n.text);
      break;
    case BrainNote::Level::kError:
      spdlog::error("{}", n.text);
      break;
  }
}

}  // namespace

struct AgentApp::Impl {
  AgentAppConfig cfg;
  std::string label;  // "drone 3" or "agent host (512 drones)"
  Participant dds;
  Writer<msg::VelocityCommand> w_cmd;
  Writer<msg::AgentStatus> w_status;
  Writer<msg::MissionAck> w_ack;
  Writer<msg::Beacon> w_beacon;

  std::mutex mu;  // guards everything below (DDS callbacks run on Fast DDS threads)
  std::vector<std::unique_ptr<Drone>> brains;
  std::map<int, Drone*> by_id;
  std::optional<SceneConfig> scene;
  eprosima::fastrtps::rtps::GuidPrefix_t server;  // the scene's publisher
  std::uint64_t server_instance = 0;              // its Scene.server_instance
  double control_period_s = 0.02;
  double scene_control_rate_hz = 50;
  std::uint64_t scene_seed = 0;
  std::uint64_t last_tick = 0;
  bool have_tick = false;
  double last_sample_wall = -1e9;
  // The last swarm state taken: its writer and that writer's sequence number.
  eprosima::fastrtps::rtps::SampleIdentity last_state;
  double scene_wall = -1e9;  // when the server's scene came (wall)
  bool server_lost = false;
  // A lost server that is gone (lost_server_gone): the swarm-state reader is
  // made anew (sync_states_reader), once per loss, as docs/faults.md says.
  bool renew_states = false;
  bool states_renewed = false;    // for this loss
  std::uint64_t rejected = 0;     // samples refused before any drone saw them
  std::mt19937_64 loss_rng;       // agent.state_loss: which samples to drop
  bool loss_logged = false;       // agent.state_loss said so in the log
  bool copy_logged = false;       // a copied scene was refused, and the log said so
  bool bad_scene_logged = false;  // a scene that cannot be flown was refused, and the log said so
  // This tick's sample, converted once for every brain in the process.
  SwarmTick swarm;
  // How the swarm state should be read: best-effort with
  // dds.best_effort_streams, in both time modes (a lockstep server publishes
  // a tick again when answers stay missing), else reliably. The run loop
  // makes the reader (not a DDS callback: Fast DDS endpoints are created and
  // deleted outside its threads) and is woken when this changes.
  std::optional<Delivery> states_wanted;
  std::condition_variable woke;

  // The run loop's own: the swarm-state reader and how it reads, and the
  // scene reader, whose match says the server's participant is alive.
  Reader<msg::SwarmState>* states = nullptr;
  Reader<msg::Scene>* scenes = nullptr;
  Delivery states_delivery = Delivery::kProfile;

  // DDS callbacks touch the members below: stop them before anything is destroyed.
  ~Impl() { dds.close(); }

  static std::string label_for(const std::vector<int>& ids) {
    return ids.size() == 1 ? "drone " + std::to_string(ids[0])
                           : "agent host (" + std::to_string(ids.size()) + " drones)";
  }

  /// Under DDS Security on this host alone, an agent announces itself to the
  /// server and tools only (DdsConfig::announce_to_tools_only), so agents
  /// never authenticate with one another: their handshakes and key exchanges,
  /// N² of them, kept a 24-drone secure swarm from coming up. The duplicate
  /// probe cannot hear another agent then; the participant id does the job.
  static bool among_tools_only(const AgentAppConfig& c) {
    return c.dds.secure() && c.dds.discovery == Discovery::kLocalhost && c.drone_ids.size() == 1;
  }

  /// The agent's shared-memory outbox and port are sized for the drones it
  /// flies. Among tools only, drone K takes participant id
  /// kAgentParticipantIdBase + K unless told one. Where a process on this
  /// host holds it, another agent flies drone K (throws DuplicateAgent);
  /// unless its port lies in the kernel's ephemeral range, where any
  /// outgoing socket may hold it: then Fast DDS picks an id, and this agent
  /// hears and is heard by the other agents, at their cost.
  static DdsConfig dds_for(const AgentAppConfig& c) {
    DdsConfig d = c.dds;
    d.shm_segment_bytes = agent_shm_segment_bytes(c.drone_ids.size());
    d.shm_port_queue = agent_shm_port_queue(c.drone_ids.size());
    if (among_tools_only(c)) {
      d.announce_to_tools_only = true;
      const int id = kAgentParticipantIdBase + c.drone_ids[0];
      if (d.participant_id < 0 && id <= max_participant_id(d.domain_id)) {
        d.participant_id = id;
        if (participant_id_taken_here(d.domain_id, id)) {
          const int port = rtps_unicast_port(d.domain_id, id);
          if (!ephemeral_port_range().contains(port))
            throw DuplicateAgent(fmt::format(
                "drone {} is already flown on this host: a process holds its participant id {} "
                "(UDP 127.0.0.1:{}); if it is no agent, give this one --participant-id",
                c.drone_ids[0], id, port));
          spdlog::warn(
              "drone {}: participant id {}'s port {} is held, and lies in the kernel's "
              "ephemeral port range, where any socket may hold it; Fast DDS picks an id "
              "instead (docs/security.md)",
              c.drone_ids[0], id, port);
          d.participant_id = -1;
        }
      }
    }
    return d;
  }

  explicit Impl(AgentAppConfig c)
      : cfg(std::move(c)),
        label(label_for(cfg.drone_ids)),
        dds(dds_for(cfg), cfg.drone_ids.size() == 1
                              ? "ddswarm-agent-" + std::to_string(cfg.drone_ids[0])
                              : "ddswarm-agent-host"),
        // Under DDS Security only agent-K may publish in drone K's partition
        // (one drone per secure agent process: docs/security.md).
        w_cmd(dds.writer<msg::VelocityCommand>(
            cfg.dds.secure() ? drone_partition(cfg.drone_ids.at(0)) : "")),
        w_status(dds.writer<msg::AgentStatus>()),
        w_ack(dds.writer<msg::MissionAck>()),
        w_beacon(dds.writer<msg::Beacon>()),
        loss_rng(0x5eed1055ULL + static_cast<std::uint64_t>(cfg.drone_ids.at(0))) {
    for (int id : cfg.drone_ids) {
      brains.push_back(std::make_unique<Drone>(id, cfg));
      by_id[id] = brains.back().get();
    }
    Reader<msg::AgentStatus>* probe = nullptr;
    const bool probe_agents = cfg.duplicate_probe_s > 0 && !among_tools_only(cfg);
    if (probe_agents)
      probe =
          &dds.reader<msg::AgentStatus>([this](const msg::AgentStatus& s, const fdds::SampleInfo&) {
            std::lock_guard<std::mutex> lock(mu);
            auto it = by_id.find(s.drone_id());
            if (it == by_id.end() || s.agent_instance() == it->second->brain.instance()) return;
            it->second->rival = s.agent_instance();
            it->second->rival_where = s.host().to_string() + " pid " + std::to_string(s.pid());
          });
    scenes = &dds.reader<msg::Scene>([this](const msg::Scene& s, const fdds::SampleInfo& info) {
      std::lock_guard<std::mutex> lock(mu);
      on_scene(s, info.sample_identity.writer_guid().guidPrefix);
    });
    // Listen before speaking: refuse to fly a drone another agent already flies.
    if (probe_agents) wait_for_stop(std::chrono::duration<double>(cfg.duplicate_probe_s));
    {
      std::lock_guard<std::mutex> lock(mu);
      for (const auto& b : brains)
        if (b->rival)
          throw DuplicateAgent("drone " + std::to_string(b->brain.id()) +
                               " is already flown by agent " + fmt::format("{:016x}", b->rival) +
                               " (" + b->rival_where + ")");
    }
    // Every agent hearing every other's heartbeat is O(N^2) traffic: at 64
    // agents it cost 1.7 cores of a paused swarm. After the probe, a rival is
    // the server's business (it keeps the first owner and counts impostors).
    if (probe) dds.remove(*probe);
    publish_status();
  }

  /// Makes the swarm-state reader once a scene says how to read (and again
  /// when a new server's scene says otherwise). Call without mu held:
  /// removing a reader waits for its running callback, which takes mu.
  void sync_states_reader() {
    std::optional<Delivery> want;
    bool renew = false;
    {
      std::lock_guard<std::mutex> lock(mu);
      want = states_wanted;
      renew = std::exchange(renew_states, false) && states != nullptr;
    }
    if (!want || (states && *want == states_delivery && !renew)) return;
    // Renewed when the lost server is gone (lost_server_gone): a server
    // SIGKILLed while it notified this reader left its lock held, and every
    // later writer would wait 1 s on it per sample, a new server included.
    // Deleting the reader takes that lock as well: where Fast DDS throws, this
    // agent starts again (restart_on_dead_owner_lock), here as on Fast DDS's
    // own threads. A sound reader is made anew in a moment.
    const StuckGuard stuck("making the swarm-state reader anew", kDdsStepStuckS);
    if (states) {
      try {
        dds.remove(*states);
      } catch (const std::exception& e) {
        if (is_dead_owner_lock_timeout(e.what())) std::terminate();
        throw;
      }
    }
    states = &dds.reader<msg::SwarmState>(
        [this](const msg::SwarmState& s, const fdds::SampleInfo& info) {
          on_swarm(s, info.sample_identity);
        },
        std::nullopt, *want);
    states_delivery = *want;
    spdlog::info("{}: reading the swarm state {}", label,
                 *want == Delivery::kLatest ? "best-effort" : "reliably");
  }

  /// The participant that announces the scene is the server: swarm samples
  /// are taken from it alone. A restarted server announces itself again. mu held.
  void on_scene(const msg::Scene& s, const eprosima::fastrtps::rtps::GuidPrefix_t& from) {
    // Every server participant has its own instance (a re-joined server is a
    // new one), so this instance from another participant is a copy (a
    // replay, a relay): refused, or its sender would become "the server".
    if (scene && s.server_instance() == server_instance && from != server) {
      ++rejected;
      if (!std::exchange(copy_logged, true))
        spdlog::warn(
            "{}: refused a copy of the server's scene (instance {:016x}) from another "
            "participant; staying with the server that announced it",
            label, s.server_instance());
      return;
    }
    if (const std::string why = scene_problem(s); !why.empty()) {
      ++rejected;
      if (!std::exchange(bad_scene_logged, true))
        spdlog::warn("{}: refused a scene (instance {:016x}) that cannot be flown: {}", label,
                     s.server_instance(), why);
      return;
    }
    const int highest =
        cfg.drone_ids.empty() ? 0 : *std::max_element(cfg.drone_ids.begin(), cfg.drone_ids.end());
    if (s.num_drones() <= highest) {
      spdlog::error("{}: the server flies only {} drones", label, s.num_drones());
      return;
    }
    server = from;
    if (scene && s.server_instance() == server_instance)
      return;  // a re-announcement: keep the mission
    scene_wall = wall_seconds();
    if (scene) {
      // A restarted server is a new world: the drone is back at its start,
      // so the old mission no longer applies. Start over and catch up with
      // whatever the new server's ring says.
      for (const auto& b : brains) {
        spdlog::warn("drone {}: new server instance {:016x} (was {:016x}): mission reset",
                     b->brain.id(), s.server_instance(), server_instance);
        b->brain.reset();
      }
      have_tick = false;
    }
    server_instance = s.server_instance();
    states_wanted = cfg.dds.best_effort_streams ? Delivery::kLatest : Delivery::kProfile;
    woke.notify_all();
    control_period_s = 1.0 / s.control_rate_hz();
    scene_control_rate_hz = s.control_rate_hz();
    scene_seed = s.seed();
    scene = from_msg(s);
    for (const auto& b : brains) start_brain(*b);
    // Under DDS Security, how long the server took (docs/security.md).
    std::optional<RemotePeer> sender;
    for (const auto& p : dds.peers_named(kServerParticipantName))
      if (p.prefix == from && p.authenticated_after_s >= 0) sender = p;
    if (sender)
      spdlog::info(
          "{}: scene '{}' received, {:.1f} s after the server announced itself (it "
          "authenticated this participant after {:.1f} s)",
          label, s.name().to_string(), sender->announced_s, sender->authenticated_after_s);
    else
      spdlog::info("{}: scene '{}' received", label, s.name().to_string());
    const double reach = sensor_range_m(cfg.agent.sensor_function);
    if (reach > s.sensor_max_range_m() + 1e-6)
      spdlog::warn(
          "{}: agent.sensor_function reacts up to {:.1f} m but the sensors "
          "(sensors.max_range_m) see only {:.1f} m: the reaction jumps when an obstacle "
          "comes into view",
          label, reach, s.sensor_max_range_m());
  }

  void start_brain(Drone& d) {
    for (const auto& n : d.brain.start(*scene, scene_control_rate_hz, scene_seed)) log_note(n);
    if (&d != brains.front().get()) return;
    if (d.brain.law_config().type != LawType::kThesis)
      spdlog::info("{}: flying the {} law", label, d.brain.law_config().name());
    if (cfg.comm.ideal()) return;
    const double ticks_per_beacon = scene_control_rate_hz / cfg.comm.beacon_rate_hz;
    if (cfg.comm.source == PeerSourceType::kBeacons &&
        std::abs(ticks_per_beacon - std::round(ticks_per_beacon)) > 1e-9)
      spdlog::warn(
          "{}: comm.beacon_rate_hz {} does not divide the control rate {} Hz; "
          "beacons go every {} ticks",
          label, cfg.comm.beacon_rate_hz, scene_control_rate_hz, std::round(ticks_per_beacon));
    spdlog::info("{}: peers from {} through the communication model", label,
                 cfg.comm.source == PeerSourceType::kBeacons ? "beacons" : "truth");
  }

  void publish_status() {
    std::vector<msg::AgentStatus> out;
    {
      std::lock_guard<std::mutex> lock(mu);
      char host[64] = {};
      gethostname(host, sizeof host - 1);
      for (const auto& d : brains) {
        const DroneBrain& b = d->brain;
        msg::AgentStatus s;
        s.drone_id(static_cast<std::uint16_t>(b.id()));
        s.agent_instance(b.instance());
        s.host(host);
        s.pid(getpid());
        s.phase(static_cast<std::uint8_t>(b.phase()));
        s.server_lost(server_lost);
        s.last_tick(last_tick);
        s.inter_distance_m(b.inter_distance_m());
        s.rejected_samples(
            static_cast<std::uint32_t>(rejected + b.rejected() + malformed_samples().load()));
        s.commands_sent(static_cast<std::uint32_t>(b.sent()));
        s.law(b.law_config().name().substr(0, 32));
        s.law_faults(static_cast<std::uint32_t>(b.law_faults()));
        s.law_fault(b.law_fault().substr(0, 255));
        out.push_back(std::move(s));
      }
    }
    for (auto& s : out) w_status.write(s);
  }

  /// One server tick: check the sample once, then every drone's brain answers.
  void on_swarm(const msg::SwarmState& s, const eprosima::fastrtps::rtps::SampleIdentity& id) {
    const auto& from = id.writer_guid().guidPrefix;
    std::lock_guard<std::mutex> lock(mu);
    if (!scene) return;  // no scene yet
    if (cfg.agent.state_loss > 0 &&
        std::uniform_real_distribution<double>(0.0, 1.0)(loss_rng) < cfg.agent.state_loss) {
      if (!std::exchange(loss_logged, true))
        spdlog::info("{}: dropping {:.1f} % of swarm states (agent.state_loss)", label,
                     100 * cfg.agent.state_loss);
      return;
    }
    if (from != server ||
        !std::isfinite(s.sim_time_s())) {  // not the server that announced the scene
      ++rejected;
      return;
    }
    // A state its writer sent before one already taken: a reader made anew
    // once the server went silent is handed the server's last state again
    // (transient-local), though that server may be dead. It is no sign of
    // life. A lockstep server that publishes a tick again writes it anew.
    if (id.writer_guid() == last_state.writer_guid() &&
        id.sequence_number() <= last_state.sequence_number()) {
      ++rejected;
      return;
    }
    last_state = id;
    if (have_tick && s.tick() < last_tick) {
      if (!server_lost) {  // a restarted server starts again from 0; anything else is stale
        ++rejected;
        return;
      }
    }
    last_sample_wall = wall_seconds();
    if (server_lost) {
      spdlog::info("{}: server samples resumed at tick {}", label, s.tick());
      server_lost = false;
    }
    have_tick = true;
    last_tick = s.tick();
    convert(s);
    for (const auto& d : brains) answer(*d);
  }

  /// The sample as every brain reads it (swarm), converted once.
  void convert(const msg::SwarmState& s) {
    swarm.tick = s.tick();
    swarm.sim_time_s = s.sim_time_s();
    swarm.drones.resize(s.drones().size());
    swarm.roster.clear();
    for (std::size_t k = 0; k < s.drones().size(); ++k) {
      const auto& d = s.drones()[k];
      DroneRow& r = swarm.drones[k];
      r.id = d.drone_id();
      r.valid = finite(d.position()) && finite(d.velocity());
      r.agent_live = (d.flags() & msg::DRONE_AGENT_LIVE) != 0;
      r.p_world = from_msg(d.position());
      r.v_world = from_msg(d.velocity());
      r.q_world_body = from_msg(d.orientation());
      r.ray_range_m = {};
      r.ray_hit = {};
      r.ray_yaw_body_rad = {};
      r.ray_elevation_body_rad = {};
      if (k < s.scans().size()) {  // checked by the drone's brain (DroneRow)
        const auto& sc = s.scans()[k];
        r.ray_range_m = sc.range_m();
        r.ray_hit = sc.hit();
        r.ray_yaw_body_rad = sc.angle_body_rad();
        r.ray_elevation_body_rad = sc.elevation_body_rad();
      }
      // A drone without a live agent (lost: the server's failsafe flies it,
      // hovering then landing) is no member of the swarm: no attraction to
      // it, or the swarm would stay tied to a wreck. The distance sensors
      // still see it as an obstacle.
      if (!r.agent_live || (d.flags() & msg::DRONE_FAILSAFE)) continue;
      if (!finite(d.position())) {
        ++rejected;
        continue;
      }
      PeerObservation o{d.drone_id(), r.p_world, d.sim_time_s()};
      if (finite(d.velocity())) o.v_world = r.v_world;
      swarm.roster.push_back(o);
    }
    swarm.missions.resize(s.recent_commands().size());
    for (std::size_t k = 0; k < s.recent_commands().size(); ++k) {
      const auto& m = s.recent_commands()[k];
      RelayedMission& r = swarm.missions[k];
      r.command = from_msg(m);
      r.issuer_instance = m.issuer_instance();
      r.apply_tick = m.apply_tick();
      r.problem = mission_problem(m);
    }
    swarm.beacons.clear();
    for (const auto& bc : s.beacons())
      swarm.beacons.push_back({bc.drone_id(), bc.tick(), bc.stamp_s(), from_msg(bc.position()),
                               from_msg(bc.true_position())});
  }

  /// Drone d's brain answers the tick; this writes and logs what it says.
  void answer(Drone& d) {
    // Answering, yet marked agent-less: the server does not hear this agent.
    if (const DroneRow* me = swarm.row(d.brain.id()); me && me->valid && d.brain.started()) {
      if (d.brain.sent() > 0 && !me->agent_live) {
        if (d.unheard_since < 0) d.unheard_since = wall_seconds();
      } else {
        d.unheard_since = -1;
      }
    }
    TickAnswer a = d.brain.tick(swarm);
    for (const auto& n : a.notes) log_note(n);
    for (const auto& k : a.acks) w_ack.write(to_msg(k.ack, k.issuer_instance));
    if (a.kind == TickAnswer::Kind::kNone) return;
    const msg::VelocityCommand cmd = command_msg(a.command);
    if (a.publish_beacon) w_beacon.write(cmd.own_beacon());
    w_cmd.write(cmd);
  }

  AgentApp::End run(double duration_s) {
    const double joined = wall_seconds();
    // Both waits spread by process, up to AgentConfig::kRejoinSpread longer,
    // so that agents that missed the server do not all join again at once.
    const double spread = 1.0 + AgentConfig::kRejoinSpread *
                                    static_cast<double>(brains[0]->brain.instance() % 1024) /
                                    1024.0;
    JoinPatience join_patience;
    join_patience.lease_s = cfg.dds.lease_duration_s;
    join_patience.scene_wait_s = cfg.agent.rejoin_after_s * spread;
    join_patience.handshake_timeout_s = cfg.agent.handshake_timeout_s;
    join_patience.handshake_wait_s = cfg.agent.handshake_timeout_s * spread;
    double end = duration_s > 0 ? joined + duration_s : 1e300;
    if (brains.size() == 1)
      spdlog::info("drone {}: agent {:016x} flying (pid {})", brains[0]->brain.id(),
                   brains[0]->brain.instance(), getpid());
    else
      spdlog::info("{}: flying drones {}..{} (pid {})", label, brains.front()->brain.id(),
                   brains.back()->brain.id(), getpid());
    LeaseWatch lease(cfg.dds.lease_duration_s, wall_seconds());
    const StopWaker stop_waker([this] {
      { const std::lock_guard<std::mutex> lock(mu); }  // the loop is waiting, or has not yet tested
      woke.notify_all();
    });
    while (!stop_requested() && wall_seconds() < end) {
      // This loop turns at least every 250 ms: a longer gap than the lease
      // means a stop or a starved machine (an agent stayed deaf to the server
      // after SIGCONT in CI, docs/faults.md).
      if (const std::string why = lease.turn(wall_seconds()); !why.empty()) {
        spdlog::warn("{}: {}", label, why);
        settle_after_stop();
        return AgentApp::End::kOutlivedLease;
      }
      if (take_rejoin_request()) {
        spdlog::warn(
            "{}: asked to join again (SIGUSR1, as ddswarm-launch sends when its discovery "
            "server dropped this participant); leaving DDS and joining again as a new "
            "participant",
            label);
        return AgentApp::End::kRejoinRequested;
      }
      sync_states_reader();
      publish_status();
      {
        std::unique_lock<std::mutex> lock(mu);
        double silent = wall_seconds() - last_sample_wall;
        if (have_tick && !server_lost && silent > cfg.agent.server_timeout_s) {
          server_lost = true;
          states_renewed = false;
          for (auto& b : brains) b->unheard_since = -1;  // counted again once it speaks
          spdlog::warn("{}: no server samples for {:.1f} s; holding commands until it returns",
                       label, silent);
        }
        JoinView view;
        view.now_s = wall_seconds();
        view.joined_s = joined;
        view.has_scene = scene.has_value();
        view.server_lost = server_lost;
        view.last_state_s = last_sample_wall;
        view.scene_s = scene_wall;
        view.scene_writer_matched = scenes->matched() > 0;
        view.scene_matched_since_s = scenes->matched_since();
        for (const auto& b : brains)  // < 0: heard, or the server went silent since
          if (b->unheard_since >= 0)
            view.unheard_since.emplace_back(b->brain.id(), b->unheard_since);
        for (const auto& p : dds.peers_named(kServerParticipantName))
          view.servers.push_back({p.prefix == server, p.announced_s, p.authenticated_after_s});
        view.secure = dds.secure();
        if (!states_renewed && lost_server_gone(view)) {
          renew_states = true;  // sync_states_reader, at the next turn
          states_renewed = true;
        }
        if (auto verdict = why_join_again(view, join_patience)) {
          spdlog::warn("{}: {}", label, verdict->why);
          return verdict->end;
        }
        // Woken at once when a scene asks for a (new) swarm-state reader or a
        // stop is requested (stop_waker), else after 250 ms: no polling, so
        // this thread wakes 4 times a second, not 20.
        woke.wait_for(lock, std::chrono::milliseconds(250), [&] {
          return stop_requested() ||
                 (states_wanted && (!states || *states_wanted != states_delivery));
        });
      }
    }
    return AgentApp::End::kStopped;
  }
};

AgentApp::AgentApp(AgentAppConfig cfg) : impl_(std::make_unique<Impl>(std::move(cfg))) {}
AgentApp::~AgentApp() = default;
AgentApp::End AgentApp::run(double duration_s) { return impl_->run(duration_s); }
bool AgentApp::heard_scene() const {
  const std::lock_guard<std::mutex> lock(impl_->mu);
  return impl_->scene.has_value();
}

}  // namespace ddswarm::agent
