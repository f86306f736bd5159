// A test helper for DDS Security (docs/security.md): joins the domain with
// some identity (or none) and tries to publish what that identity should not.
//
//   --publish velocity : velocity commands for --drone K, in --partition P
//                        (default: drone/K when secure). With --spoof, each
//                        carries the drone's live agent instance (learnt from
//                        its heartbeats) and the current tick: a plausible
//                        command only the sender's identity can give away.
//   --publish swarm_state : whole-swarm samples, as if it were the server.
//
// It publishes at 100 Hz for --for seconds (or, when the writer was refused,
// only listens) while counting what it hears, then prints one line:
//   probe: writer created|refused matched=M sent=N heard_state=S heard_status=T heard_heartbeats=H
// and exits 0, so the test asserts the outcome.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <mutex>
#include <optional>

#include "common/convert.hpp"
#include "common/participant.hpp"
#include "common/process.hpp"

using namespace ddswarm;

int main(int argc, char** argv) {
  return run_main("secure_probe", [&]() -> int {
    CLI::App app{"try to publish with a DDS Security identity (or none)"};
    DdsConfig dds;
    std::string what = "velocity";
    int drone = 0;
    std::optional<std::string> partition;
    bool spoof = false;
    double for_s = 3.0, east_mps = 2.0, wait_match_s = 0;
    add_dds_options(app, dds);
    app.add_option("--publish", what, "velocity | swarm_state")
        ->check(CLI::IsMember({"velocity", "swarm_state"}));
    app.add_option("--drone", drone, "velocity: the drone addressed");
    app.add_option("--partition", partition,
                   "velocity: the writer's partition (default: drone/K when secure)");
    app.add_flag("--spoof", spoof,
                 "velocity: carry the drone's live agent instance and the current tick");
    app.add_option("--east", east_mps, "velocity: m/s east in every command");
    app.add_option("--for", for_s, "wall seconds to publish and listen");
    app.add_option(
        "--wait-match", wait_match_s,
        "first wait up to this many wall seconds for a matched reader (with --spoof, also the "
        "drone's heartbeat; when refused, a swarm state), so a slow authentication does not "
        "shorten the attack");
    CLI11_PARSE(app, argc, argv);
    install_stop_signals();

    Participant p(dds, "secure_probe");
    std::mutex mu;
    std::uint64_t tick = 0, owner = 0;
    std::atomic<int> heard_state{0}, heard_status{0}, heard_heartbeats{0};
    p.reader<msg::SwarmState>([&](const msg::SwarmState& s, const fdds::SampleInfo&) {
      std::lock_guard<std::mutex> lock(mu);
      tick = std::max(tick, s.tick());
      ++heard_state;
    });
    p.reader<msg::SimStatus>(
        [&](const msg::SimStatus&, const fdds::SampleInfo&) { ++heard_status; });
    p.reader<msg::AgentStatus>([&](const msg::AgentStatus& a, const fdds::SampleInfo&) {
      std::lock_guard<std::mutex> lock(mu);
      if (a.drone_id() == drone) owner = a.agent_instance();
      ++heard_heartbeats;
    });

    std::optional<Writer<msg::VelocityCommand>> w_cmd;
    std::optional<Writer<msg::SwarmState>> w_state;
    bool refused = false;
    try {
      if (what == "velocity")
        w_cmd.emplace(p.writer<msg::VelocityCommand>(
            partition.value_or(dds.secure() ? drone_partition(drone) : "")));
      else
        w_state.emplace(p.writer<msg::SwarmState>());
    } catch (const DdsError& e) {
      std::fprintf(stderr, "probe: %s\n", e.what());
      refused = true;
    }
    const double w0 = wall_seconds();
    auto ready = [&] {
      std::lock_guard<std::mutex> lock(mu);
      if (refused) return heard_state > 0;  // nothing to match: wait until it hears the swarm
      const int m = w_cmd ? w_cmd->matched() : w_state->matched();
      return m > 0 && (!spoof || owner != 0);
    };
    while (!stop_requested() && wall_seconds() - w0 < wait_match_s && !ready())
      wait_for_stop(std::chrono::milliseconds(20));
    const double t0 = wall_seconds();
    int matched = 0;
    long sent = 0;
    while (!stop_requested() && wall_seconds() - t0 < for_s) {
      msg::VelocityCommand c;
      std::uint64_t k, inst;
      {
        std::lock_guard<std::mutex> lock(mu);
        k = tick;
        inst = owner;
      }
      if (w_cmd) {
        c.drone_id(static_cast<std::uint16_t>(drone));
        c.tick(spoof ? k : 0);
        c.sim_time_s(0.02 * static_cast<double>(k));
        c.velocity(to_msg(Eigen::Vector3d(east_mps, 0, 0)));
        c.motors_on(true);
        c.phase(2);
        c.agent_instance(spoof ? inst : 0xbadbadbadbad0003ULL);
        if (w_cmd->write(c)) ++sent;
        matched = std::max(matched, w_cmd->matched());
      } else if (w_state) {
        msg::SwarmState s;
        s.tick(k + 1);
        if (w_state->write(s)) ++sent;
        matched = std::max(matched, w_state->matched());
      }
      wait_for_stop(std::chrono::milliseconds(10));
    }
    std::printf(
        "probe: writer %s matched=%d sent=%ld heard_state=%d heard_status=%d heard_heartbeats=%d\n",
        refused ? "refused" : "created", matched, sent, heard_state.load(), heard_status.load(),
        heard_heartbeats.load());
    return 0;
  });
}
