// A test helper that attacks a running server over plain DDS while a
// legitimate agent (tests/scripted_commander) hovers drone --id at --z.
//
// It waits until the drone hovers, learns the legitimate agent's instance
// from its heartbeats, then for --attack wall seconds publishes, every tick:
// velocity commands with NaN and inf, an absurd speed, an unknown drone id,
// a stale tick, a future tick, an impostor's plausible command; and mission
// commands of an unknown type and with a NaN velocity. Every spoofed command
// carries a velocity that would visibly move the drone if it were applied.
//
// Exit 0 when every matching SimStatus rejected_* counter grew, no hostile
// mission was forwarded, and the drone kept hovering (height within the
// tolerance, no horizontal drift, no absurd speed, no failsafe, its agent live).
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdio>
#include <limits>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "common/convert.hpp"
#include "common/participant.hpp"
#include "common/process.hpp"

using namespace ddswarm;

namespace {

constexpr std::uint64_t kImpostor = 0xbadbadbadbad0001ULL;
constexpr std::uint64_t kIssuer = 0xbadbadbadbad0002ULL;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

bool finite(const msg::Vec3& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

/// What the attacker sees of the drone while it watches (guarded by a mutex).
struct Watch {
  std::uint64_t tick = 0;
  bool have_state = false;
  Eigen::Vector3d p_world{0, 0, 0};
  bool agent_live = false;
  double stable_since_wall = -1;  // wall time since the drone is within tolerance/2 of the target
  // Recorded only while `observing`:
  bool observing = false;
  Eigen::Vector3d p_start{0, 0, 0};
  double max_dz = 0, max_drift_xy = 0, max_speed = 0;
  float max_command_age_s = 0;
  int samples = 0, failsafe_samples = 0, not_live_samples = 0, non_finite_samples = 0;
  bool hostile_mission_forwarded = false;
  std::uint64_t owner = 0;  // the legitimate agent's instance, from its heartbeats
  std::optional<msg::SimStatus> status;
};

msg::VelocityCommand command(int id, std::uint64_t tick, const Eigen::Vector3d& v,
                             std::uint64_t instance) {
  msg::VelocityCommand c;
  c.drone_id(static_cast<std::uint16_t>(id));
  c.tick(tick);
  c.sim_time_s(0.02 * static_cast<double>(tick));
  c.velocity(to_msg(v));
  c.motors_on(true);
  c.phase(2);
  c.agent_instance(instance);
  return c;
}

void print_counters(const char* label, const msg::SimStatus& s) {
  std::printf(
      "%s: tick %llu non_finite %u absurd %u unknown_id %u stale_tick %u future_tick %u "
      "impostor %u mission %u commands_applied %llu commands_late %llu agents_live %u failsafe "
      "%u\n",
      label, static_cast<unsigned long long>(s.tick()), s.rejected_non_finite(),
      s.rejected_absurd(), s.rejected_unknown_id(), s.rejected_stale_tick(),
      s.rejected_future_tick(), s.rejected_impostor(), s.rejected_mission(),
      static_cast<unsigned long long>(s.commands_applied()),
      static_cast<unsigned long long>(s.commands_late()), s.agents_live(), s.failsafe());
}

}  // namespace

int main(int argc, char** argv) {
  return run_main("hostile_publisher", [&]() -> int {
    CLI::App app{"attack a running ddswarm-sim with malformed and spoofed samples"};
    DdsConfig dds;
    int id = 0;
    double target_z = 2.0, tolerance = 0.1, attack_s = 3.0, timeout_s = 40, max_speed = 0.5;
    app.add_option("--domain", dds.domain_id);
    app.add_option("--id", id, "the legitimately flown drone to attack");
    app.add_option("--z", target_z, "m, the altitude the legitimate agent holds");
    app.add_option("--tolerance", tolerance, "m, allowed height error and horizontal drift");
    app.add_option("--max-speed", max_speed, "m/s, fastest the hovering drone may move");
    app.add_option("--attack", attack_s, "wall seconds of hostile traffic");
    app.add_option("--timeout", timeout_s, "wall seconds to wait for the drone to hover");
    CLI11_PARSE(app, argc, argv);
    install_stop_signals();

    dds = one_shot(dds);  // a few seconds' attack: kOneShotLeaseS says why
    Participant p(dds, "hostile_publisher");
    auto w_cmd = p.writer<msg::VelocityCommand>();
    auto w_hb = p.writer<msg::AgentStatus>();
    auto w_mission = p.writer<msg::MissionCommand>();
    std::mutex mu;
    Watch w;

    p.reader<msg::AgentStatus>([&](const msg::AgentStatus& a, const fdds::SampleInfo&) {
      std::lock_guard<std::mutex> lock(mu);
      if (a.drone_id() == id && a.agent_instance() != kImpostor && !w.owner)
        w.owner = a.agent_instance();
    });
    p.reader<msg::SimStatus>([&](const msg::SimStatus& s, const fdds::SampleInfo&) {
      std::lock_guard<std::mutex> lock(mu);
      w.status = s;
    });
    p.reader<msg::SwarmState>([&](const msg::SwarmState& s, const fdds::SampleInfo&) {
      std::lock_guard<std::mutex> lock(mu);
      w.tick = std::max(w.tick, s.tick());
      for (const auto& m : s.recent_commands())
        if (m.issuer_instance() == kIssuer) w.hostile_mission_forwarded = true;
      if (s.drones().size() <= static_cast<std::size_t>(id)) return;
      const auto& d = s.drones()[id];
      const bool ok = finite(d.position()) && finite(d.velocity());
      Eigen::Vector3d pos = from_msg(d.position());
      w.have_state = true;
      w.p_world = pos;
      w.agent_live = d.flags() & msg::DRONE_AGENT_LIVE;
      if (ok && std::abs(pos.z() - target_z) < tolerance / 2) {
        if (w.stable_since_wall < 0) w.stable_since_wall = wall_seconds();
      } else {
        w.stable_since_wall = -1;
      }
      if (!w.observing) return;
      ++w.samples;
      if (!ok) {
        ++w.non_finite_samples;
        return;
      }
      w.max_dz = std::max(w.max_dz, std::abs(pos.z() - target_z));
      w.max_drift_xy = std::max(w.max_drift_xy, (pos - w.p_start).head<2>().norm());
      w.max_speed = std::max(w.max_speed, from_msg(d.velocity()).norm());
      w.max_command_age_s = std::max(w.max_command_age_s, d.command_age_s());
      if (d.flags() & msg::DRONE_FAILSAFE) ++w.failsafe_samples;
      if (!(d.flags() & msg::DRONE_AGENT_LIVE)) ++w.not_live_samples;
    });

    // 1. Wait for a legitimate agent hovering the drone, and for our writers to match the server.
    const double t0 = wall_seconds();
    for (;;) {
      {
        std::lock_guard<std::mutex> lock(mu);
        if (w.owner && w.agent_live && w.status && w.stable_since_wall >= 0 &&
            wall_seconds() - w.stable_since_wall > 1.0 && w_cmd.matched() > 0 &&
            w_mission.matched() > 0)
          break;
        if (stop_requested() || wall_seconds() - t0 > timeout_s) {
          std::printf(
              "FAIL: drone %d never hovered at %.2f m under a live agent within %.0f s "
              "(owner %016llx, live %d, z %.3f, status %d, writers matched %d/%d)\n",
              id, target_z, timeout_s, static_cast<unsigned long long>(w.owner), w.agent_live,
              w.p_world.z(), w.status.has_value(), w_cmd.matched(), w_mission.matched());
          return 1;
        }
      }
      wait_for_stop(std::chrono::milliseconds(20));
    }
    msg::SimStatus before;
    std::uint64_t owner;
    {
      std::lock_guard<std::mutex> lock(mu);
      before = *w.status;
      owner = w.owner;
      w.observing = true;
      w.p_start = w.p_world;
    }
    std::printf("legitimate agent %016llx hovers drone %d at z=%.3f; attacking for %.1f s\n",
                static_cast<unsigned long long>(owner), id, w.p_start.z(), attack_s);
    print_counters("before", before);

    // 2. Attack: one round per control tick (50 Hz).
    std::uint32_t seq = 1;
    int rounds = 0;
    const double attack_start = wall_seconds();
    double last_slow = -1;
    while (!stop_requested() && wall_seconds() - attack_start < attack_s) {
      std::uint64_t tick;
      {
        std::lock_guard<std::mutex> lock(mu);
        tick = w.tick;
      }
      const Eigen::Vector3d down(0, 0, -2.0), east(2.0, 0, 0);
      // Spoofed with the owner's own instance: only the content can give them away.
      w_cmd.write(command(id, tick, {kNaN, 0, 0}, owner));
      auto inf = command(id, tick, {0, 0, kInf}, owner);
      w_cmd.write(inf);
      auto spin = command(id, tick, {0, 0, 0}, owner);
      spin.yaw_rate_rad_s(-kInf);
      w_cmd.write(spin);
      w_cmd.write(command(id, tick, {1e6, 0, 0}, owner));
      w_cmd.write(command(999, tick, down, owner));
      w_cmd.write(command(id, 0, down, owner));
      w_cmd.write(command(id, tick + 1000, down, owner));
      // An impostor: well-formed, current, plausible; only its instance differs.
      w_cmd.write(command(id, tick, east, kImpostor));
      if (wall_seconds() - last_slow > 0.2) {
        last_slow = wall_seconds();
        msg::AgentStatus hb;
        hb.drone_id(static_cast<std::uint16_t>(id));
        hb.agent_instance(kImpostor);
        hb.host("impostor");
        w_hb.write(hb);
        msg::MissionCommand m;
        m.seq(seq++);
        m.type(42);
        m.target(-1);
        m.issuer("hostile");
        m.issuer_instance(kIssuer);
        w_mission.write(m);
        m.seq(seq++);
        m.type(static_cast<std::uint8_t>(MissionType::kMove));
        m.velocity(to_msg(Eigen::Vector3d(kNaN, 1.0, 0)));
        m.duration_s(5.0);
        w_mission.write(m);
      }
      ++rounds;
      wait_for_stop(std::chrono::milliseconds(20));
    }

    // 3. Keep watching: an applied hostile command would show within a tick or two.
    std::uint64_t end_tick;
    {
      std::lock_guard<std::mutex> lock(mu);
      end_tick = w.tick;
    }
    wait_for_stop(std::chrono::milliseconds(1000));
    std::optional<msg::SimStatus> after;
    for (double t = wall_seconds(); wall_seconds() - t < 3.0;
         wait_for_stop(std::chrono::milliseconds(50))) {
      std::lock_guard<std::mutex> lock(mu);
      if (w.status && w.status->tick() > end_tick) {
        after = w.status;
        break;
      }
    }
    std::lock_guard<std::mutex> lock(mu);
    w.observing = false;
    std::printf("%d attack rounds (%d velocity commands, %u mission commands)\n", rounds,
                rounds * 8, seq - 1);
    if (!after) {
      std::printf("FAIL: no SimStatus after the attack\n");
      return 1;
    }
    print_counters("after", *after);
    std::printf(
        "drone %d over %d samples: max |z-%.2f| %.4f m, max horizontal drift %.4f m, "
        "max speed %.4f m/s, max command age %.3f s, failsafe samples %d, "
        "agent-not-live samples %d, non-finite samples %d\n",
        id, w.samples, target_z, w.max_dz, w.max_drift_xy, w.max_speed, w.max_command_age_s,
        w.failsafe_samples, w.not_live_samples, w.non_finite_samples);

    std::vector<std::string> failures;
    // The legitimate agent alone must never trip the gate.
    if (before.rejected_non_finite() + before.rejected_absurd() + before.rejected_unknown_id() +
            before.rejected_stale_tick() + before.rejected_future_tick() +
            before.rejected_impostor() + before.rejected_mission() >
        0)
      failures.push_back("the legitimate agent's own samples were rejected before the attack");
    auto grew = [&](const char* name, std::uint64_t b, std::uint64_t a) {
      if (a <= b)
        failures.push_back(fmt::format("rejected_{} did not grow ({} -> {})", name, b, a));
    };
    grew("non_finite", before.rejected_non_finite(), after->rejected_non_finite());
    grew("absurd", before.rejected_absurd(), after->rejected_absurd());
    grew("unknown_id", before.rejected_unknown_id(), after->rejected_unknown_id());
    grew("stale_tick", before.rejected_stale_tick(), after->rejected_stale_tick());
    grew("future_tick", before.rejected_future_tick(), after->rejected_future_tick());
    grew("impostor", before.rejected_impostor(), after->rejected_impostor());
    grew("mission", before.rejected_mission(), after->rejected_mission());
    if (after->commands_applied() <= before.commands_applied())
      failures.push_back("the legitimate agent's commands stopped being applied");
    if (w.samples < 10) failures.push_back(fmt::format("only {} drone samples watched", w.samples));
    if (w.non_finite_samples) failures.push_back("the drone's state became non-finite");
    if (w.max_dz > tolerance)
      failures.push_back(fmt::format("height left {:.2f} +- {:.2f} m (max error {:.3f} m)",
                                     target_z, tolerance, w.max_dz));
    if (w.max_drift_xy > tolerance)
      failures.push_back(fmt::format("drifted {:.3f} m sideways", w.max_drift_xy));
    if (w.max_speed > max_speed)
      failures.push_back(fmt::format("moved at {:.3f} m/s (limit {:.2f})", w.max_speed, max_speed));
    if (w.failsafe_samples)
      failures.push_back(
          fmt::format("drone in failsafe for {} samples: legitimate commands were starved",
                      w.failsafe_samples));
    if (w.not_live_samples)
      failures.push_back(
          fmt::format("legitimate agent not live for {} samples", w.not_live_samples));
    if (w.hostile_mission_forwarded)
      failures.push_back("a hostile mission command was forwarded to agents");
    for (const auto& f : failures) std::printf("FAIL: %s\n", f.c_str());
    return failures.empty() ? 0 : 1;
  });
}
