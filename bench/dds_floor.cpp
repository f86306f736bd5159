// dds_floor: the lockstep floor that Fast DDS sets on this machine.
//
// One process publishes a whole-swarm msg::SwarmState with N drones and their
// scans (the size ddswarm's server publishes); N responder processes (this
// binary, --respond ID) each answer with one msg::VelocityCommand from inside
// the DDS callback, as ddswarm's agents do; once all N have answered, the next
// tick goes out. Same Participant, transports (localhost only) and QoS
// profiles as ddswarm. Measures discovery time, idle CPU after discovery and
// ticks/s after a warm-up, with simple discovery and with the Fast DDS
// discovery server.
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <iostream>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>

#include "bench/bench_util.hpp"
#include "bench/hover_field.hpp"
#include "common/participant.hpp"
#include "common/process.hpp"
#include "sim_server/sim_server.hpp"

using namespace ddswarm;
using namespace ddswarm::bench;

namespace {

constexpr int kRays = 8;  // config/thesis_course.yaml sensors.count

msg::SwarmState make_state(int n) {
  msg::SwarmState s;
  s.drones().resize(n);
  s.scans().resize(n);
  for (int i = 0; i < n; ++i) {
    auto& d = s.drones()[i];
    d.drone_id(static_cast<std::uint16_t>(i));
    d.position().x(i * 1.5);
    d.orientation().w(1.0);
    auto& sc = s.scans()[i];
    sc.drone_id(static_cast<std::uint16_t>(i));
    sc.max_range_m(6.0f);
    for (int k = 0; k < kRays; ++k) {
      sc.angle_body_rad().push_back(static_cast<float>(2 * M_PI * k / kRays));
      sc.elevation_body_rad().push_back(0.0f);
      sc.range_m().push_back(6.0f);
      sc.hit().push_back(0);
    }
  }
  return s;
}

std::string g_profiles;  // --profiles: a QoS profiles file other than ddswarm's
double g_work_us = 0;    // --work-us: the publisher's CPU between ticks, standing in for physics
// --physics-hz: the publisher steps a lockstep server's physics between ticks;
// --physics-scenario: whose scene, formation, airframe, controller and sensors.
double g_physics_hz = 0;
std::string g_physics_scenario;
bool g_best_effort =
    false;  // --best-effort-streams: read the two streams as a real-time swarm does
Delivery stream_delivery() { return g_best_effort ? Delivery::kLatest : Delivery::kProfile; }

DdsConfig dds_for(int domain, const std::string& server, int participant_id = -1) {
  DdsConfig c;
  if (!g_profiles.empty()) c.profiles_file = g_profiles;
  c.domain_id = domain;
  c.participant_id = participant_id;
  if (!server.empty()) {
    c.discovery = Discovery::kDiscoveryServer;
    c.discovery_server = server;
    c.lease_duration_s = kDiscoveryServerLeaseS;  // as ddswarm-launch gives a swarm with one
  }
  return c;
}

/// Responder: answers every SwarmState with one VelocityCommand, inside the callback.
int respond(int id, int domain, const std::string& server, double duration_s, int participant_id) {
  install_stop_signals();
  // An agent's shared-memory outbox and inbox, as ddswarm-agent sizes them for one drone.
  DdsConfig dds = dds_for(domain, server, participant_id);
  dds.shm_segment_bytes = agent_shm_segment_bytes(1);
  dds.shm_port_queue = agent_shm_port_queue(1);
  Participant p(dds, "dds_floor responder " + std::to_string(id));
  auto w = p.writer<msg::VelocityCommand>();
  msg::VelocityCommand cmd;
  cmd.drone_id(static_cast<std::uint16_t>(id));
  cmd.motors_on(true);
  p.reader<msg::SwarmState>(
      [&](const msg::SwarmState& s, const fdds::SampleInfo&) {
        // Read what an agent reads: its own state and every peer's position.
        double sx = 0;
        for (const auto& d : s.drones()) sx += d.position().x();
        cmd.tick(s.tick());
        cmd.sim_time_s(s.sim_time_s());
        cmd.velocity().x(id < static_cast<int>(s.drones().size()) ? -sx * 1e-6 : 0);
        w.write(cmd);
      },
      std::nullopt, stream_delivery());
  wait_for_stop(std::chrono::duration<double>(duration_s));
  p.close();
  return 0;
}

struct Result {
  int n = 0;
  std::string discovery;
  bool ok = false;
  std::string why;
  double discovery_s = NAN, idle_cores = NAN, busy_cores = NAN, ticks_per_s = NAN;
  long ticks = 0;
  double responder_rss_mb = NAN;
  int responder_threads = 0;
  double physics_us = NAN;  ///< --physics-hz: the publisher's CPU per tick in the physics (µs)
};

/// CPU seconds this thread has run.
double thread_cpu_s() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

double cpu_of(const std::map<pid_t, ProcSample>& m) {
  double s = 0;
  for (const auto& [p, x] : m) s += x.cpu_s;
  return s;
}

/// CPU seconds used between two samples, by the processes present in both.
double cpu_between(const std::map<pid_t, ProcSample>& a, const std::map<pid_t, ProcSample>& b) {
  double s = 0;
  for (const auto& [p, x] : b)
    if (auto it = a.find(p); it != a.end()) s += x.cpu_s - it->second.cpu_s;
  return s;
}

Result run_one(int n, bool use_server, bool explicit_ids, int domain, double warmup_s,
               double measure_s, double idle_s, double discovery_timeout_s,
               const std::string& log_dir) {
  Result r;
  r.n = n;
  r.discovery = use_server ? "server" : "simple";
  // --physics-hz: what a lockstep server computes between ticks, for N
  // hovering drones (bench/hover_field.hpp), in place of --work-us's wait.
  std::optional<bench::HoverField> field;
  bench::TickPlan plan = bench::TickPlan::at(g_physics_hz);
  if (g_physics_hz > 0 && g_physics_scenario.empty()) {
    field.emplace(n, 1.0 / g_physics_hz);
  } else if (g_physics_hz > 0) {
    const sim::ServerConfig c = sim::load_server_config(g_physics_scenario);
    plan = bench::TickPlan::at(g_physics_hz, c.sim.control_rate_hz);
    plan.sensors = c.sensors;
    plan.sensor_every = c.sim.sensor_every();
    field.emplace(c.scene, c.quadrotor, c.controller, c.scene.start_positions(n, c.scenario.seed),
                  1.0 / g_physics_hz);
  }
  std::vector<pid_t> kids;
  std::string server;
  const double t0 = wall_seconds();
  if (use_server) {
    int port = free_udp_port();
    server = fmt::format("127.0.0.1:{}", port);
    kids.push_back(start_discovery_server(port, log_dir.empty() ? "" : log_dir + "/ds.log"));
  }
  const double child_budget = discovery_timeout_s + warmup_s + measure_s + idle_s + 30;
  for (int i = 0; i < n; ++i) {
    std::vector<std::string> a = {self_exe(),
                                  "--respond",
                                  std::to_string(i),
                                  "--domain",
                                  std::to_string(domain),
                                  "--duration",
                                  fmt::format("{:.0f}", child_budget)};
    if (!g_profiles.empty()) a.insert(a.end(), {"--profiles", g_profiles});
    if (g_best_effort) a.push_back("--best-effort-streams");
    if (use_server) {
      a.push_back("--discovery-server");
      a.push_back(server);
    }
    if (explicit_ids) {
      a.push_back("--participant-id");
      a.push_back(std::to_string(i + 1));
    }
    kids.push_back(spawn(a, log_dir.empty() ? "" : fmt::format("{}/responder-{}.log", log_dir, i)));
  }
  std::vector<pid_t> all = kids;
  all.push_back(getpid());
  {
    Participant p(dds_for(domain, server, explicit_ids ? 0 : -1), "dds_floor publisher");
    auto w = p.writer<msg::SwarmState>();
    std::mutex mu;
    std::condition_variable cv;
    std::uint64_t tick = 0;
    std::vector<char> answered(n, 0);
    int count = 0;
    auto& rd = p.reader<msg::VelocityCommand>(
        [&](const msg::VelocityCommand& c, const fdds::SampleInfo&) {
          std::lock_guard<std::mutex> lock(mu);
          if (c.tick() != tick || c.drone_id() >= n || answered[c.drone_id()]) return;
          answered[c.drone_id()] = 1;
          if (++count == n) cv.notify_all();
        },
        std::nullopt, stream_delivery());
    // Discovery: every responder's reader and writer matched with ours.
    while (!stop_requested() && (w.matched() < n || rd.matched() < n) &&
           wall_seconds() - t0 < discovery_timeout_s)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    r.discovery_s = wall_seconds() - t0;
    if (w.matched() < n || rd.matched() < n) {
      r.why =
          fmt::format("discovery incomplete after {:.0f} s: {}/{} readers, {}/{} writers matched",
                      r.discovery_s, w.matched(), n, rd.matched(), n);
    } else {
      // Idle cost once discovered: the participants' announcements and liveliness.
      auto a = sample_all(all);
      wait_for_stop(std::chrono::duration<double>(idle_s));
      r.idle_cores = cpu_between(a, sample_all(all)) / idle_s;

      msg::SwarmState s = make_state(n);
      auto publish = [&](std::uint64_t k) {
        s.tick(k);
        s.sim_time_s(k * 0.02);
        w.write(s);
      };
      // Lockstep; re-publish a tick nobody answered within 0.25 s (a sample
      // written before the match completed is lost for good: FASTDDS_NOTES trap 1).
      long ticks = 0;
      double physics_cpu_s = 0;  // in the measured window
      bool measuring = false;
      double t_measure = 0;
      std::map<pid_t, ProcSample> cpu0;
      const double t_start = wall_seconds();
      publish(0);
      while (!stop_requested()) {
        std::unique_lock<std::mutex> lock(mu);
        if (!cv.wait_for(lock, std::chrono::milliseconds(250), [&] { return count == n; })) {
          lock.unlock();
          if (wall_seconds() - t_start > warmup_s + measure_s + 30) {
            r.why = fmt::format("tick {} unanswered by {} responder(s)", tick, n - count);
            break;
          }
          publish(tick);
          continue;
        }
        ++tick;
        count = 0;
        std::fill(answered.begin(), answered.end(), 0);
        lock.unlock();
        const double now = wall_seconds();
        if (!measuring && now - t_start >= warmup_s) {
          measuring = true;
          t_measure = now;
          ticks = 0;
          physics_cpu_s = 0;
          cpu0 = sample_all(all);
        } else if (measuring) {
          ++ticks;
          if (now - t_measure >= measure_s) {
            const double dt = now - t_measure;
            r.busy_cores = cpu_between(cpu0, sample_all(all)) / dt;
            r.ticks = ticks;
            r.ticks_per_s = ticks / dt;
            if (field && ticks > 0) r.physics_us = physics_cpu_s * 1e6 / static_cast<double>(ticks);
            r.ok = true;
            break;
          }
        }
        if (field) {
          const double c0 = thread_cpu_s();
          field->server_tick(plan, tick);
          if (measuring) physics_cpu_s += thread_cpu_s() - c0;
        }
        if (g_work_us > 0) {  // busy, as a physics step is: no sleep, no yield
          const double until = wall_seconds() + g_work_us * 1e-6;
          while (wall_seconds() < until) {
          }
        }
        publish(tick);
      }
      auto procs = sample_all(kids, false);
      double rss = 0;
      int m = 0;
      for (const auto& [pid, x] : procs)
        if (x.comm == "dds_floor") {
          rss += x.rss_kb;
          r.responder_threads = x.threads;
          ++m;
        }
      if (m) r.responder_rss_mb = rss / m / 1024.0;
    }
    p.close();
  }
  stop_all(kids);
  (void)cpu_of;
  return r;
}

std::string fmt_num(double v, const char* f) {
  return std::isfinite(v) ? fmt::format(fmt::runtime(f), v) : "-";
}

}  // namespace

