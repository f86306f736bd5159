#include "sim_server/server_inbox.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

#include "common/convert.hpp"
#include "common/process.hpp"

namespace ddswarm::sim {
namespace {

std::int64_t system_now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

void log_online(int id, std::uint64_t agent) {
  spdlog::info("drone {}: agent {:016x} online", id, agent);
}

}  // namespace

ServerInbox::ServerInbox(const ServerConfig& c, std::uint64_t server_instance, Pipeline pipeline)
    : cfg(c),
      n(c.scenario.drones),
      instance(server_instance),
      agents(n, c.scenario.mode == TimeMode::kLockstep, pipeline),
      missions(server_instance) {
  counters.num_drones(static_cast<std::uint16_t>(n));
  counters.server_instance(instance);
  counters.mode(cfg.scenario.mode == TimeMode::kLockstep ? msg::MODE_LOCKSTEP : msg::MODE_REALTIME);
}

void ServerInbox::subscribe(Participant& dds) {
  // dds.best_effort_streams: the server need not acknowledge each command.
  // In real time a lost one is superseded one period later; in lockstep the
  // tick is published again after sim.lockstep_resend_s, and the agent
  // answers it again (run_lockstep).
  const Delivery commands = cfg.dds.best_effort_streams ? Delivery::kLatest : Delivery::kProfile;
  if (!dds.secure()) {
    dds.reader<msg::VelocityCommand>(
        [this](const msg::VelocityCommand& c, const fdds::SampleInfo&) { on_command(c); },
        std::nullopt, commands);
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
}

void ServerInbox::take_tick(std::vector<char>& live, std::vector<Phase>& phase,
                            std::vector<msg::Beacon>& beacons_out) {
  for (int i = 0; i < n; ++i) {
    live[i] = agents[i].live;
    phase[i] = agents[i].phase;
  }
  std::sort(beacons.begin(), beacons.end(),
            [](const msg::Beacon& a, const msg::Beacon& b) { return a.drone_id() < b.drone_id(); });
  beacons_out = std::move(beacons);
  beacons.clear();
}

bool ServerInbox::may_rejoin() {
  std::lock_guard<std::mutex> lock(mu);
  if (missions.begun()) {
    spdlog::warn("asked to join DDS again (SIGUSR1), but a mission has begun: staying");
    return false;
  }
  spdlog::warn(
      "asked to join DDS again (SIGUSR1, as ddswarm-launch sends when its discovery "
      "server dropped this participant); starting again as a new server");
  return true;
}

void ServerInbox::on_rival_scene(std::uint64_t other, std::int64_t other_published_ns) {
  std::lock_guard<std::mutex> lock(mu);
  const auto move = arbiter.on_scene(other_published_ns, system_now_ns(), missions.begun());
  if (move == RivalArbiter::Move::kLeave) return yield_to(other);
  if (move == RivalArbiter::Move::kStayAndSay)
    spdlog::error(
        "another server (instance {:016x}) is on DDS domain {}: two swarms on one domain "
        "are one swarm; it should leave (this one stays: {})",
        other, cfg.dds.domain_id, missions.begun() ? "its swarm has a mission" : "it joined first");
}

void ServerInbox::on_rival_status(const msg::SimStatus& s) {
  std::lock_guard<std::mutex> lock(mu);
  if (RivalArbiter::leaves_for_status(missions.begun(), s.mission_seq()))
    yield_to(s.server_instance());
}

void ServerInbox::yield_to(std::uint64_t other) {
  rival_instance = other;
  cv.notify_all();
}

void ServerInbox::on_command(const msg::VelocityCommand& c) {
  std::lock_guard<std::mutex> lock(mu);
  CommandFacts f{c.drone_id(), c.tick(), from_msg(c.velocity()), c.yaw_rate_rad_s(),
                 c.agent_instance()};
  switch (agents.check(f, cfg.sim.max_command_speed_mps)) {
    case Verdict::kAccept:
      break;
    case Verdict::kNonFinite:
      counters.rejected_non_finite(counters.rejected_non_finite() + 1);
      return;
    case Verdict::kAbsurd:
      counters.rejected_absurd(counters.rejected_absurd() + 1);
      return;
    case Verdict::kUnknownId:
      counters.rejected_unknown_id(counters.rejected_unknown_id() + 1);
      return;
    case Verdict::kImpostor:
      counters.rejected_impostor(counters.rejected_impostor() + 1);
      return;
    case Verdict::kStaleTick:
      counters.rejected_stale_tick(counters.rejected_stale_tick() + 1);
      return;
    case Verdict::kFutureTick:
      counters.rejected_future_tick(counters.rejected_future_tick() + 1);
      return;
    case Verdict::kRepeat:
      return;  // an answer already applied, to a tick published twice
  }
  const Phase phase =
      static_cast<Phase>(std::min<int>(c.phase(), static_cast<int>(Phase::kFailsafe)));
  const CommandRecord rec{{f.velocity, f.yaw_rate, c.motors_on()},
                          c.tick(),
                          phase,
                          c.mission_seq(),
                          c.mission_issuer(),
                          c.busy()};
  const auto r = agents.record(c.drone_id(), c.agent_instance(), rec, wall_seconds());
  if (r.online) log_online(c.drone_id(), c.agent_instance());
  if (r.status_due) status_due = true;
  if (c.has_beacon() && c.own_beacon().drone_id() == c.drone_id() &&
      std::isfinite(c.own_beacon().position().x()) &&
      std::isfinite(c.own_beacon().position().y()) &&
      std::isfinite(c.own_beacon().position().z())) {
    // One beacon per drone per tick: a repeated answer replaces, never duplicates.
    std::erase_if(beacons, [&](const msg::Beacon& b) { return b.drone_id() == c.drone_id(); });
    beacons.push_back(c.own_beacon());
  }
  if (r.late) counters.commands_late(counters.commands_late() + 1);
  // One wake-up per tick: the main thread needs to run only when the last
  // live agent has answered (it also wakes on its own every 20 ms).
  if (r.wake) cv.notify_all();
}

void ServerInbox::on_heartbeat(const msg::AgentStatus& a) {
  std::lock_guard<std::mutex> lock(mu);
  const auto heard = agents.heartbeat(a.drone_id(), a.agent_instance(), wall_seconds());
  if (heard == AgentRegistry::Heard::kUnknownId) {
    counters.rejected_unknown_id(counters.rejected_unknown_id() + 1);
    return;
  }
  if (heard == AgentRegistry::Heard::kImpostor) {
    counters.rejected_impostor(counters.rejected_impostor() + 1);
    return;
  }
  const bool new_agent = heard == AgentRegistry::Heard::kOnline;
  if (new_agent) {
    log_online(a.drone_id(), a.agent_instance());
    status_due = true;
  }
  if (std::isfinite(a.inter_distance_m()) && a.inter_distance_m() > 0)
    agent_d_int = std::max(agent_d_int, a.inter_distance_m());
  // Only a new agent changes what the main loop waits for (and its status
  // goes out at once). Waking it for every heartbeat, 4 a second from each
  // agent, woke it 0.7 extra times per tick at 64 drones in lockstep.
  if (new_agent) cv.notify_all();
}

void ServerInbox::on_mission(const msg::MissionCommand& m) {
  std::lock_guard<std::mutex> lock(mu);
  std::string problem;
  switch (missions.take(m, problem)) {
    case MissionRelay::Intake::kMalformed:
      counters.rejected_mission(counters.rejected_mission() + 1);
      spdlog::warn("mission command seq {} rejected: {}", m.seq(), problem);
      return;
    case MissionRelay::Intake::kStale:
      counters.rejected_stale_mission(counters.rejected_stale_mission() + 1);
      spdlog::warn("mission command seq {} from {} was for server {:016x}, not this one: ignored",
                   m.seq(), m.issuer().to_string(), m.server_instance());
      return;
    case MissionRelay::Intake::kRepeat:
      spdlog::info("mission seq {} repeated: forwarding again for acknowledgement", m.seq());
      break;
    case MissionRelay::Intake::kNew:
      break;
  }
  cv.notify_all();
}

void ServerInbox::expire_agents(double now_wall_s) {
  const auto e = agents.expire(now_wall_s, cfg.sim.agent_timeout_s);
  if (e.silence_began)
    spdlog::warn(
        "no agent heard for {:.1f} s: waiting up to {:.1f} s before declaring any lost "
        "(the silence may be this server's)",
        e.newest_silence_s, e.limit_s);
  if (e.holding_began)
    spdlog::warn(
        "{} agents silent past {:.1f} s at once: waiting up to {:.1f} s more before declaring "
        "any lost (their writes may be stalled on this server's port)",
        e.past_limit, e.limit_s, kPortLockTimeoutS);
  for (const auto& [i, silent_s] : e.lost) {
    status_due = true;
    counters.lockstep_timeouts(counters.lockstep_timeouts() + 1);
    spdlog::warn("drone {}: agent lost (silent for {:.1f} s); drone enters failsafe", i, silent_s);
  }
}

}  // namespace ddswarm::sim
