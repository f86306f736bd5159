#include "ground_station/dds_commander.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <map>
#include <mutex>
#include <random>
#include <set>

#include "common/convert.hpp"
#include "common/mission.hpp"
#include "common/participant.hpp"
#include "common/process.hpp"

namespace ddswarm::gs {

namespace {
/// v with decimals, or "n/a" when not measured (NaN).
std::string measured(double v, int decimals) {
  return std::isfinite(v) ? fmt::format("{:.{}f}", v, decimals) : "n/a";
}
}  // namespace

std::string TaskOutcome::line() const {
  std::string lost;
  if (!lost_drones.empty())
    lost = fmt::format("; lost drones (agent lost, failsafe): {}", fmt::join(lost_drones, ", "));
  if (!ok) return "task failed: " + reason + lost;
  const SwarmTaskMetrics& m = metrics;
  const std::string swarm = fmt::format(
      "; order {} (min {}), mean speed {} m/s, near misses {}, components max {}, lambda2 min {}",
      measured(m.order_mean, 2), measured(m.order_min, 2), measured(m.speed_mean_mps, 2),
      m.near_misses, m.components_max, measured(m.lambda2_min, 2));
  return fmt::format(
             "task complete: {:.2f} s sim time (wall {:.1f} s), {} drones at {:.2f} m/s, "
             "collisions: "
             "obstacle {}, drone {}, ground {}; min inter-drone distance {:.2f} m, min obstacle "
             "clearance {:.2f} m",
             task_time_s, wall_time_s, drones, speed_mps, collisions_obstacle, collisions_drone,
             collisions_ground, min_inter_drone_m, min_clearance_m) +
         swarm + lost;
}

namespace {
/// Seconds without a new ack writer matched after which a ground station
/// stops waiting for the rest (wait_for_server).
constexpr double kMatchQuietS = 2.0;

struct AgentSeen {
  double wall = -1e9;
  double d_int = 0;
  Phase phase = Phase::kIdle;
  std::uint64_t rejected = 0;  // AgentStatus.rejected_samples
  std::string process;         // host:pid of the agent process flying it
  std::string law;             // AgentStatus.law
  std::string law_fault;       // AgentStatus.law_fault, empty while sound
};
}  // namespace

struct DdsCommander::Impl {
  GroundStationConfig cfg;
  const std::uint64_t instance;
  Participant dds;
  Writer<msg::MissionCommand> w_mission;

  mutable std::mutex mu;
  std::condition_variable cv;
  std::optional<msg::SimStatus> sim;
  double sim_wall = -1e9;
  std::optional<msg::TaskStatus> task;
  std::uint64_t scene_seed = 0;
  std::string scene_name;
  std::map<int, AgentSeen> agents;
  std::map<std::uint32_t, std::map<int, msg::MissionAck>> acks;  // seq -> drone -> ack
  std::uint32_t seq = 0;
  std::uint32_t task_seq = 0;
  double last_command_wall = -1e9;  // when the latest command was sent
  std::uint32_t last_seq = 0;       // the latest command's seq
  Reader<msg::MissionAck>* ack_reader = nullptr;
  Reader<msg::TaskStatus>* task_reader = nullptr;
  std::optional<TaskOutcome> outcome;
  Reader<msg::SwarmState>* state_reader = nullptr;  // made by the first swarm_snapshot()
  std::optional<msg::SwarmState> state;             // the latest, once state_reader exists
  std::atomic<bool> interrupted{false};             // set_interrupted()

  /// A stop was requested: a signal, or set_interrupted(true).
  bool stopped() const { return stop_requested() || interrupted; }

  /// The swarm state's reader, made on first use.
  void ensure_state_reader() {
    if (state_reader) return;
    state_reader =
        &dds.reader<msg::SwarmState>([this](const msg::SwarmState& s, const fdds::SampleInfo&) {
          std::lock_guard<std::mutex> lock(mu);
          state = s;
          cv.notify_all();
        });
  }

  // DDS callbacks touch the members below: stop them before anything is destroyed.
  ~Impl() { dds.close(); }

