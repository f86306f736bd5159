// swarm_probe: reads a running ddswarm swarm's figures for bench/swarm_bench.sh.
//
// Waits until every drone is airborne, lets the swarm settle, then measures
// over a fixed wall time: ticks/s and real-time factor (from the server's own
// SimStatus tick and wall clock), the CPU time of every process under the
// launcher by kind (/proc/<pid>/stat), agents' RSS and PSS, and with --ages
// (real time) the age of the command each drone flies (DroneState.command_age_s
// in every SwarmState) and how many commands were never applied.
// Prints one line of key=value pairs.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <mutex>
#include <thread>

#include "bench/bench_util.hpp"
#include "common/participant.hpp"
#include "common/process.hpp"

using namespace ddswarm;
using namespace ddswarm::bench;

namespace {

struct AgeStats {
  std::vector<long> hist = std::vector<long>(64, 0);  // command age in control periods
  long drone_ticks = 0;                               // drone-ticks measured
  long missed = 0;                                    // commands never applied
  long samples = 0, probe_gaps = 0;
  std::uint64_t last_tick = 0;
  std::vector<std::int64_t> last_applied;  // per drone, -1 = unknown
  // Per drone: are the misses a few drones' or everyone's?
  std::vector<long> missed_by_drone;
  // Misses seen in a sample where half the swarm or more missed at once.
  long missed_in_stalls = 0;
};

// "drones with a miss, and the share of all misses that the worst tenth of
// the drones hold": a few starved or late-joined processes, or the whole swarm.
std::string miss_spread(const std::vector<long>& by_drone) {
  std::vector<long> v(by_drone);
  std::sort(v.rbegin(), v.rend());
  long total = 0, top = 0;
  int with = 0;
  for (std::size_t i = 0; i < v.size(); ++i) {
    total += v[i];
    if (v[i] > 0) ++with;
    if (i < std::max<std::size_t>(1, v.size() / 10)) top += v[i];
  }
  return fmt::format("missed_drones={} missed_top_tenth_share={:.3f}", with,
                     total ? static_cast<double>(top) / total : 0.0);
}

double percentile(const std::vector<long>& hist, double q) {
  long total = 0;
  for (long h : hist) total += h;
  if (total == 0) return NAN;
  long want = static_cast<long>(std::ceil(q * total)), seen = 0;
  for (std::size_t k = 0; k < hist.size(); ++k) {
    seen += hist[k];
    if (seen >= want) return static_cast<double>(k);
  }
  return static_cast<double>(hist.size() - 1);
}

}  // namespace

