#include "experiment/experiment.hpp"

#include <fmt/format.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>
#include <vector>

#include "common/config_error.hpp"
#include "common/domain_claim.hpp"
#include "common/process.hpp"
#include "common/scenario_check.hpp"
#include "common/scene.hpp"
#include "common/topics.hpp"
#include "experiment/report.hpp"
#include "ground_station/gs_file_config.hpp"
#include "launcher/launcher.hpp"
#include "launcher/preflight.hpp"

namespace ddswarm::gs {

namespace fs = std::filesystem;

TaskOutcome swarm_not_up(DdsCommander& gs, int drones, double waited_s,
                         const std::function<bool()>& give_up) {
  TaskOutcome fail;
  if (give_up && give_up()) {
    fail.reason = "a process of the run ended before the swarm was up";
    return fail;
  }
  auto st = gs.status();
  fail.reason =
      fmt::format("only {}/{} agents online ({} heard by the server) after {:g} s",
                  st.drones_online, drones, std::max(st.drones_server_hears, 0), waited_s);
  fail.never_up = true;
  return fail;
}

TaskOutcome fly_task(DdsCommander& gs, int drones, const TaskConfig& task,
                     const std::function<void(const std::string&)>& progress,
                     const std::function<bool()>& give_up, double swarm_wait_s) {
  if (!gs.wait_for_swarm(drones, swarm_wait_s, give_up))
    return swarm_not_up(gs, drones, swarm_wait_s, give_up);
  TaskOutcome fail;
  auto r = gs.takeoff(0);
  if (progress) progress(r.message);
  if (!r.ok) {
    fail.reason = "takeoff: " + r.message;
    return fail;
  }
  if (!gs.wait_takeoff_done(drones, 120.0)) {
    fail.reason = "not every drone became airborne";
    return fail;
  }
  r = gs.task(task.speed_mps, task.epsilon_m);
  if (progress) progress(r.message);
  if (!r.ok) {
    fail.reason = "task: " + r.message;
    return fail;
  }
  gs.wait_task(progress);
  return gs.last_task().value_or(fail);
}

namespace {

std::string slug(const std::string& s) {
  std::string out;
  for (char c : s) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return out;
}

template <class T>
T node_or(const YAML::Node& root, std::initializer_list<const char*> path, T fallback) {
  YAML::Node n = YAML::Clone(root);
  for (const char* k : path) {
    if (!n.IsMap() || !n[k]) return fallback;
    n = n[k];
  }
  try {
    return n.as<T>();
  } catch (...) {
    return fallback;
  }
}

std::string clock(double s) {
  int t = static_cast<int>(s + 0.5);
  return fmt::format("{}:{:02d}", t / 60, t % 60);
}

}  // namespace

namespace {

/// One run, planned before any starts (its seeded scenario file written).
struct RunPlan {
  std::size_t set = 0;
  int k = 0;
  std::string tag, scenario_file;
  RunRecord rec;
  TaskConfig task;
};

/// Where one run's wall time went.
struct RunTimes {
  double startup_s = 0;   ///< processes started until every agent is online and matched
  double flight_s = 0;    ///< takeoff until the task's result
  double teardown_s = 0;  ///< stopping every process
};

/// argv with what every process of a run on domain takes: the domain, and
/// under DDS Security the certificates (each child takes its own role's identity).
std::vector<std::string> with_run_dds(std::vector<std::string> a, int domain,
                                      const ExperimentOptions& opt) {
  a.push_back("--domain");
  a.push_back(std::to_string(domain));
  if (opt.dds.secure()) {
    a.push_back("--secure");
    a.push_back(opt.dds.security_dir);
  }
  return a;
}

ChildSpec server_spec(const RunPlan& p, int domain, const std::string& bin,
                      const ExperimentOptions& opt) {
  return {"sim", with_run_dds({bin + "/ddswarm-sim", "--scenario", p.scenario_file}, domain, opt)};
}

/// The run's agent processes: one per drone, or opt.agent_hosts hosts.
std::vector<ChildSpec> agent_specs(const RunPlan& p, int domain, const std::string& bin,
                                   const ExperimentOptions& opt) {
  std::vector<ChildSpec> specs;
  std::vector<int> ids(p.rec.drones);
  for (int i = 0; i < p.rec.drones; ++i) ids[i] = i;
  const auto shares = agent_host_shares(ids, opt.agent_hosts);
  for (std::size_t h = 0; h < shares.size(); ++h)
    specs.push_back(
        {"agent host " + std::to_string(h),
         with_run_dds(agent_command(bin, shares[h], true, p.scenario_file, true), domain, opt)});
  for (int i = 0; opt.agent_hosts == 0 && i < p.rec.drones; ++i)
    specs.push_back(
        {"agent " + std::to_string(i),
         with_run_dds(agent_command(bin, std::to_string(i), false, p.scenario_file, true), domain,
                      opt)});
  return specs;
}

/// A bad key or value in a set (or a --set) would fail each of its runs at
/// start-up, after a minute's wait for a swarm that never comes. So each
/// set's scenario is read first as its processes will read it: by the ground
/// station's reader here, and by its server's and first agent's --check, on
/// the set's first run file (its runs differ in their seed alone; a server
/// that cannot start from a seed ends its run at once, as any process that
/// ends before the swarm is up). Throws ConfigError naming what the user
/// wrote: the experiment file's line and set, the --set, or the scenario
/// file's line (explain_scenario_error).
void check_sets(const ExperimentConfig& cfg, const std::vector<RunPlan>& plans, int domain,
                const std::string& bin, const ExperimentOptions& opt) {
  const YamlDocument user = YamlDocument::load_file(cfg.scenario_path);
  std::vector<ChildSpec> checks;
  std::vector<const RunPlan*> checked;
  for (const auto& p : plans) {
    if (p.k != 0) continue;
    const ScenarioOrigin origin{cfg.scenario_path, key_lines(user.root()),
                                override_origins(cfg, p.set)};
    try {
      (void)load_gs_config(p.scenario_file);
    } catch (const ConfigError& e) {
      throw ConfigError(explain_scenario_error(e.what(), p.scenario_file, origin));
    }
    checks.push_back(server_spec(p, domain, bin, opt));
    checks.push_back(agent_specs(p, domain, bin, opt).front());
    checked.push_back(&p);
  }
  for (auto& c : checks) c.argv.push_back("--check");
  const std::string error = first_check_error(checks);
  if (error.empty()) return;
  // Each reader names the file it read: the set's.
  for (const RunPlan* p : checked)
    if (error.find(p->scenario_file + ":") != std::string::npos)
      throw ConfigError(explain_scenario_error(
          error, p->scenario_file,
          {cfg.scenario_path, key_lines(user.root()), override_origins(cfg, p->set)}));
  throw ConfigError(explain_scenario_error(error, "", {cfg.scenario_path, {}, {}}));
}

}  // namespace

namespace {

/// Writes every run's seeded scenario file under out_dir/runs; the runs in
/// the order they go, set by set.
std::vector<RunPlan> plan_runs(const ExperimentConfig& cfg, const ExperimentOptions& opt) {
  std::vector<RunPlan> plans;
  for (std::size_t s = 0; s < cfg.sets.size(); ++s) {
    YAML::Node base = scenario_for_set(cfg, s);
    anchor_mesh_files(base, std::filesystem::path(cfg.scenario_path).parent_path().string());
    for (int k = 0; k < cfg.runs_per_set; ++k) {
      RunPlan p;
      p.set = s;
      p.k = k;
      YAML::Node sc = YAML::Clone(base);
      const std::uint64_t seed = cfg.seed(static_cast<int>(s), k);
      sc["scenario"]["seed"] = seed;
      sc["scenario"]["mode"] = cfg.mode;
      sc["sim"]["task_timeout_s"] = cfg.timeout_s;
      p.tag = fmt::format("{}-{:02d}", slug(cfg.sets[s].name), k);
      p.scenario_file = opt.out_dir + "/runs/" + p.tag + ".yaml";
      {
        std::ofstream f(p.scenario_file);
        f << YAML::Dump(sc) << "\n";
        if (!f) throw std::runtime_error("cannot write " + p.scenario_file);
      }
      RunRecord& rec = p.rec;
      rec.set_name = cfg.sets[s].name;
      rec.run_index = k;
      rec.seed = seed;
      rec.mode = cfg.mode;
      rec.drones = node_or<int>(sc, {"scenario", "drones"}, 6);
      rec.d_int_m = node_or<double>(sc, {"agent", "inter_distance_m"}, 4.0);
      rec.sensor_function = node_or<std::string>(sc, {"agent", "sensor_function", "type"}, "fs1");
      p.task.speed_mps = node_or<double>(sc, {"task", "speed_mps"}, p.task.speed_mps);
      p.task.epsilon_m = node_or<double>(sc, {"task", "epsilon_m"}, p.task.epsilon_m);
      rec.speed_mps = p.task.speed_mps;
      for (const auto& [key, value] : cfg.sets[s].overrides) rec.params[key] = YAML::Dump(value);
      plans.push_back(std::move(p));
    }
  }
  return plans;
}

/// Starts one run's processes on its domain: the recorder (with --record),
/// the server, and the agents (one process each, or opt.agent_hosts hosts).
void start_run_processes(Launcher& procs, const RunPlan& p, int domain, const std::string& bin,
                         const ExperimentOptions& opt) {
  const bool recording = !opt.record_dir.empty();
  if (recording) {
    fs::create_directories(opt.record_dir);
    procs.start(
        {"record",
         with_run_dds({bin + "/ddswarm-record", "-o", opt.record_dir + "/" + p.tag + ".mcap"},
                      domain, opt),
         kRecorderMatchedServer});
  }
  procs.start(server_spec(p, domain, bin, opt));
  // The recording holds the whole flight: the agents start once it hears the server.
  if (recording && !procs.wait_ready("record", kRecorderWaitS))
    std::fprintf(stderr,
                 "ddswarm-gs: warning: run %s: the recorder has not matched the server's swarm "
                 "state within %g s; starting the agents anyway\n",
                 p.tag.c_str(), kRecorderWaitS);
  for (const auto& spec : agent_specs(p, domain, bin, opt)) procs.start(spec);
}

/// How one start of a run ended: its outcome, and the processes that ended
/// during it ("" = none).
struct RunStart {
  TaskOutcome o;
  std::string died;
};

/// One start of a run, its starts-th: fresh processes on domain, the swarm's
/// bring-up and the task, every process stopped before it returns. Sets
/// times' start-up and flight, adds to its teardown.
RunStart start_and_fly(const RunPlan& p, int starts, int domain, const std::string& bin,
                       const ExperimentOptions& opt, double run_start, RunTimes& times) {
  RunStart r;
  Launcher procs(opt.out_dir + "/logs/" + p.tag +
                 (starts > 1 ? ".start" + std::to_string(starts) : ""));
  start_run_processes(procs, p, domain, bin, opt);
  DdsConfig dds = one_shot(opt.dds);
  dds.domain_id = domain;
  // The run's ground station announces a lease it will not outlive and
  // leaves before its swarm: the swarm's processes never check its lease,
  // and this process, which holds the whole experiment, has left DDS when
  // they go. In Fast DDS 2.9.1 a process that removes a departing peer as
  // its lease timer for that peer fires aborts (kOneShotLeaseS, docs/dds.md).
  std::optional<DdsCommander> commander(std::in_place, opt.gs, dds);
  DdsCommander& gs = *commander;
  // The run's end, set under watch_mu and told on watch_cv, so that the
  // watchdog's 100 ms wait ends at once (it held every run up to 100 ms).
  bool finished = false;
  std::mutex watch_mu;
  std::condition_variable watch_cv;
  // A process that ends during the run fails it (rec.ok below); one that
  // ends before the swarm is up also ends the wait for it, which would
  // otherwise last a minute.
  std::atomic<bool> someone_died{false};
  std::thread watchdog([&] {
    std::unique_lock<std::mutex> lock(watch_mu);
    while (!finished && !stop_requested()) {
      lock.unlock();  // the run's end is told while this reaps
      for (const auto& e : procs.reap()) {
        r.died += (r.died.empty() ? "" : "; ") + e.describe();
        someone_died = true;
      }
      lock.lock();
      watch_cv.wait_for(lock, std::chrono::milliseconds(100), [&] { return finished; });
    }
  });
  const auto give_up = [&] { return someone_died.load(); };
  // Waited for here, to split start-up from flight; a swarm not up is
  // not waited for again.
  const bool up = gs.wait_for_swarm(p.rec.drones, kSwarmWaitS, give_up);
  const double flight_start = wall_seconds();
  times.startup_s = flight_start - run_start;
  r.o = up ? fly_task(gs, p.rec.drones, p.task, nullptr, give_up)
           : swarm_not_up(gs, p.rec.drones, kSwarmWaitS, give_up);
  times.flight_s = wall_seconds() - flight_start;
  {
    std::lock_guard<std::mutex> lock(watch_mu);
    finished = true;
  }
  watch_cv.notify_all();
  watchdog.join();
  const double stop_start = wall_seconds();
  commander.reset();
  procs.stop_all(3.0);
  times.teardown_s += wall_seconds() - stop_start;
  return r;
}

/// A run's CSV row: its plan's, with how its last start ended.
RunRecord finished_record(RunRecord rec, const RunStart& r, double run_start) {
  rec = with_outcome(std::move(rec), r.o);
  if (!r.died.empty()) {  // a process died: the run failed, whatever the task said
    rec.ok = false;
    rec.failure_reason = r.died;
  }
  rec.wall_time_s = wall_seconds() - run_start;
  return rec;
}

/// The runs of one experiment, flown by `jobs` workers, each on a domain of
/// its own: what they share (the output, the counters, the records) under mu.
struct ExperimentRuns {
  ExperimentRuns(const ExperimentOptions& opt, std::vector<RunPlan>& plans, std::ostream& out,
                 std::string bin, std::string csv, int total, double t0)
      : opt(opt),
        plans(plans),
        out(out),
        bin(std::move(bin)),
        csv(std::move(csv)),
        total(total),
        t0(t0),
        records(plans.size()) {}

