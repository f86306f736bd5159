// An agent ignores swarm samples that do not come from its server
// (forged by another participant: NaN positions, a tick far in the future),
// counts them, and keeps flying on the real ones. With --copy-scene the forger
// first republishes the server's own scene, and then plausible states: the
// agent must still take its states from the server alone. With --bad-scene it
// first publishes a scene of its own that cannot be flown (no volume between
// its bounds): the agent refuses it, counts it, and flies on. Exit 0 when it did
// (forged samples counted, the height held, the server never lost the agent).
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <limits>
#include <mutex>
#include <optional>

#include "common/convert.hpp"
#include "common/participant.hpp"
#include "common/process.hpp"

using namespace ddswarm;

int main(int argc, char** argv) {
  return run_main("forged_swarm_state", [&]() -> int {
    CLI::App app{"forge SwarmState samples at a running agent"};
    DdsConfig dds;
    double attack_s = 3.0, z = 2.0, tolerance = 0.15;
    bool copy_scene = false, bad_scene = false;
    app.add_option("--domain", dds.domain_id);
    app.add_option("--attack", attack_s, "wall seconds of forged samples");
    app.add_option("--z", z, "m, the altitude drone 0 holds");
    app.add_flag("--copy-scene", copy_scene,
                 "republish the server's scene first, then plausible states");
    app.add_flag("--bad-scene", bad_scene,
                 "publish a scene of another instance that cannot be flown first, then plausible "
                 "states");
    CLI11_PARSE(app, argc, argv);
    const bool plausible = copy_scene || bad_scene;  // the states that follow a scene
    install_stop_signals();
    dds = one_shot(dds);  // a few seconds' attack: kOneShotLeaseS says why
    Participant p(dds, "forger");
    auto w = p.writer<msg::SwarmState>();
    std::mutex mu;
    std::uint64_t rejected_before = 0, rejected_now = 0, real_tick = 0;
    bool have_status = false;
    double max_dz = 0;
    bool watching = false;
    int lost_ticks =
        0;  // real states, while watching, whose drone 0 the server flew without its agent
    std::optional<msg::Scene> real_scene;
    p.reader<msg::Scene>([&](const msg::Scene& s, const fdds::SampleInfo&) {
      std::lock_guard<std::mutex> lock(mu);
      if (!real_scene) real_scene = s;
    });
    p.reader<msg::AgentStatus>([&](const msg::AgentStatus& a, const fdds::SampleInfo&) {
      std::lock_guard<std::mutex> lock(mu);
      if (a.drone_id() != 0) return;
      rejected_now = a.rejected_samples();
      if (!have_status) rejected_before = rejected_now;
      have_status = true;
    });
    p.reader<msg::SwarmState>([&](const msg::SwarmState& s, const fdds::SampleInfo& info) {
      if (info.sample_identity.writer_guid().guidPrefix == w.raw()->guid().guidPrefix) return;
      std::lock_guard<std::mutex> lock(mu);
      real_tick = s.tick();
      if (watching && !s.drones().empty()) {
        const auto& d = s.drones()[0];
        max_dz = std::max(max_dz, std::abs(d.position().z() - z));
        if (!(d.flags() & msg::DRONE_AGENT_LIVE) || (d.flags() & msg::DRONE_FAILSAFE)) ++lost_ticks;
      }
    });
    const auto heard = [&] {
      std::lock_guard<std::mutex> lock(mu);
      return have_status && (!plausible || real_scene);  // the scene may come after a heartbeat
    };
    for (int i = 0; i < 50 && !heard(); ++i) wait_for_stop(std::chrono::milliseconds(100));
    {
      std::lock_guard<std::mutex> lock(mu);
      if (!have_status) throw std::runtime_error("no heartbeat from agent 0");
      if (plausible && !real_scene) throw std::runtime_error("no scene from the server");
      rejected_before = rejected_now;
      watching = true;
    }
    std::optional<Writer<msg::Scene>> scenes;
    if (plausible) {
      scenes.emplace(p.writer<msg::Scene>());
      std::lock_guard<std::mutex> lock(mu);
      msg::Scene s = *real_scene;
      if (bad_scene) {
        s.server_instance(random_instance());
        s.bounds_max(s.bounds_min());
      }
      scenes->write(s);
    }
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double end = wall_seconds() + attack_s;
    int sent = 0;
    while (wall_seconds() < end && !stop_requested()) {
      msg::SwarmState f;
      {
        std::lock_guard<std::mutex> lock(mu);
        f.tick(sent % 2 && !plausible ? real_tick + 1000000 : real_tick + 1);
        f.sim_time_s(plausible ? static_cast<double>(real_tick + 1) * 0.02 : 1e6);
      }
      f.drones().resize(1);
      f.drones()[0].drone_id(0);
      f.drones()[0].flags(msg::DRONE_AGENT_LIVE | msg::DRONE_AIRBORNE);
      // Odd samples: NaN position; even: a plausible state 50 m away. After a
      // copied scene, every one is plausible: 1 m below the height held.
      f.drones()[0].position(to_msg(plausible  ? Eigen::Vector3d(0, 0, z - 1)
                                    : sent % 2 ? Eigen::Vector3d(nan, nan, nan)
                                               : Eigen::Vector3d(50, 0, 2)));
      w.write(f);
      ++sent;
      wait_for_stop(std::chrono::milliseconds(20));
    }
    wait_for_stop(std::chrono::milliseconds(800));  // one more heartbeat
    std::lock_guard<std::mutex> lock(mu);
    std::printf(
        "forged %d samples%s; agent 0 rejected %llu; drone 0 height error at most %.3f m; "
        "%d states without its agent\n",
        sent,
        copy_scene  ? " after a copy of the scene"
        : bad_scene ? " after a scene that cannot be flown"
                    : "",
        static_cast<unsigned long long>(rejected_now - rejected_before), max_dz, lost_ticks);
    if (rejected_now - rejected_before < static_cast<std::uint64_t>(sent) / 2) return 1;
    return max_dz <= tolerance && lost_ticks == 0 ? 0 : 1;
  });
}