int main(int argc, char** argv) {
  return run_main("dds_floor", [&]() -> int {
    CLI::App app{
        "dds_floor: the bare Fast DDS lockstep floor (one whole-swarm sample out, N answers back)"};
    std::vector<int> sizes = {6, 16, 32, 64, 128};
    std::string discovery = "both", csv, log_dir;
    double warmup_s = 2, measure_s = 5, idle_s = 2, discovery_timeout_s = 120, duration_s = 600;
    int simple_max = 64, domain = -1, respond_id = -1, participant_id = -1;
    bool explicit_ids = false;
    std::string server;
    app.add_option("--drones", sizes, "swarm sizes to measure")->delimiter(',');
    app.add_option("--discovery", discovery, "simple | server | both")
        ->check(CLI::IsMember({"simple", "server", "both"}));
    app.add_option(
        "--simple-max", simple_max,
        "largest N run with simple discovery (N=128 takes ~90 s to discover, and more than "
        "~100 participants need explicit ids)");
    app.add_option("--warmup", warmup_s, "s of lockstep before measuring");
    app.add_option("--time", measure_s, "s of lockstep measured");
    app.add_option("--idle", idle_s, "s of idle CPU measured after discovery");
    app.add_option("--discovery-timeout", discovery_timeout_s, "s to wait for discovery");
    app.add_option("--domain", domain,
                   "DDS domain (default: random in 20-79, whose RTPS ports stay below the "
                   "ephemeral port range)");
    app.add_option("--profiles", g_profiles,
                   "QoS profiles XML (default: ddswarm's config/dds_profiles.xml)")
        ->check(CLI::ExistingFile);
    app.add_option("--work-us", g_work_us,
                   "µs the publisher spends busy between ticks, as a server steps physics there "
                   "(0: none, the floor)")
        ->check(CLI::NonNegativeNumber);
    app.add_option(
           "--physics-hz", g_physics_hz,
           "step a lockstep server's physics between ticks: N hovering drones' flight "
           "controllers and Bullet at this rate (Hz) for one control tick, then their sensors "
           "(0: none, the floor). The floor with it is the most plain lockstep can tick "
           "(its physics CPU per tick is printed)")
        ->check(CLI::Range(0.0, 4000.0));
    app.add_option(
           "--physics-scenario", g_physics_scenario,
           "with --physics-hz: this scenario's scene, start formation, airframe, controller and "
           "sensors (default: a field of pillars, 8 rays of 6 m every tick)")
        ->check(CLI::ExistingFile);
    app.add_flag("--best-effort-streams", g_best_effort,
                 "read the swarm state and the commands best-effort, as ddswarm does by default "
                 "(dds.best_effort_streams; writers stay reliable; a lost tick is re-published "
                 "after 0.25 s)");
    app.add_option("--csv", csv, "append one row per run to this CSV");
    app.add_option("--log-dir", log_dir,
                   "responder and discovery-server logs (default: discarded)");
    app.add_flag(
        "--explicit-ids", explicit_ids,
        "give every participant its RTPS participant id (publisher 0, responder i: i+1) instead of "
        "Fast DDS's automatic one (needs N < dds.participant_id's limit for the domain)");
    app.add_option("--participant-id", participant_id, "internal: responder's participant id")
        ->group("");
    app.add_option("--respond", respond_id, "internal: run as responder ID")->group("");
    app.add_option("--discovery-server", server, "internal: responder's discovery server")
        ->group("");
    app.add_option("--duration", duration_s, "internal: responder's lifetime (s)")->group("");
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
      return app.exit(e) == 0 ? 0 : 2;
    }
    if (domain < 0) domain = 20 + static_cast<int>(random_instance() % 60);
    if (respond_id >= 0) return respond(respond_id, domain, server, duration_s, participant_id);
    install_stop_signals();
    if (!log_dir.empty()) std::filesystem::create_directories(log_dir);

    std::vector<Result> results;
    for (int n : sizes) {
      for (bool use_server : {false, true}) {
        if (stop_requested()) break;
        if (use_server && discovery == "simple") continue;
        if (!use_server && discovery == "server") continue;
        if (!use_server && n > simple_max) {
          Result r;
          r.n = n;
          r.discovery = "simple";
          r.why = fmt::format("skipped (--simple-max {})", simple_max);
          results.push_back(r);
          continue;
        }
        std::fprintf(stderr, "dds_floor: N=%d, %s discovery ...\n", n,
                     use_server ? "server" : "simple");
        if (explicit_ids && n > max_participant_id(domain) - 1) {
          Result r;
          r.n = n;
          r.discovery = use_server ? "server" : "simple";
          r.why = fmt::format(
              "skipped: explicit ids need N <= {} in domain {} (dds.participant_id range)",
              max_participant_id(domain) - 1, domain);
          results.push_back(r);
          continue;
        }
        Result r = run_one(n, use_server, explicit_ids, domain, warmup_s, measure_s, idle_s,
                           discovery_timeout_s, log_dir);
        std::fprintf(stderr, "dds_floor: N=%d %s: %s\n", n, r.discovery.c_str(),
                     r.ok ? fmt::format("{:.0f} ticks/s", r.ticks_per_s).c_str() : r.why.c_str());
        results.push_back(r);
      }
    }
    const std::string between =
        g_physics_hz > 0
            ? fmt::format("; the publisher steps {:.0f} Hz physics for N drones between ticks",
                          g_physics_hz)
        : g_work_us > 0 ? fmt::format("; the publisher busy {:.0f} us between ticks", g_work_us)
                        : std::string();
    std::printf(
        "\n== bare Fast DDS lockstep floor: 1 publisher of a whole-swarm SwarmState, N responder "
        "processes%s; %.0f s warm-up, %.0f s measured ==\n",
        between.c_str(), warmup_s, measure_s);
    std::printf(
        "| N | discovery | ticks/s | discovery time (s) | idle CPU (cores) | CPU while ticking "
        "(cores) | "
        "responder RSS (MB) | responder threads | physics CPU per tick (µs) | note |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
    for (const auto& r : results)
      std::printf("| %d | %s | %s | %s | %s | %s | %s | %s | %s | %s |\n", r.n, r.discovery.c_str(),
                  fmt_num(r.ticks_per_s, "{:.0f}").c_str(),
                  fmt_num(r.discovery_s, "{:.1f}").c_str(), fmt_num(r.idle_cores, "{:.2f}").c_str(),
                  fmt_num(r.busy_cores, "{:.2f}").c_str(),
                  fmt_num(r.responder_rss_mb, "{:.1f}").c_str(),
                  r.responder_threads ? std::to_string(r.responder_threads).c_str() : "-",
                  fmt_num(r.physics_us, "{:.0f}").c_str(), r.why.c_str());
    if (!csv.empty()) {
      bool fresh = !std::filesystem::exists(csv);
      std::ofstream f(csv, std::ios::app);
      if (fresh)
        f << "n,discovery,ok,ticks_per_s,discovery_s,idle_cores,busy_cores,responder_rss_mb,note,"
             "physics_hz,"
             "work_us,physics_us\n";
      for (const auto& r : results)
        f << r.n << "," << r.discovery << "," << (r.ok ? 1 : 0) << "," << r.ticks_per_s << ","
          << r.discovery_s << "," << r.idle_cores << "," << r.busy_cores << ","
          << r.responder_rss_mb << ",\"" << r.why << "\"," << g_physics_hz << "," << g_work_us
          << "," << r.physics_us << "\n";
    }
    bool any_fail = false;
    for (const auto& r : results)
      if (!r.ok && r.why.rfind("skipped", 0) != 0) any_fail = true;
    return any_fail ? 1 : 0;
  });
}