  /// Under DDS Security on one host a ground station meets the server and
  /// tools only, never an agent (DdsConfig::meets_agents): each command is a
  /// new participant, and N handshakes with the agents per command, beside
  /// the swarm's own bring-up, overflowed the discovery ports at 64 drones.
  /// The server relays what it needs of them: who is live, each drone's
  /// phase and the commands each accepted (accepted_by).
  static DdsConfig meeting(DdsConfig d) {
    if (d.secure() && d.discovery == Discovery::kLocalhost) d.meets_agents = false;
    return d;
  }

  Impl(const GroundStationConfig& c, const DdsConfig& d)
      : cfg(c),
        instance(random_instance()),
        dds(meeting(d), "ddswarm-gs"),
        w_mission(dds.writer<msg::MissionCommand>()) {
    // Seqs increase across ground-station sessions too, so agents never
    // mistake a new session's command for a repeat of an old one.
    seq = static_cast<std::uint32_t>(std::time(nullptr) % 1000000) * 1000;
    dds.reader<msg::SimStatus>([this](const msg::SimStatus& s, const fdds::SampleInfo&) {
      std::lock_guard<std::mutex> lock(mu);
      sim = s;
      sim_wall = wall_seconds();
      cv.notify_all();
    });
    dds.reader<msg::Scene>([this](const msg::Scene& sc, const fdds::SampleInfo&) {
      std::lock_guard<std::mutex> lock(mu);
      scene_seed = sc.seed();
      scene_name = sc.name().to_string();
    });
    task_reader =
        &dds.reader<msg::TaskStatus>([this](const msg::TaskStatus& t, const fdds::SampleInfo&) {
          std::lock_guard<std::mutex> lock(mu);
          task = t;
          cv.notify_all();
        });
    dds.reader<msg::AgentStatus>([this](const msg::AgentStatus& a, const fdds::SampleInfo&) {
      std::lock_guard<std::mutex> lock(mu);
      auto& s = agents[a.drone_id()];
      s.wall = wall_seconds();
      s.d_int = a.inter_distance_m();
      s.phase = static_cast<Phase>(a.phase());
      s.process = a.host().to_string() + ":" + std::to_string(a.pid());
      s.rejected = a.rejected_samples();
      s.law = a.law().to_string();
      s.law_fault = a.law_fault().to_string();
      cv.notify_all();
    });
    ack_reader =
        &dds.reader<msg::MissionAck>([this](const msg::MissionAck& a, const fdds::SampleInfo&) {
          std::lock_guard<std::mutex> lock(mu);
          if (a.issuer_instance() != instance) return;
          acks[a.seq()][a.drone_id()] = a;
          cv.notify_all();
        });
  }

  /// count, or every drone of the server's scenario when count < 0. Needs sim.
  std::size_t wanted(int count) const {
    return static_cast<std::size_t>(count >= 0 ? count : sim->num_drones());
  }

  /// The server's own latest status lists count agents live (count < 0:
  /// every drone). A ground station can hear an agent that the server does
  /// not: under load, discovery may have matched the agent with this process
  /// but not yet with the server, and the server releases a mission command
  /// only to the agents it hears. The online set (online_locked) includes
  /// the server's list.
  bool server_hears_at_least(int count) const {
    return sim && sim->live_agents().size() >= wanted(count);
  }

  /// Agents heard recently, plus those the server (the authority on
  /// liveness) reports live in its latest status.
  std::set<int> online_locked() const {
    std::set<int> out;
    double now = wall_seconds();
    for (const auto& [id, s] : agents)
      if (now - s.wall <= cfg.online_window_s) out.insert(id);
    if (sim && now - sim_wall <= cfg.online_window_s)
      for (auto id : sim->live_agents()) out.insert(id);
    return out;
  }

  double d_int_locked() const {
    double d = 0;
    for (const auto& [id, s] : agents) d = std::max(d, s.d_int);
    return d > 0 ? d : 4.0;
  }

  /// Waits until done() holds (evaluated with mu held) or timeout_s; false
  /// on timeout or when a stop was requested.
  template <class Pred>
  bool wait(double timeout_s, Pred done) {
    using namespace std::chrono;
    const auto end =
        steady_clock::now() + duration_cast<steady_clock::duration>(duration<double>(timeout_s));
    std::unique_lock<std::mutex> lock(mu);
    // A signal handler cannot notify cv, and with no server nothing else
    // does: look at the stop flag (Ctrl-C) every 100 ms.
    while (!stopped() && !done()) {
      const auto now = steady_clock::now();
      if (now >= end) return false;
      cv.wait_for(lock, std::min<steady_clock::duration>(end - now, milliseconds(100)));
    }
    return !stopped();
  }

