#include "ground_station/experiment.hpp"

#include <fmt/format.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include "common/process.hpp"
#include "ground_station/launcher.hpp"
#include "ground_station/report.hpp"

namespace ddswarm::gs {

namespace fs = std::filesystem;

TaskOutcome fly_task(DdsCommander& gs, int drones, const TaskConfig& task,
                     const std::function<void(const std::string&)>& progress) {
  TaskOutcome fail;
  if (!gs.wait_for_swarm(drones, 30.0)) {
    auto st = gs.status();
    fail.reason = fmt::format("only {}/{} agents online after 30 s", st.drones_online, drones);
    return fail;
  }
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

int run_experiment(const ExperimentConfig& cfg, const ExperimentOptions& opt, std::ostream& out) {
  const std::string bin = opt.bin_dir.empty() ? Launcher::self_dir() : opt.bin_dir;
  fs::create_directories(opt.out_dir + "/runs");
  const std::string csv = opt.out_dir + "/" + slug(cfg.name) + ".csv";
  if (fs::exists(csv)) fs::remove(csv);  // a fresh experiment; older rows would mix in
  const int total = static_cast<int>(cfg.sets.size()) * cfg.runs_per_set;
  const double t0 = wall_seconds();
  int done = 0, failed = 0;
  std::vector<RunRecord> records;
  out << fmt::format("experiment '{}': {} sets x {} runs, {} mode, results in {}\n", cfg.name,
                     cfg.sets.size(), cfg.runs_per_set, cfg.mode, opt.out_dir);
  for (std::size_t s = 0; s < cfg.sets.size() && !stop_requested(); ++s) {
    YAML::Node base = scenario_for_set(cfg, s);
    for (int k = 0; k < cfg.runs_per_set && !stop_requested(); ++k) {
      YAML::Node sc = YAML::Clone(base);
      const std::uint64_t seed = cfg.seed(static_cast<int>(s), k);
      sc["scenario"]["seed"] = seed;
      sc["scenario"]["mode"] = cfg.mode;
      sc["sim"]["task_timeout_s"] = cfg.timeout_s;
      const std::string tag = fmt::format("{}-{:02d}", slug(cfg.sets[s].name), k);
      const std::string scenario_file = opt.out_dir + "/runs/" + tag + ".yaml";
      {
        std::ofstream f(scenario_file);
        f << YAML::Dump(sc) << "\n";
        if (!f) throw std::runtime_error("cannot write " + scenario_file);
      }
      RunRecord rec;
      rec.set_name = cfg.sets[s].name;
      rec.run_index = k;
      rec.seed = seed;
      rec.mode = cfg.mode;
      rec.drones = node_or<int>(sc, {"scenario", "drones"}, 6);
      rec.d_int_m = node_or<double>(sc, {"agent", "inter_distance_m"}, 4.0);
      rec.sensor_function = node_or<std::string>(sc, {"agent", "sensor_function", "type"}, "fs1");
      TaskConfig task;
      task.speed_mps = node_or<double>(sc, {"task", "speed_mps"}, task.speed_mps);
      task.epsilon_m = node_or<double>(sc, {"task", "epsilon_m"}, task.epsilon_m);
      rec.speed_mps = task.speed_mps;
      for (const auto& [key, value] : cfg.sets[s].overrides) rec.params[key] = YAML::Dump(value);

      const double run_start = wall_seconds();
      out << fmt::format("run {} of {} ({} #{}, seed {}), elapsed {}", done + 1, total,
                         cfg.sets[s].name, k + 1, seed, clock(run_start - t0));
      if (done > 0)
        out << fmt::format(", ETA {}", clock((run_start - t0) / done * (total - done)));
      out << std::endl;

      TaskOutcome o;
      std::string died;
      {
        Launcher procs(opt.out_dir + "/logs/" + tag);
        auto common_args = [&](std::vector<std::string> a) {
          a.push_back("--domain");
          a.push_back(std::to_string(opt.dds.domain_id));
          if (opt.dds.secure()) {  // each child takes its own role's identity
            a.push_back("--secure");
            a.push_back(opt.dds.security_dir);
          }
          return a;
        };
        if (!opt.record_dir.empty()) {
          fs::create_directories(opt.record_dir);
          procs.start({"record", common_args({bin + "/ddswarm-record", "-o",
                                              opt.record_dir + "/" + tag + ".mcap"})});
        }
        procs.start({"sim", common_args({bin + "/ddswarm-sim", "--scenario", scenario_file})});
        for (int i = 0; i < rec.drones; ++i)
          procs.start({"agent " + std::to_string(i),
                       common_args({bin + "/ddswarm-agent", "--id", std::to_string(i), "--config",
                                    scenario_file})});
        DdsCommander gs(opt.gs, opt.dds);
        // The sim-time limit per run: the task fails after cfg.timeout_s of sim time.
        std::atomic<bool> finished{false};
        std::thread watchdog([&] {
          while (!finished && !stop_requested()) {
            for (const auto& e : procs.reap()) died += (died.empty() ? "" : "; ") + e.describe();
            std::this_thread::sleep_for(std::chrono::milliseconds(100));
          }
        });
        o = fly_task(gs, rec.drones, task, nullptr);
        finished = true;
        watchdog.join();
        procs.stop_all(3.0);
      }
      rec.ok = o.ok && died.empty();
      rec.failure_reason = !died.empty() ? died : o.reason;
      rec.task_time_s = o.ok ? o.task_time_s : std::nan("");
      rec.wall_time_s = wall_seconds() - run_start;
      rec.collisions_obstacle = o.collisions_obstacle;
      rec.collisions_drone = o.collisions_drone;
      rec.collisions_ground = o.collisions_ground;
      rec.min_inter_drone_m = o.min_inter_drone_m;
      rec.min_clearance_m = o.min_clearance_m;
      append_csv(csv, rec);
      records.push_back(rec);
      ++done;
      if (!rec.ok) ++failed;
      out << "  " << (rec.ok ? o.line() : "FAILED: " + rec.failure_reason) << std::endl;
    }
  }
  auto summary = summarize(records);
  const std::string table = markdown_table(summary);
  {
    std::ofstream f(opt.out_dir + "/" + slug(cfg.name) + ".md");
    f << "# " << cfg.name << "\n\n" << table << "\n";
  }
  out << "\n" << table << "\n";
  try {
    write_plots(records, opt.out_dir + "/plots");
    out << "plots: " << opt.out_dir << "/plots\n";
  } catch (const std::exception& e) {
    out << "plots not written: " << e.what() << "\n";
  }
  out << fmt::format("{} runs, {} failed, {} wall; CSV {}\n", done, failed, clock(wall_seconds() - t0), csv);
  return failed == 0 && done == total ? 0 : 1;
}

}  // namespace ddswarm::gs