int main(int argc, char** argv) {
  return run_main("swarm_probe", [&]() -> int {
    CLI::App app{"swarm_probe: measure a running ddswarm swarm (bench/swarm_bench.sh)"};
    int drones = 6;
    pid_t launcher = 0;
    double settle_s = 2, time_s = 10, timeout_s = 300;
    bool ages = false;
    DdsConfig dds;
    app.add_option("--drones", drones, "drones that must be airborne before measuring")->required();
    app.add_option("--launcher-pid", launcher,
                   "CPU and memory of this process and its descendants");
    app.add_option("--settle", settle_s, "s of wall time after all are airborne, before measuring");
    app.add_option("--time", time_s, "s of wall time measured");
    app.add_option("--timeout", timeout_s, "s to wait for the swarm to be airborne");
    app.add_flag("--ages", ages, "also read every SwarmState: command ages and missed commands");
    add_dds_options(app, dds);
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
      return app.exit(e) == 0 ? 0 : 2;
    }
    install_stop_signals();
    std::mutex mu;
    msg::SimStatus status;
    bool have_status = false;
    double control_rate_hz = 0;
    AgeStats ag;
    ag.last_applied.assign(drones, -1);
    ag.missed_by_drone.assign(drones, 0);
    std::atomic<bool> measuring{false};
    // A participant with its readers; made again while no server is heard
    // through a discovery server, as the ground station does (a probe that
    // joined a loaded 128-process swarm last once heard nothing for 240 s).
    std::unique_ptr<Participant> participant;
    auto join = [&] {
      participant.reset();
      participant = std::make_unique<Participant>(dds, "swarm_probe");
      Participant& p = *participant;
      p.reader<msg::Scene>([&](const msg::Scene& s, const fdds::SampleInfo&) {
        std::lock_guard<std::mutex> lock(mu);
        control_rate_hz = s.control_rate_hz();
      });
      p.reader<msg::SimStatus>([&](const msg::SimStatus& s, const fdds::SampleInfo&) {
        std::lock_guard<std::mutex> lock(mu);
        status = s;
        have_status = true;
      });
      if (!ages) return;
      p.reader<msg::SwarmState>([&](const msg::SwarmState& s, const fdds::SampleInfo&) {
        if (!measuring) return;
        std::lock_guard<std::mutex> lock(mu);
        if (control_rate_hz <= 0) return;
        const double period = 1.0 / control_rate_hz;
        const bool consecutive = ag.samples > 0 && s.tick() == ag.last_tick + 1;
        if (ag.samples > 0 && s.tick() > ag.last_tick + 1)
          ag.probe_gaps += s.tick() - ag.last_tick - 1;
        ++ag.samples;
        ag.last_tick = s.tick();
        long tick_missed = 0;
        int tick_drones = 0, tick_missing = 0;
        for (const auto& d : s.drones()) {
          const int i = d.drone_id();
          if (i >= drones) continue;
          const std::uint16_t want = msg::DRONE_AGENT_LIVE | msg::DRONE_AIRBORNE;
          if ((d.flags() & want) != want || (d.flags() & msg::DRONE_FAILSAFE)) {
            ag.last_applied[i] = -1;
            continue;
          }
          // The command applied on the step that produced tick k answered tick
          // k-1-age; from state published to command applied: age+1 periods.
          const long age = std::lround(d.command_age_s() / period);
          ++ag.hist[std::min<long>(age + 1, 63)];
          ++ag.drone_ticks;
          ++tick_drones;
          const std::int64_t applied = static_cast<std::int64_t>(s.tick()) - 1 - age;
          if (consecutive && ag.last_applied[i] >= 0 && applied > ag.last_applied[i] + 1) {
            ag.missed += applied - ag.last_applied[i] - 1;
            ag.missed_by_drone[i] += applied - ag.last_applied[i] - 1;
            tick_missed += applied - ag.last_applied[i] - 1;
            ++tick_missing;
          }
          if (!consecutive) ag.last_applied[i] = -1;
          ag.last_applied[i] = std::max(ag.last_applied[i], applied);
        }
        // A machine-wide stall (the kernel, another process) makes most of
        // the swarm late at once; a starved agent misses alone.
        if (tick_drones > 0 && 2 * tick_missing >= tick_drones) ag.missed_in_stalls += tick_missed;
      });
    };
    join();
    auto snapshot = [&] {
      std::lock_guard<std::mutex> lock(mu);
      return std::make_pair(have_status, status);
    };
    // 1. Every drone airborne.
    const double t0 = wall_seconds();
    const bool via_discovery_server = dds.discovery == Discovery::kDiscoveryServer;
    double joined = t0;
    int joins = 0;
    while (!stop_requested()) {
      auto [ok, s] = snapshot();
      if (ok && s.airborne() >= drones) break;
      const double waited = wall_seconds() - joined;
      if (!ok && via_discovery_server && waited > rejoin_patience_s(kToolRejoinAfterS, joins)) {
        std::fprintf(stderr,
                     "swarm_probe: no server heard within %.0f s through the discovery server; "
                     "joining again as a new participant\n",
                     waited);
        join();
        joined = wall_seconds();
        ++joins;
      }
      if (wall_seconds() - t0 > timeout_s) {
        std::printf("probe ok=0 why=airborne_%d_of_%d_after_%.0fs\n", ok ? s.airborne() : 0, drones,
                    timeout_s);
        return 1;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    wait_for_stop(std::chrono::duration<double>(settle_s));
    // 2. The window, bounded by two SimStatus samples (server tick and clock at the same instant).
    auto next_status = [&](std::uint64_t after_tick, double after_wall) {
      const double limit = wall_seconds() + 10;
      while (!stop_requested() && wall_seconds() < limit) {
        auto [ok, s] = snapshot();
        if (ok && s.wall_time_s() > after_wall && s.tick() >= after_tick) return s;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
      return snapshot().second;
    };
    std::vector<pid_t> procs;
    if (launcher > 0) {
      procs = descendants(launcher);
      procs.push_back(launcher);
    }
    procs.push_back(getpid());
    // The kernel's own threads (children of kthreadd): a memory monitor such
    // as DAMON's kdamond stalls a small VM in bursts (docs/performance.md).
    const std::vector<pid_t> kthreads = descendants(2);
    const auto k0 = sample_all(kthreads);
    msg::SimStatus s0 = next_status(0, snapshot().second.wall_time_s());
    auto cpu0 = sample_all(procs);
    const double w0 = wall_seconds();
    measuring = true;
    wait_for_stop(std::chrono::duration<double>(time_s));
    msg::SimStatus s1 = next_status(s0.tick(), s0.wall_time_s() + time_s * 0.9);
    measuring = false;
    auto cpu1 = sample_all(procs, true);
    const auto k1 = sample_all(kthreads);
    const double dw = wall_seconds() - w0;

    const double server_dw = s1.wall_time_s() - s0.wall_time_s();
    const double ticks_per_s = server_dw > 0 ? (s1.tick() - s0.tick()) / server_dw : NAN;
    const double rtf = server_dw > 0 ? (s1.sim_time_s() - s0.sim_time_s()) / server_dw : NAN;
    std::map<std::string, double> cpu;
    std::map<std::string, int> count;
    double agent_rss = 0, agent_rss_max = 0, agent_pss = 0;
    int agent_threads = 0;
    for (const auto& [pid, b] : cpu1) {
      auto it = cpu0.find(pid);
      if (it == cpu0.end()) continue;
      std::string kind = pid == getpid()                          ? "probe"
                         : b.comm == "ddswarm-sim"                ? "sim"
                         : b.comm == "ddswarm-agent"              ? "agents"
                         : b.comm == "ddswarm-launch"             ? "launcher"
                         : b.comm.rfind("fast-discovery", 0) == 0 ? "ds"
                                                                  : "other";
      cpu[kind] += (b.cpu_s - it->second.cpu_s) / dw;
      ++count[kind];
      if (kind == "agents") {
        agent_rss += b.rss_kb / 1024.0;
        agent_pss += b.pss_kb / 1024.0;
        agent_rss_max = std::max(agent_rss_max, b.rss_kb / 1024.0);
        agent_threads = b.threads;
      }
    }
    const int na = std::max(1, count["agents"]);
    std::string line = fmt::format(
        "probe ok=1 drones={} ticks_per_s={:.1f} rtf={:.3f} window_s={:.1f} status_rtf={:.3f} "
        "agents_seen={} "
        "cpu_sim={:.3f} cpu_agents={:.3f} cpu_agent_each={:.4f} cpu_ds={:.3f} cpu_launcher={:.3f} "
        "cpu_probe={:.3f} "
        "cpu_other={:.3f} rss_agent_mb={:.1f} rss_agent_max_mb={:.1f} pss_agent_mb={:.1f} "
        "agent_threads={}",
        drones, ticks_per_s, rtf, server_dw, s1.real_time_factor(), count["agents"], cpu["sim"],
        cpu["agents"], cpu["agents"] / na, cpu["ds"], cpu["launcher"], cpu["probe"], cpu["other"],
        agent_rss / na, agent_rss_max, agent_pss / na, agent_threads);
    if (ages) {
      std::lock_guard<std::mutex> lock(mu);
      line += fmt::format(
          " age_p50_periods={} age_p99_periods={} age_max_periods={} missed={} drone_ticks={} "
          "missed_frac={:.5f} "
          "probe_samples={} probe_gaps={} failsafe={} commands_applied={} lockstep_timeouts={}",
          percentile(ag.hist, 0.5), percentile(ag.hist, 0.99), percentile(ag.hist, 1.0), ag.missed,
          ag.drone_ticks, ag.drone_ticks ? static_cast<double>(ag.missed) / ag.drone_ticks : NAN,
          ag.samples, ag.probe_gaps, s1.failsafe(), s1.commands_applied() - s0.commands_applied(),
          s1.lockstep_timeouts());
      line += " " + miss_spread(ag.missed_by_drone);
      line += fmt::format(" missed_in_stalls={:.3f}",
                          ag.missed ? static_cast<double>(ag.missed_in_stalls) / ag.missed : 0.0);
    }
    double kernel = 0, kernel_top = 0;
    std::string kernel_top_name = "-";
    for (const auto& [pid, b] : k1) {
      auto it = k0.find(pid);
      if (it == k0.end()) continue;
      const double c = (b.cpu_s - it->second.cpu_s) / dw;
      kernel += c;
      if (c > kernel_top) kernel_top = c, kernel_top_name = b.comm;
    }
    line += fmt::format(" cpu_kernel={:.3f} cpu_kernel_top={}:{:.3f}", kernel, kernel_top_name,
                        kernel_top);
    std::printf("%s\n", line.c_str());
    participant->close();
    return 0;
  });
}