  /// The task status is latched: once our reader has matched the server's
  /// writer, its last sample follows. On a loaded machine (a lockstep swarm
  /// busy on every core) the match can come seconds after the server's first
  /// status, so wait up to match_s for the match, then up to sample_s for done().
  template <class Pred>
  bool wait_latched_task(double match_s, double sample_s, Pred done) {
    wait(match_s, [&] { return done() || task_reader->matched() > 0; });
    return wait(sample_s, done);
  }

  /// The server says drone id's agent accepted our command seq (relayed from
  /// its VelocityCommand): for an agent whose acks or heartbeats never reach us.
  bool accepted_by(int id, std::uint32_t seq) const {
    const auto k = static_cast<std::size_t>(id);
    return sim && id >= 0 && k < sim->mission_seq().size() && k < sim->mission_issuer().size() &&
           sim->mission_seq()[k] == seq && sim->mission_issuer()[k] == instance;
  }

  /// The server hears our commands and every online agent's acks reach us. mu held.
  bool all_matched() const {
    // One ack writer per agent process; an agent host flies many drones.
    std::set<std::string> processes;
    for (int id : online_locked()) {
      auto it = agents.find(id);
      processes.insert(it != agents.end() && !it->second.process.empty()
                           ? it->second.process
                           : "drone " + std::to_string(id));
    }
    // Meeting no agent, it takes the server's word for every ack.
    return w_mission.matched() > 0 &&
           (!dds.meets_agents() || ack_reader->matched() >= static_cast<int>(processes.size()));
  }

