// A test helper that talks plain DDS, no agent code: it flies drone 0 to a
// target with a proportional velocity law and reports how well it hovers.
// Exit 0 when the drone held the target within the tolerance.
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <mutex>

#include "common/convert.hpp"
#include "common/participant.hpp"
#include "common/process.hpp"

using namespace ddswarm;

int main(int argc, char** argv) {
  return run_main("scripted_commander", [&]() -> int {
    CLI::App app{"fly drone 0 to a point and hover"};
    DdsConfig dds;
    double target_z = 2.0, hold_s = 5.0, tolerance = 0.1, timeout_s = 60;
    int id = 0;
    app.add_option("--domain", dds.domain_id);
    app.add_option("--id", id);
    app.add_option("--z", target_z, "target altitude (m)");
    app.add_option("--hold", hold_s, "sim seconds to hover after reaching the target");
    app.add_option("--tolerance", tolerance, "m");
    app.add_option("--timeout", timeout_s, "wall seconds");
    CLI11_PARSE(app, argc, argv);
    install_stop_signals();
    Participant p(dds, "scripted_commander");
    auto w_cmd = p.writer<msg::VelocityCommand>();
    auto w_hb = p.writer<msg::AgentStatus>();
    const std::uint64_t instance = 0x5c1e7ed0000 + id;
    std::mutex mu;
    Eigen::Vector3d target(0, 0, target_z);
    bool have_target = false;
    double reached_t = -1, max_dev = 0, last_t = 0;
    Eigen::Vector3d last_p(0, 0, 0);
    std::atomic<bool> done{false};
    p.reader<msg::SwarmState>([&](const msg::SwarmState& s, const fdds::SampleInfo&) {
      if (s.drones().size() <= static_cast<std::size_t>(id)) return;
      std::lock_guard<std::mutex> lock(mu);
      const auto& d = s.drones()[id];
      Eigen::Vector3d pos = from_msg(d.position());
      if (!have_target) {
        target.x() = pos.x();
        target.y() = pos.y();
        have_target = true;
      }
      last_t = s.sim_time_s();
      last_p = pos;
      Eigen::Vector3d err = target - pos;
      if (reached_t < 0 && err.norm() < tolerance) reached_t = s.sim_time_s();
      if (reached_t >= 0) max_dev = std::max(max_dev, err.norm());
      bool finished = reached_t >= 0 && s.sim_time_s() - reached_t >= hold_s;
      Eigen::Vector3d v = 1.2 * err;
      if (v.norm() > 1.0) v *= 1.0 / v.norm();
      msg::VelocityCommand c;
      c.drone_id(static_cast<std::uint16_t>(id));
      c.tick(s.tick());
      c.sim_time_s(s.sim_time_s());
      c.velocity(to_msg(v));
      c.motors_on(true);
      c.phase(2);
      c.busy(!finished);
      c.agent_instance(instance);
      w_cmd.write(c);
      if (finished) done = true;
    });
    const double start = wall_seconds();
    while (!done && !stop_requested() && wall_seconds() - start < timeout_s) {
      msg::AgentStatus hb;
      hb.drone_id(static_cast<std::uint16_t>(id));
      hb.agent_instance(instance);
      hb.host("test");
      w_hb.write(hb);
      wait_for_stop(std::chrono::milliseconds(200));
    }
    std::lock_guard<std::mutex> lock(mu);
    // %a prints the exact bits, so reruns can be compared for identity.
    std::printf("final t=%.3f pos=(%a, %a, %a)\n", last_t, last_p.x(), last_p.y(), last_p.z());
    std::printf("reached=%.3f max_deviation_after_reaching=%.4f m\n", reached_t, max_dev);
    if (!done) {
      std::printf("did not settle within %.0f s wall\n", timeout_s);
      return 1;
    }
    return max_dev <= tolerance ? 0 : 1;
  });
}
