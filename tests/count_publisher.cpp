// Publishes an exact, known sequence for recorder tests: N CollisionEvents
// (tick = i), N MissionAcks (seq = i) and N SwarmStates (tick = i), paced so
// no reliable sample is overwritten, after a recorder has matched.
#include <CLI/CLI.hpp>

#include <cstdio>

#include "common/participant.hpp"
#include "common/process.hpp"

using namespace ddswarm;

int main(int argc, char** argv) {
  return run_main("count_publisher", [&]() -> int {
    CLI::App app{"publish a known sequence"};
    DdsConfig dds;
    int n = 200;
    app.add_option("--domain", dds.domain_id);
    app.add_option("--count", n);
    CLI11_PARSE(app, argc, argv);
    install_stop_signals();
    Participant p(dds, "count_publisher");
    auto w_coll = p.writer<msg::CollisionEvent>();
    auto w_ack = p.writer<msg::MissionAck>();
    auto w_swarm = p.writer<msg::SwarmState>();
    for (int i = 0;
         i < 100 && (w_coll.matched() < 1 || w_ack.matched() < 1 || w_swarm.matched() < 1); ++i)
      wait_for_stop(std::chrono::milliseconds(100));
    if (w_coll.matched() < 1) throw std::runtime_error("no recorder matched");
    // Matching completes on the reader side a moment later; keep-last QoS could
    // otherwise overwrite the first samples before they are acknowledged.
    wait_for_stop(std::chrono::milliseconds(500));
    for (int i = 1; i <= n && !stop_requested(); ++i) {
      msg::CollisionEvent c;
      c.tick(static_cast<std::uint64_t>(i));
      c.drone_id(static_cast<std::uint16_t>(i % 7));
      w_coll.write(c);
      msg::MissionAck a;
      a.drone_id(static_cast<std::uint16_t>(i % 5));
      a.seq(static_cast<std::uint32_t>(i));
      w_ack.write(a);
      msg::SwarmState s;
      s.tick(static_cast<std::uint64_t>(i));
      s.sim_time_s(i * 0.02);
      w_swarm.write(s);
      wait_for_stop(std::chrono::milliseconds(5));
    }
    wait_for_stop(std::chrono::milliseconds(500));  // let the last reliable samples arrive
    std::printf("published %d of each\n", n);
    return 0;
  });
}