  CommandResult send(MissionCommand c) {
    std::unique_lock<std::mutex> lock(mu);
    c.seq = ++seq;
    c.issuer = cfg.name;
    std::set<int> expect = online_locked();
    if (c.target >= 0) expect = expect.count(c.target) ? std::set<int>{c.target} : std::set<int>{};
    if (expect.empty()) {
      return {false, c.target >= 0 ? fmt::format("drone {} is not online", c.target)
                                   : "no agent is online"};
    }
    msg::MissionCommand m = to_msg(c);
    m.issuer_instance(instance);
    // Addressed to the server we hear: a restarted server ignores it (our
    // transient-local history must not replay an old mission in a new world).
    if (sim) m.server_instance(sim->server_instance());
    last_command_wall = wall_seconds();
    last_seq = c.seq;
    lock.unlock();
    if (!w_mission.write(m)) return {false, "DDS refused the command"};
    lock.lock();
    const std::uint32_t s = c.seq;
    // Accepted, as the server relays it from the agent's commands: for an
    // agent whose ack writer this process never discovered.
    auto relayed = [&](int id) { return accepted_by(id, s); };
    auto answered = [&](int id) { return acks[s].count(id) > 0 || relayed(id); };
    auto all_in = [&] {
      if (stopped()) return true;
      for (int id : expect)
        if (!answered(id)) return false;
      if (c.target < 0)  // an agent heard only now must answer too
        for (int id : online_locked())
          if (!answered(id)) return false;
      return true;
    };
    // One retry with the same seq after a third of the timeout: agents that
    // applied it only acknowledge again.
    if (!cv.wait_for(lock, std::chrono::duration<double>(cfg.ack_timeout_s / 3), all_in)) {
      lock.unlock();
      w_mission.write(m);
      lock.lock();
      cv.wait_for(lock, std::chrono::duration<double>(cfg.ack_timeout_s * 2 / 3), all_in);
    }
    const auto& got = acks[s];
    // Drones whose heartbeat arrived while we waited, or that answered anyway, count too.
    if (c.target < 0) {
      for (int id : online_locked()) expect.insert(id);
      for (const auto& [id, a] : got) expect.insert(id);
    }
    CommandResult r;
    std::vector<int>& missing = r.missing;
    std::string rejected;
    int accepted = 0, via_server = 0;
    for (int id : expect) {
      auto it = got.find(id);
      if (it == got.end()) {
        if (relayed(id)) {
          ++accepted;
          ++via_server;
        } else {
          missing.push_back(id);
        }
      } else if (!it->second.accepted()) {
        rejected += fmt::format("{}rejected by {}: {}", rejected.empty() ? "" : "; ", id,
                                it->second.reason().to_string());
        r.rejected.emplace_back(id, it->second.reason().to_string());
      } else {
        ++accepted;
      }
    }
    r.ok = missing.empty() && rejected.empty();
    r.message = fmt::format("{} {}/{} acknowledged", to_string(c.type), accepted, expect.size());
    if (via_server > 0) r.message += fmt::format(" ({} through the server)", via_server);
    if (!missing.empty())
      r.message += fmt::format("; no ack from drones {}", fmt::join(missing, ", "));
    if (!rejected.empty()) r.message += "; " + rejected;
    if (c.type == MissionType::kTask) task_seq = s;
    return r;
  }
};

DdsCommander::DdsCommander(const GroundStationConfig& cfg, const DdsConfig& dds)
    : impl_(std::make_unique<Impl>(cfg, dds)) {}
DdsCommander::~DdsCommander() = default;

bool DdsCommander::wait_for_swarm(int count, double timeout_s,
                                  const std::function<bool()>& give_up) {
  auto& I = *impl_;
  bool gave_up = false;
  const bool up = I.wait(timeout_s, [&] {
    gave_up = give_up && give_up();
    return gave_up || (I.server_hears_at_least(count) && I.all_matched());
  });
  return up && !gave_up;
}

bool DdsCommander::wait_for_online(int count, double timeout_s) {
  // The server's view only: an agent this process hears but the server does
  // not yet would miss the first ticks of a command sent now, and a lockstep
  // run with the same seed would fly differently (mp_comm_task).
  return impl_->wait(timeout_s, [&] { return impl_->server_hears_at_least(count); });
}

bool DdsCommander::wait_for_server(double timeout_s) {
  auto& I = *impl_;
  auto everyone = [&] {
    return I.sim && I.online_locked().size() >= I.sim->agents_live() && I.all_matched();
  };
  // First the server, for up to the discovery timeout.
  if (!I.wait(timeout_s, [&] { return everyone() || (I.sim && I.w_mission.matched() > 0); }))
    return false;
  // Then every live agent's ack writer, for up to the ack timeout: an ack
  // written before it matched our reader could be lost. A frozen or
  // unreachable agent never matches, so go on after that and let the
  // acknowledgements name whoever stays silent. Nor does an agent whose
  // writer Fast DDS leaves unmatched (at 128 processes, after a re-join): it
  // would hold every command for the whole timeout, though the server relays
  // what it accepts. So stop waiting, too, once no writer has matched for
  // kMatchQuietS.
  int matched = -1;
  double since = wall_seconds();
  I.wait(I.cfg.ack_timeout_s, [&] {
    if (everyone()) return true;
    if (const int m = I.ack_reader->matched(); m != matched) {
      matched = m;
      since = wall_seconds();
    }
    return wall_seconds() - since > kMatchQuietS;
  });
  return !I.stopped();
}

ServerSearch server_search(const std::vector<ServerPeer>& servers, bool secure, bool status_heard) {
  using State = ServerSearch::State;
  if (status_heard) return {State::kHeard, "its status heard"};
  if (servers.empty()) return {State::kNothing, "no server's participant discovered"};
  const ServerPeer& newest = servers.back();
  const std::string ago = fmt::format("{:.0f} s ago", newest.announced_s);
  if (secure && newest.authenticated_after_s < 0)
    return {State::kComingUp,
            "a server's participant discovered " + ago + ", its DDS Security handshake not passed"};
  if (secure)
    return {State::kComingUp,
            "a server's participant discovered " + ago + ", none of its status heard yet"};
  return {State::kUnheard, "a server's participant discovered " + ago +
                               ", none of its status heard (a secure swarm needs --secure)"};
}

ServerSearch DdsCommander::server_search() const {
  auto& I = *impl_;
  bool heard = false;
  {
    std::lock_guard<std::mutex> lock(I.mu);
    heard = I.sim.has_value();
  }
  std::vector<ServerPeer> servers;
  for (const auto& p : I.dds.peers_named(kServerParticipantName))
    servers.push_back({p.announced_s, p.authenticated_after_s});
  return ddswarm::gs::server_search(servers, I.dds.secure(), heard);
}

bool DdsCommander::wait_for_status(double timeout_s) {
  return impl_->wait(timeout_s, [&] { return impl_->sim.has_value(); });
}

bool DdsCommander::wait_sim_time(double t, double timeout_s) {
  return impl_->wait(timeout_s, [&] { return impl_->sim && impl_->sim->sim_time_s() >= t; });
}

bool DdsCommander::wait_airborne(int count, double timeout_s) {
  return impl_->wait(timeout_s, [&] { return impl_->sim && impl_->sim->airborne() == count; });
}

bool climb_over(const ClimbWord& w) {
  auto past = [](const std::optional<Phase>& p) {
    return p && *p != Phase::kTakeoff && *p != Phase::kIdle;
  };
  return past(w.heartbeat) || past(w.server);
}

bool DdsCommander::wait_takeoff_done(int count, double timeout_s) {
  return impl_->wait(timeout_s, [&] {
    if (!impl_->sim || impl_->sim->airborne() < count) return false;
    const auto& sim = *impl_->sim;
    for (int id : impl_->online_locked()) {
      ClimbWord w;
      auto it = impl_->agents.find(id);
      if (it != impl_->agents.end() && it->second.wall > impl_->last_command_wall)
        w.heartbeat = it->second.phase;
      // The server's word, also for an agent whose heartbeats never reach us.
      const auto k = static_cast<std::size_t>(id);
      if (impl_->accepted_by(id, impl_->last_seq) && k < sim.phase().size())
        w.server = static_cast<Phase>(sim.phase()[k]);
      if (!climb_over(w)) return false;
    }
    return true;
  });
}

CommandResult DdsCommander::takeoff(double altitude_m) {
  MissionCommand c;
  c.type = MissionType::kTakeoff;
  c.value = altitude_m;
  return impl_->send(c);
}

CommandResult DdsCommander::move(const Eigen::Vector3d& v, double duration_s) {
  MissionCommand c;
  c.type = MissionType::kMove;
  c.velocity = v;
  c.duration_s = duration_s;
  return impl_->send(c);
}

CommandResult DdsCommander::set_distance(double d) {
  MissionCommand c;
  c.type = MissionType::kSetDistance;
  c.value = d;
  return impl_->send(c);
}

CommandResult DdsCommander::land() {
  MissionCommand c;
  c.type = MissionType::kLand;
  return impl_->send(c);
}

CommandResult DdsCommander::follow_leader(int leader) {
  MissionCommand c;
  c.type = MissionType::kFollowLeader;
  c.leader_id = leader;
  return impl_->send(c);
}

CommandResult DdsCommander::teleop(const Eigen::Vector3d& v) {
  MissionCommand c;
  c.type = MissionType::kTeleop;
  c.velocity = v;
  return impl_->send(c);
}

CommandResult DdsCommander::hold_for(double duration_s) {
  MissionCommand c;
  c.type = MissionType::kHold;
  c.duration_s = duration_s;
  return impl_->send(c);
}

CommandResult DdsCommander::task(double speed, double eps) {
  MissionCommand c;
  c.type = MissionType::kTask;
  c.value = speed > 0 ? speed : TaskConfig{}.speed_mps;
  {
    std::lock_guard<std::mutex> lock(impl_->mu);
    c.epsilon_m = eps > 0 ? eps : default_epsilon(impl_->d_int_locked());
    impl_->outcome.reset();
  }
  return impl_->send(c);
}

bool DdsCommander::wait_agent_statuses(double timeout_s) {
  auto& I = *impl_;
  std::unique_lock<std::mutex> lock(I.mu);
  return I.cv.wait_for(lock, std::chrono::duration<double>(timeout_s), [&] {
    if (!I.dds.meets_agents()) return true;  // no heartbeat comes
    if (!I.sim) return false;
    for (auto id : I.sim->live_agents())
      if (!I.agents.count(id)) return false;
    return true;
  });
}

bool DdsCommander::wait_task_status(double timeout_s) {
  return impl_->wait_latched_task(timeout_s, 1.0, [&] { return impl_->task.has_value(); });
}

bool DdsCommander::attach_task(double timeout_s) {
  auto& I = *impl_;
  bool ok = I.wait_latched_task(timeout_s, timeout_s,
                                [&] { return I.task && I.task->phase() != msg::TASK_NONE; });
  std::lock_guard<std::mutex> lock(I.mu);
  if (!ok || !I.task) return false;
  I.task_seq = I.task->seq();
  return true;
}

std::string DdsCommander::wait_task(std::function<void(const std::string&)> on_progress) {
  auto& I = *impl_;
  std::unique_lock<std::mutex> lock(I.mu);
  const double start = wall_seconds();
  double last_progress = start;
  TaskOutcome o;
  const std::uint64_t server_instance = I.sim ? I.sim->server_instance() : 0;
  bool server_lost = false;
  while (true) {
    I.cv.wait_for(lock, std::chrono::milliseconds(200));
    double now = wall_seconds();
    const bool mine = I.task && I.task->seq() == I.task_seq;
    if (mine && (I.task->phase() == msg::TASK_COMPLETE || I.task->phase() == msg::TASK_FAILED)) {
      const auto& t = *I.task;
      for (auto id : t.lost_drones()) o.lost_drones.push_back(id);
      o.ok = t.phase() == msg::TASK_COMPLETE;
      o.reason = t.reason().to_string();
      o.task_time_s = t.elapsed_s();
      o.wall_time_s = t.wall_elapsed_s();
      o.epsilon_m = t.epsilon_m();
      o.speed_mps = t.speed_mps();
      o.drones = t.drones();
      o.collisions_obstacle = static_cast<int>(t.collisions_obstacle());
      o.collisions_drone = static_cast<int>(t.collisions_drone());
      o.collisions_ground = static_cast<int>(t.collisions_ground());
      o.min_inter_drone_m = t.min_inter_drone_m();
      o.min_clearance_m = t.min_clearance_m();
      o.metrics.order_mean = t.order_mean();
      o.metrics.order_min = t.order_min();
      o.metrics.speed_mean_mps = t.speed_mean_mps();
      o.metrics.near_misses = t.near_misses();
      o.metrics.components_max = t.components_max();
      o.metrics.lambda2_min = t.lambda2_min();
      o.metrics.range_m = t.metrics_range_m();
      o.metrics.near_miss_m = t.near_miss_m();
      o.seed = I.scene_seed;
      o.scenario = I.scene_name;
      break;
    }
    if (I.stopped()) {
      o.reason = "interrupted";
      break;
    }
    if (now - start > I.cfg.task_timeout_s) {
      o.reason = fmt::format("no result within {:.0f} s of wall time", I.cfg.task_timeout_s);
      break;
    }
    // The server: silent for a second is reported; a new instance (a
    // restart: a new world) ends the task; silent past server_timeout_s gives up.
    const double silent = now - I.sim_wall;
    if (silent > 1.0 && !server_lost) {
      server_lost = true;
      lock.unlock();
      if (on_progress)
        on_progress(
            fmt::format("server lost: no status for {:.1f} s; waiting up to {:.0f} s for it",
                        silent, I.cfg.server_timeout_s));
      lock.lock();
    }
    if (silent > I.cfg.server_timeout_s) {
      o.reason = fmt::format("server lost (no status for {:.0f} s)", I.cfg.server_timeout_s);
      break;
    }
    if (I.sim && I.sim->server_instance() != server_instance) {
      o.reason = fmt::format(
          "server restarted (instance {:016x}, was {:016x}): the task ended with the old world",
          I.sim->server_instance(), server_instance);
      break;
    }
    if (server_lost && silent <= 1.0) {
      server_lost = false;
      lock.unlock();
      if (on_progress) on_progress("server back");
      lock.lock();
    }
    if (on_progress && now - last_progress >= 2.0 && mine) {
      last_progress = now;
      std::string p =
          fmt::format("t={:.1f} s: {}/{} past finish, widest pair {:.1f} m (epsilon {:.1f} m)",
                      I.task->elapsed_s(), I.task->past_finish(), I.task->drones(),
                      I.task->max_pair_distance_m(), I.task->epsilon_m());
      lock.unlock();
      on_progress(p);
      lock.lock();
    }
  }
  I.outcome = o;
  return o.line();
}

SwarmStatus DdsCommander::status() {
  std::lock_guard<std::mutex> lock(impl_->mu);
  SwarmStatus s;
  s.drones_online = static_cast<int>(impl_->online_locked().size());
  s.d_int_m = impl_->d_int_locked();
  if (impl_->sim) {
    const auto& m = *impl_->sim;
    s.sim_time_s = m.sim_time_s();
    s.real_time_factor = m.real_time_factor();
    s.drones_total = m.num_drones();
    s.drones_server_hears = static_cast<int>(m.live_agents().size());
    s.airborne = m.airborne();
    s.collisions =
        static_cast<int>(m.collisions_obstacle() + m.collisions_drone() + m.collisions_ground());
    s.mode = (m.mode() == msg::MODE_LOCKSTEP ? "lockstep, " : "realtime, ") + m.state().to_string();
  } else {
    s.real_time_factor = std::nan("");
    s.mode = "no server";
  }
  if (impl_->sim) s.failsafe = impl_->sim->failsafe();
  if (impl_->task) {
    const auto& t = *impl_->task;
    if (t.phase() == msg::TASK_RUNNING)
      s.task = fmt::format("running {:.1f} s, {}/{} past finish", t.elapsed_s(), t.past_finish(),
                           t.drones());
    else if (t.phase() == msg::TASK_COMPLETE)
      s.task = fmt::format("complete in {:.2f} s", t.elapsed_s());
    else if (t.phase() == msg::TASK_FAILED)
      s.task = "failed: " + t.reason().to_string();
    if (t.phase() != msg::TASK_NONE && !t.lost_drones().empty())
      s.task += fmt::format(", lost drones {}", fmt::join(t.lost_drones(), " "));
  }
  if (impl_->sim) {
    const auto& m = *impl_->sim;
    s.commands_applied = static_cast<std::int64_t>(m.commands_applied());
    s.commands_late = static_cast<std::int64_t>(m.commands_late());
    s.lockstep_resends = static_cast<std::int64_t>(m.lockstep_resends());
    s.rejected = {
        {"non-finite", m.rejected_non_finite()},   {"absurd", m.rejected_absurd()},
        {"unknown id", m.rejected_unknown_id()},   {"stale tick", m.rejected_stale_tick()},
        {"future tick", m.rejected_future_tick()}, {"impostor", m.rejected_impostor()},
        {"mission", m.rejected_mission()},         {"malformed", m.rejected_malformed()}};
  }
  if (!impl_->agents.empty()) {
    std::uint64_t by_agents = 0;
    for (const auto& [id, a] : impl_->agents) by_agents += a.rejected;
    s.rejected.emplace_back("agents", by_agents);
  }
  std::map<std::string, int> laws;
  for (const auto& [id, a] : impl_->agents) {
    if (!a.law.empty()) laws[a.law]++;
    if (!a.law_fault.empty())
      s.law_faults.push_back(fmt::format("drone {} ({}): {}", id, a.law, a.law_fault));
  }
  for (const auto& [l, k] : laws)
    s.laws += fmt::format("{}{} {}", s.laws.empty() ? "" : ", ", k, l);
  std::map<Phase, int> phases;
  for (const auto& [id, a] : impl_->agents) phases[a.phase]++;
  for (const auto& [p, k] : phases)
    s.task_phase += fmt::format("{}{} {}", s.task_phase.empty() ? "" : ", ", k, to_string(p));
  return s;
}

std::optional<SwarmSnapshot> DdsCommander::swarm_snapshot(double timeout_s) {
  Impl& m = *impl_;
  m.ensure_state_reader();
  std::unique_lock<std::mutex> lock(m.mu);
  m.cv.wait_for(lock, std::chrono::duration<double>(timeout_s),
                [&] { return m.state.has_value(); });
  if (!m.state) return std::nullopt;
  return snapshot_of(*m.state);
}

bool DdsCommander::read_swarm_state(double timeout_s, std::int64_t after_tick,
                                    const std::function<void(const msg::SwarmState&)>& read) {
  Impl& m = *impl_;
  m.ensure_state_reader();
  const bool got = m.wait(timeout_s, [&] {
    return m.state && static_cast<std::int64_t>(m.state->tick()) > after_tick;
  });
  if (!got) return false;
  std::lock_guard<std::mutex> lock(m.mu);
  read(*m.state);
  return true;
}

void DdsCommander::set_interrupted(bool on) {
  impl_->interrupted = on;
  std::lock_guard<std::mutex> lock(impl_->mu);
  impl_->cv.notify_all();
}

std::optional<TaskOutcome> DdsCommander::last_task() const {
  std::lock_guard<std::mutex> lock(impl_->mu);
  return impl_->outcome;
}

}  // namespace ddswarm::gs