  const ExperimentOptions& opt;
  std::vector<RunPlan>& plans;
  std::ostream& out;
  const std::string bin, csv;
  const int total;
  const double t0;
  std::mutex mu;  // out, the counters and the records below
  int started = 0, done = 0, failed = 0;
  std::vector<std::optional<RunRecord>> records;
  RunTimes sum;

  /// Says that the run starts, with the time elapsed and, past the first, the ETA.
  void announce(const RunPlan& p, double run_start) {
    std::lock_guard<std::mutex> lock(mu);
    ++started;
    out << fmt::format("run {} of {} ({} #{}, seed {}), elapsed {}", started, total, p.rec.set_name,
                       p.k + 1, p.rec.seed, clock(run_start - t0));
    if (done > 0) out << fmt::format(", ETA {}", clock((run_start - t0) / done * (total - done)));
    out << std::endl;
  }

  /// One run, on its own DDS domain (one per parallel job): fresh processes,
  /// every one of them stopped before it returns. A run whose swarm never
  /// came up starts again: that is a start-up failure, not a result
  /// (start_run_again).
  void run_one(std::size_t index, int domain) {
    RunPlan& p = plans[index];
    RunTimes times;
    const double run_start = wall_seconds();
    announce(p, run_start);
    RunStart r;
    for (int starts = 1;; ++starts) {
      r = start_and_fly(p, starts, domain, bin, opt, run_start, times);
      if (stop_requested() || !start_run_again(r.o, !r.died.empty(), starts)) break;
      std::lock_guard<std::mutex> lock(mu);
      out << fmt::format("  {}: {}; starting the run again ({} of {})", p.tag, r.o.reason,
                         starts + 1, kRunStarts)
          << std::endl;
    }
    const RunRecord rec = finished_record(p.rec, r, run_start);
    std::lock_guard<std::mutex> lock(mu);
    append_csv(csv, rec);
    ++done;
    if (!rec.ok) ++failed;
    sum.startup_s += times.startup_s;
    sum.flight_s += times.flight_s;
    sum.teardown_s += times.teardown_s;
    out << "  " << p.tag << ": " << (rec.ok ? r.o.line() : "FAILED: " + rec.failure_reason)
        << std::endl;
    records[index] = rec;
  }
};

/// The experiment's table (out_dir/<name>.md and out) and plots, and where
/// its wall time went; returns the exit code.
int report_experiment(const ExperimentConfig& cfg, const ExperimentOptions& opt,
                      ExperimentRuns& runs, int jobs) {
  std::ostream& out = runs.out;
  std::vector<RunRecord> finished_records;
  for (auto& r : runs.records)
    if (r) finished_records.push_back(*r);
  auto summary = summarize(finished_records);
  const std::string table = markdown_table(summary);
  const std::string metrics = metrics_table(summary);
  {
    std::ofstream f(opt.out_dir + "/" + slug(cfg.name) + ".md");
    f << "# " << cfg.name << "\n\n" << table << "\n";
    if (!metrics.empty()) f << "## Swarm metrics\n\n" << metrics << "\n";
  }
  out << "\n" << table << "\n";
  if (!metrics.empty()) out << "Swarm metrics:\n\n" << metrics << "\n";
  try {
    write_plots(finished_records, opt.out_dir + "/plots");
    out << "plots: " << opt.out_dir << "/plots\n";
  } catch (const std::exception& e) {
    out << "plots not written: " << e.what() << "\n";
  }
  const double wall = wall_seconds() - runs.t0;
  const RunTimes& sum = runs.sum;
  const double busy = sum.startup_s + sum.flight_s + sum.teardown_s;
  if (runs.done > 0 && busy > 0)
    out << fmt::format(
        "wall time per run (summed over {} runs, {} at a time): start-up {:.1f} s ({:.0f} %), "
        "flight {:.1f} s "
        "({:.0f} %), teardown {:.1f} s ({:.0f} %)\n",
        runs.done, jobs, sum.startup_s, 100 * sum.startup_s / busy, sum.flight_s,
        100 * sum.flight_s / busy, sum.teardown_s, 100 * sum.teardown_s / busy);
  out << fmt::format("{} runs, {} failed, {} wall; CSV {}\n", runs.done, runs.failed, clock(wall),
                     runs.csv);
  return runs.failed == 0 && runs.done == runs.total ? 0 : 1;
}

}  // namespace

RunRecord with_outcome(RunRecord rec, const TaskOutcome& o) {
  rec.ok = o.ok;
  rec.failure_reason = o.reason;
  rec.task_time_s = o.ok ? o.task_time_s : std::nan("");
  rec.wall_time_s = o.wall_time_s;
  rec.collisions_obstacle = o.collisions_obstacle;
  rec.collisions_drone = o.collisions_drone;
  rec.collisions_ground = o.collisions_ground;
  rec.min_inter_drone_m = o.min_inter_drone_m;
  rec.min_clearance_m = o.min_clearance_m;
  rec.metrics = o.metrics;
  return rec;
}

int run_experiment(const ExperimentConfig& cfg, const ExperimentOptions& opt, std::ostream& out) {
  const std::string bin = opt.bin_dir.empty() ? Launcher::self_dir() : opt.bin_dir;
  fs::create_directories(opt.out_dir + "/runs");
  const std::string csv = opt.out_dir + "/" + slug(cfg.name) + ".csv";
  if (fs::exists(csv)) fs::remove(csv);  // a fresh experiment; older rows would mix in
  const int total = static_cast<int>(cfg.sets.size()) * cfg.runs_per_set;
  const int jobs = std::max(1, std::min(opt.jobs, total));
  // One domain per job, claimed on this host for the whole experiment: a
  // second experiment, a launched swarm or any live participant keeps its
  // domain (common/domain_claim.hpp).
  std::vector<std::string> skipped;
  const std::vector<DomainClaim> domains = claim_free_domains(opt.dds.domain_id, jobs, &skipped);
  if (static_cast<int>(domains.size()) < jobs)
    throw std::invalid_argument(fmt::format(
        "--jobs {}: only {} free DDS domains from {} to 232 on this host{}", jobs, domains.size(),
        opt.dds.domain_id, skipped.empty() ? "" : " (" + skipped.front() + ", ...)"));
  const double t0 = wall_seconds();

  std::vector<RunPlan> plans = plan_runs(cfg, opt);
  check_sets(cfg, plans, domains.front().domain(), bin, opt);
  out << fmt::format("experiment '{}': {} sets x {} runs, {} mode, {} at a time, results in {}\n",
                     cfg.name, cfg.sets.size(), cfg.runs_per_set, cfg.mode, jobs, opt.out_dir);
  for (const auto& why : skipped) out << "  not on " << why << "\n";
  out << "  runs on DDS domain" << (jobs > 1 ? "s" : "");
  for (std::size_t w = 0; w < domains.size(); ++w) out << (w ? ", " : " ") << domains[w].domain();
  out << std::endl;

  ExperimentRuns runs(opt, plans, out, bin, csv, total, t0);
  std::atomic<int> next{0};
  std::vector<std::thread> workers;
  for (int w = 0; w < jobs; ++w)
    workers.emplace_back([&, w] {
      for (int i = next++; i < total && !stop_requested(); i = next++)
        runs.run_one(i, domains[w].domain());
    });
  for (auto& t : workers) t.join();
  return report_experiment(cfg, opt, runs, jobs);
}

}  // namespace ddswarm::gs
