#include "ground_station/subcommands.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>

#include "common/cli_checks.hpp"
#include "common/config_error.hpp"
#include "common/participant.hpp"
#include "common/process.hpp"
#include "experiment/compare.hpp"
#include "experiment/experiment.hpp"
#include "experiment/report.hpp"
#include "ground_station/growing_wait.hpp"
#include "ground_station/line_reader.hpp"
#include "ground_station/menu.hpp"
#include "ground_station/rejoining_commander.hpp"
#include "ground_station/trace.hpp"
#include "ground_station/web/web_bridge.hpp"

namespace ddswarm::gs {

namespace {

int report(const CommandResult& r) {
  std::printf("%s\n", r.message.c_str());
  return r.ok ? 0 : 1;
}

bool finite_all(std::initializer_list<double> v) {
  for (double x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

}  // namespace

void add_gs_command_line(CLI::App& app, GsCommandLine& cl) {
  app.require_subcommand(0, 1);
  app.add_option("--config", cl.config, "scenario YAML (ground_station, task and dds sections)");
  add_dds_options(app, cl.dds_cli);
  app.add_option("--web", cl.web_addr,
                 "serve the live 3D view at ADDR:PORT (e.g. 127.0.0.1:8080; port 0 = any free one) "
                 "until Ctrl-C");
  app.add_option("--web-root", cl.web_root,
                 "the page's files (default: the source tree's ground_station/web/www)");
  app.add_flag("--web-allow-remote", cl.web_remote,
               "allow --web on a non-loopback address (the page commands the swarm)");
  app.add_option("--web-max-upload-mb", cl.web_upload_mb,
                 "largest recording the page may upload (MiB)");
  app.add_option("--web-duration", cl.web_duration,
                 "with --web: stop after this many wall seconds (0 = until Ctrl-C)");

  cl.menu = app.add_subcommand("menu", "interactive console (the default)");
  auto* wait_agents = cl.wait_agents =
      app.add_subcommand("wait-agents", "wait until the server and N agents are online");
  wait_agents->add_option("--count", cl.wait_count, "agents to wait for (default: all drones)");
  wait_agents->add_option("--timeout", cl.wait_timeout, "seconds")
      ->check(finite_range(0.0, 86400.0));
  auto* takeoff = cl.takeoff = app.add_subcommand("takeoff", "take off and hold");
  takeoff->add_option("--altitude", cl.altitude, "m above ground (0 = agents' default)")
      ->check(finite_range(0.0, 1000.0));
  takeoff->add_flag("--wait", cl.wait_flag, "wait until every drone has reached its altitude");
  auto* move = cl.move = app.add_subcommand("move", "move the swarm by velocity for a time");
  move->add_option("--north", cl.north, "m/s")->check(finite_range(-50.0, 50.0));
  move->add_option("--east", cl.east, "m/s")->check(finite_range(-50.0, 50.0));
  move->add_option("--up", cl.up, "m/s")->check(finite_range(-50.0, 50.0));
  move->add_option("--time", cl.time_s, "s")->required()->check(finite_range(0.0, 86400.0));
  move->add_flag("--wait", cl.wait_flag, "wait until the move's time has passed (sim time)");
  auto* distance = cl.distance =
      app.add_subcommand("distance", "change the inter-drone distance D_int");
  distance->add_option("metres", cl.d_int, "new D_int (m)")
      ->required()
      ->check(finite_range(0.31, 1000.0));
  auto* land = cl.land = app.add_subcommand("land", "land every drone");
  land->add_flag("--wait", cl.wait_flag, "wait until every drone is on the ground");
  auto* hold = cl.hold = app.add_subcommand("hold", "stop mission motion, keep swarming");
  hold->add_option("--time", cl.hold_s,
                   "swarm in place for this many sim seconds (lockstep runs the clock meanwhile)")
      ->check(finite_range(0.0, 86400.0));
  hold->add_flag("--wait", cl.wait_flag, "wait until the time has passed (sim time)");
  auto* follow = cl.follow =
      app.add_subcommand("follow", "follow the leader: the rest swarm around it");
  follow->add_option("--leader", cl.leader, "leader drone id")
      ->required()
      ->check(CLI::Range(0, 1023));
  auto* teleop = cl.teleop =
      app.add_subcommand("teleop", "set the leader's velocity while following");
  teleop->add_option("--north", cl.north, "m/s")->check(finite_range(-50.0, 50.0));
  teleop->add_option("--east", cl.east, "m/s")->check(finite_range(-50.0, 50.0));
  teleop->add_option("--up", cl.up, "m/s")->check(finite_range(-50.0, 50.0));
  auto* task = cl.task =
      app.add_subcommand("task", "run the thesis task (the swarm must be airborne)");
  task->add_option("--speed", cl.speed, "m/s toward the goal (default: task.speed_mps)")
      ->check(finite_range(0.0, 50.0));
  task->add_option("--epsilon", cl.epsilon, "m, swarm condition (default: 2*D_int+1)")
      ->check(finite_range(0.0, 10000.0));
  task->add_flag("--no-wait", cl.no_wait, "return once accepted");
  task->add_flag("--takeoff", cl.fly, "wait for every agent, take off first, then run the task");
  task->add_option("--csv", cl.csv, "append the result to this CSV");
  task->add_flag(
      "--attach", cl.attach,
      "send nothing: report the task the server is refereeing (e.g. after a ground station died)");
  auto* status = cl.status = app.add_subcommand("status", "print the swarm's status");
  status->add_flag("--drones", cl.status_drones,
                   "also print every drone and the pairwise distances");
  auto* trace = cl.trace =
      app.add_subcommand("trace", "write every drone's state to CSV until Ctrl-C or --duration");
  trace->add_option("--out", cl.trace_out, "CSV file")->required();
  trace->add_option("--every", cl.trace_every, "keep one tick in N")->check(CLI::Range(1, 100000));
  trace->add_option("--duration", cl.trace_duration, "wall seconds (0 = until Ctrl-C)")
      ->check(finite_range(0.0, 1e9));
  trace->add_option("--metrics", cl.trace_metrics,
                    "also write the swarm metrics of every traced tick to this CSV");
  trace
      ->add_option("--metrics-range", cl.trace_metrics_range,
                   "m, communication range of the metrics (0 = the scenario's sim.metrics_range_m)")
      ->check(finite_range(0.0, 100000.0));
  auto* experiment = cl.experiment =
      app.add_subcommand("experiment", "run an experiment file (e.g. config/table1.yaml)");
  experiment->add_option("file", cl.exp_file, "experiment YAML")->required();
  experiment->add_option("--out", cl.out_dir, "output directory");
  experiment->add_option("--record", cl.record_dir,
                         "record each run's DDS traffic to DIR/<run>.mcap");
  experiment
      ->add_option(
          "--jobs", cl.jobs,
          "runs at a time, each on a DDS domain of its own (the first free ones from --domain up)")
      ->check(CLI::Range(1, 16));
  experiment
      ->add_option("--agent-hosts", cl.exp_agent_hosts,
                   "each run's agents in K ddswarm-agent --ids processes instead of one per drone "
                   "(the same lockstep results, faster for large swarms)")
      ->check(CLI::Range(0, 1024));
  experiment->add_option("--set", cl.exp_sets,
                         "override a scenario key in every set, over the set's own value, e.g. "
                         "--set sim.physics_rate_hz=250 (repeatable; recorded in the CSV)");

  auto* compare = cl.compare = app.add_subcommand(
      "compare",
      "compare experiment CSVs set by set: means, Welch's t and the Mann-Whitney rank test at "
      "5 %, same-seed runs (no DDS)");
  compare
      ->add_option("files", cl.cmp_files,
                   "the base experiment's CSV, then one or more to compare with it")
      ->required()
      ->check(CLI::ExistingFile);
  compare
      ->add_option("--labels", cl.cmp_labels,
                   "a name per CSV for the table and plot (default: the paths)")
      ->delimiter(',');
  compare->add_option("--plot", cl.cmp_plot,
                      "write DIR/compare.png and .svg: every CSV's mean and spread per set");
  compare->add_flag("--fail-if-different", cl.cmp_fail,
                    "exit 1 when a set's mean differs at the 5 % level (Welch's t; the rank "
                    "test is printed beside it)");
}

int run_gs(CLI::App& app, GsCommandLine& cl) {
  if (*cl.compare)
    return compare_experiments(cl.cmp_files, cl.cmp_labels, cl.cmp_plot, cl.cmp_fail);
  spdlog::set_level(spdlog::level::warn);
  auto file = load_gs_config(cl.config);
  merge_cli(file.dds, cl.dds_cli, app);
  // A ground station is a short-lived process, one per command: over shared
  // memory a new one takes 1.5-3.2 s to hear the server right after another
  // is killed; over loopback UDP, 0.15-0.25 s (docs/configuration.md).
  if (!file.gs.shared_memory) file.dds.shared_memory = false;
  default_security_role(file.dds, "gs");
  validate_with_overrides(cl.config, [&] { file.dds.validate(); });
  install_stop_signals();

  if (!cl.web_addr.empty()) {
    if (!app.get_subcommands().empty())
      throw FieldError("--web", cl.web_addr, "takes no subcommand");
    return serve_web(file, cl.web_addr, cl.web_root, cl.web_remote, cl.web_upload_mb,
                     cl.web_duration, std::filesystem::path(cl.config).parent_path());
  }
  if (*cl.experiment) return experiment_command(file, cl);
  if (*cl.trace) return trace_command(cl.config, file, cl);
  const bool interactive = app.get_subcommands().empty() || *cl.menu;
  // A one-shot command comes and goes; it announces a lease it will not
  // outlive, so that no peer's lease timer for it fires as it leaves: in
  // Fast DDS 2.9.1 that race aborts the peer (kOneShotLeaseS, docs/dds.md).
  if (!interactive) file.dds = one_shot(file.dds);
  // wait-agents --timeout T gives the server T to appear, too: the launcher's
  // and the experiment runner's waits are the ones in force.
  if (*cl.wait_agents)
    file.gs.discovery_timeout_s = std::max(file.gs.discovery_timeout_s, cl.wait_timeout);
  // Status needs only the clock (a replayed recording has no server to command).
  bool ready = false;
  auto commander = join_swarm(file, *cl.status || (*cl.task && cl.attach), ready);
  DdsCommander& gs = *commander;
  if (!ready && !interactive) {
    if (stop_requested()) return 1;  // interrupted while discovering: reported below
    const ServerSearch s = gs.server_search();
    std::fprintf(stderr,
                 "ddswarm-gs: error: no simulation server found on domain %d within %.0f s: %s\n",
                 file.dds.domain_id,
                 file.gs.discovery_timeout_s +
                     (s.state == ServerSearch::State::kComingUp ? kServerComingUpS : 0.0),
                 s.found.c_str());
    return 1;
  }
  if (interactive) return console(std::move(commander), file);
  if (*cl.wait_agents) return wait_agents_command(gs, cl.wait_count, cl.wait_timeout);
  if (*cl.status) return status_command(gs, file, cl.status_drones);
  if (*cl.task) return task_command(gs, file, cl);
  return swarm_command(gs, cl);
}

void append_result(const std::string& csv, const TaskOutcome& o, int drones) {
  if (csv.empty()) return;
  RunRecord rec;
  rec.set_name = o.scenario.empty() ? "cli" : o.scenario;
  rec.seed = o.seed;
  rec.drones = drones;
  rec.speed_mps = o.speed_mps;
  append_csv(csv, with_outcome(std::move(rec), o));
}

int serve_web(const GsFileConfig& file, const std::string& addr, const std::string& root,
              bool remote, double upload_mb, double duration_s,
              const std::filesystem::path& mesh_dir) {
  web::WebBridgeOptions o;
  o.mesh_dir = mesh_dir.empty() ? std::filesystem::path(".") : mesh_dir;
  web::parse_listen_address(addr, o.server);
  o.server.web_root = root.empty() ? web::default_web_root() : std::filesystem::path(root);
  o.server.allow_remote = remote;
  check_range("--web-max-upload-mb", upload_mb, 1.0, 1048576.0);
  o.server.max_upload_bytes = static_cast<std::uint64_t>(upload_mb * (1 << 20));
  check_non_negative("--web-duration", duration_s);
  o.server.validate();
  o.gs = file.gs;
  o.task = file.task;
  o.dds = file.dds;
  o.duration_s = duration_s;
  web::WebBridge bridge(o);
  std::printf("web: serving %s\n", bridge.url().c_str());
  std::fflush(stdout);
  auto counts = bridge.run();
  std::fprintf(stderr, "%s\n", counts.line().c_str());
  return 0;
}

int compare_experiments(const std::vector<std::string>& files, std::vector<std::string> labels,
                        const std::string& plot_dir, bool fail_if_different) {
  if (files.size() < 2)
    throw FieldError("compare", std::to_string(files.size()) + " file", "needs 2 CSVs or more");
  if (labels.empty()) labels = files;
  if (labels.size() != files.size())
    throw FieldError("--labels", std::to_string(labels.size()) + " labels",
                     "needs one per CSV (" + std::to_string(files.size()) + ")");
  std::vector<std::vector<RunRecord>> runs;
  for (const auto& f : files) {
    try {
      runs.push_back(read_csv(f));
    } catch (const std::runtime_error& e) {
      throw ConfigError(e.what());
    }
  }
  bool different = false;
  for (std::size_t i = 1; i < files.size(); ++i) {
    const auto sets = compare_sets(runs[0], runs[i]);
    std::printf("%s against %s:\n\n%s\n", labels[i].c_str(), labels[0].c_str(),
                comparison_table(sets, labels[0], labels[i]).c_str());
    for (const auto& c : sets) different = different || c.significant;
  }
  if (!plot_dir.empty()) {
    std::vector<std::vector<SetSummary>> sums;
    for (const auto& r : runs) sums.push_back(summarize(r));
    std::printf("plot: %s\n", write_comparison_plot(sums, labels, plot_dir, "compare").c_str());
  }
  return fail_if_different && different ? 1 : 0;
}

int experiment_command(const GsFileConfig& file, const GsCommandLine& cl) {
  auto exp = load_experiment_file(cl.exp_file);
  if (!cl.exp_sets.empty()) override_every_set(exp, parse_set_options(cl.exp_sets));
  ExperimentOptions opt;
  opt.out_dir = cl.out_dir;
  opt.dds = file.dds;
  opt.gs = file.gs;
  opt.record_dir = cl.record_dir;
  opt.jobs = cl.jobs;
  opt.agent_hosts = cl.exp_agent_hosts;
  return run_experiment(exp, opt, std::cout);
}

int trace_command(const std::string& config, const GsFileConfig& file, const GsCommandLine& cl) {
  TraceMetrics metrics{cl.trace_metrics, scenario_metrics_options(config)};
  if (cl.trace_metrics_range > 0) metrics.options.range_m = cl.trace_metrics_range;
  SwarmTrace t(file.dds, cl.trace_out, cl.trace_every, metrics);
  t.run(cl.trace_duration);
  std::printf("%ld rows written to %s\n", t.rows(), cl.trace_out.c_str());
  if (!cl.trace_metrics.empty())
    std::printf("%ld rows written to %s\n", t.metrics_rows(), cl.trace_metrics.c_str());
  return 0;
}

std::unique_ptr<DdsCommander> join_swarm(const GsFileConfig& file, bool wait_for_status,
                                         bool& ready) {
  // Give discovery a moment: the server's status is transient-local.
  // Through a discovery server, a participant that hears no server within
  // kToolRejoinAfterS (then twice as long at each try) joins again as a new
  // one: under a 128-process bring-up Fast DDS 2.9's discovery server
  // sometimes drops a participant's endpoints for good, and a ground
  // station's as well as an agent's.
  std::unique_ptr<DdsCommander> commander;
  const bool via_discovery_server = file.dds.discovery == Discovery::kDiscoveryServer;
  ready = false;
  int joins = 0;
  keep_joining(file.gs.discovery_timeout_s, [&](double left) {
    commander.reset();  // the old participant leaves before the new one joins
    commander = std::make_unique<DdsCommander>(file.gs, file.dds);
    const double slice =
        via_discovery_server ? std::min(left, rejoin_patience_s(kToolRejoinAfterS, joins++)) : left;
    ready = wait_for_status ? commander->wait_for_status(slice) : commander->wait_for_server(slice);
    if (ready || stop_requested() || !via_discovery_server || left - slice < 1.0) return false;
    std::fprintf(stderr,
                 "ddswarm-gs: no server heard within %.0f s through the discovery server; joining "
                 "again as a "
                 "new participant\n",
                 slice);
    return true;
  });
  if (!commander)
    commander = std::make_unique<DdsCommander>(file.gs, file.dds);  // stopped before joining
  // A server on its way (its participant discovered, its handshake or its
  // endpoints not through yet) is not "no server": under a secure swarm's
  // bring-up the server may be busy with handshakes for tens of seconds.
  if (!ready && !stop_requested()) {
    const ServerSearch s = commander->server_search();
    if (s.state == ServerSearch::State::kComingUp) {
      std::fprintf(stderr, "ddswarm-gs: %s after %.0f s; waiting up to %.0f s more\n",
                   s.found.c_str(), file.gs.discovery_timeout_s, kServerComingUpS);
      ready = wait_for_status ? commander->wait_for_status(kServerComingUpS)
                              : commander->wait_for_server(kServerComingUpS);
    }
  }
  return commander;
}

int console(std::unique_ptr<DdsCommander> commander, const GsFileConfig& file) {
  LineReader reader(std::cin);
  reader.set_interrupt(stop_requested);
  MenuOptions mo;
  mo.max_speed_mps = file.gs.max_input_speed_mps;
  mo.max_duration_s = file.gs.max_input_time_s;
  mo.default_task_speed_mps = file.task.speed_mps;
  mo.task_epsilon_m = file.task.epsilon_m;
  // Left at its prompt (Ctrl-Z, then fg) for longer than its lease, the
  // console joins again as a new participant before its next command.
  RejoiningCommander rejoining(
      std::move(commander),
      [&file]() -> std::unique_ptr<Commander> {
        auto fresh = std::make_unique<DdsCommander>(file.gs, file.dds);
        fresh->wait_for_server(file.gs.discovery_timeout_s);
        return fresh;
      },
      file.dds.lease_duration_s, std::cerr);
  return run_menu(rejoining, reader, std::cout, mo);
}

int wait_agents_command(DdsCommander& gs, int wait_count, double wait_timeout) {
  // The server's view decides: the next command is another process, which
  // waits for its own connections to the agents (wait_for_server).
  // In slices, saying how far it got: a large or a slow swarm takes a while,
  // and past --timeout it waits on while agents keep coming (GrowingWait).
  constexpr double kProgressS = 10.0;
  const double t0 = wall_seconds();
  GrowingWait wait(t0, wait_timeout, kAgentsGrowingS);
  bool ok = false;
  for (;;) {
    const double left = wait.until_s() - wall_seconds();
    if (left <= 0) break;
    ok = gs.wait_for_online(wait_count, std::min(left, kProgressS));
    if (ok || stop_requested()) break;
    const SwarmStatus now = gs.status();
    const double at = wall_seconds();
    wait.saw(now.drones_server_hears, at);
    if (wait.until_s() - at <= 0) break;
    std::fprintf(stderr,
                 "ddswarm-gs: waiting for agents: the server hears %d of %d after %.0f s (of %g "
                 "s%s)\n",
                 std::max(now.drones_server_hears, 0),
                 wait_count < 0 ? now.drones_total : wait_count, at - t0, wait_timeout,
                 wait.past_timeout(at) ? "; more keep coming" : "");
  }
  const double waited = wall_seconds() - t0;
  auto st = gs.status();
  if (ok) {
    std::printf("%d/%d agents online\n", st.drones_online, st.drones_total);
    return 0;
  }
  // This station may hear agents the server does not: say whose view timed out.
  const int asked = wait_count < 0 ? st.drones_total : wait_count;
  if (st.drones_server_hears < 0)
    std::printf(
        "timed out after %g s: no server heard (this ground station hears %d/%d agents "
        "online)\n",
        wait_timeout, st.drones_online, st.drones_total);
  else
    std::printf(
        "timed out after %s: the server hears %d of the %d agents asked for (this ground "
        "station hears %d/%d online)\n",
        (wait.extended() ? fmt::format("{:.0f} s (--timeout {:g}, then no new agent for {:g} s)",
                                       waited, wait_timeout, kAgentsGrowingS)
                         : fmt::format("{:g} s", wait_timeout))
            .c_str(),
        st.drones_server_hears, asked, st.drones_online, st.drones_total);
  return 1;
}

int status_command(DdsCommander& gs, const GsFileConfig& file, bool status_drones) {
  gs.wait_task_status(file.gs.discovery_timeout_s);  // latched: follows the match when there is one
  // Every live agent's phase, law and law fault, from its heartbeat.
  gs.wait_agent_statuses(std::min(file.gs.discovery_timeout_s, kAgentHeartbeatsWaitS));
  const SwarmStatus st = gs.status();
  std::printf("%s\n%s\n", format_status(st).c_str(), format_rejections(st).c_str());
  if (const std::string c = format_commands(st); !c.empty()) std::printf("%s\n", c.c_str());
  for (const auto& f : st.law_faults) std::printf("law fault: %s\n", f.c_str());
  if (status_drones) {
    auto snap = gs.swarm_snapshot(file.gs.discovery_timeout_s);
    if (!snap) {
      std::fprintf(stderr, "ddswarm-gs: error: no swarm state received within %.0f s\n",
                   file.gs.discovery_timeout_s);
      return 1;
    }
    std::printf("%s", snap->table().c_str());
  }
  return 0;
}

int task_command(DdsCommander& gs, const GsFileConfig& file, const GsCommandLine& cl) {
  TaskConfig t = file.task;
  if (cl.speed > 0) t.speed_mps = cl.speed;
  if (cl.epsilon > 0) t.epsilon_m = cl.epsilon;
  auto progress = [](const std::string& p) {
    std::printf("  %s\n", p.c_str());
    std::fflush(stdout);
  };
  TaskOutcome o;
  if (cl.attach) {
    if (!gs.attach_task(file.gs.discovery_timeout_s)) {
      std::fprintf(stderr, "ddswarm-gs: error: the server reports no task within %.0f s\n",
                   file.gs.discovery_timeout_s);
      return 1;
    }
    auto st = gs.status();
    std::printf("attached: task %s\n", st.task.c_str());
    gs.wait_task(progress);
    o = gs.last_task().value_or(TaskOutcome{});
  } else if (cl.fly) {
    o = fly_task(gs, file.drones, t, progress);
  } else {
    auto r = gs.task(t.speed_mps, t.epsilon_m);
    std::printf("%s\n", r.message.c_str());
    if (!r.ok) return 1;
    if (cl.no_wait) return 0;
    gs.wait_task(progress);
    o = gs.last_task().value_or(TaskOutcome{});
  }
  std::printf("%s\n", o.line().c_str());
  append_result(cl.csv.empty() ? file.gs.results_csv : cl.csv, o, file.drones);
  return o.ok ? 0 : 1;
}

int swarm_command(DdsCommander& gs, const GsCommandLine& cl) {
  if (*cl.takeoff) {
    int rc = report(gs.takeoff(cl.altitude));
    if (rc == 0 && cl.wait_flag && !gs.wait_takeoff_done(gs.status().drones_online, 120)) {
      std::fprintf(stderr, "ddswarm-gs: error: not every drone became airborne within 120 s\n");
      return 1;
    }
    return rc;
  }
  if (*cl.move) {
    if (!finite_all({cl.north, cl.east, cl.up, cl.time_s})) return 2;
    double t0 = gs.status().sim_time_s;
    int rc = report(gs.move(Eigen::Vector3d(cl.east, cl.north, cl.up), cl.time_s));
    if (rc == 0 && cl.wait_flag) gs.wait_sim_time(t0 + cl.time_s, cl.time_s * 100 + 60);
    return rc;
  }
  if (*cl.distance) return report(gs.set_distance(cl.d_int));
  if (*cl.land) {
    int rc = report(gs.land());
    if (rc == 0 && cl.wait_flag && !gs.wait_airborne(0, 120)) return 1;
    return rc;
  }
  if (*cl.hold) {
    double t0 = gs.status().sim_time_s;
    int rc = report(gs.hold_for(cl.hold_s));
    if (rc == 0 && cl.wait_flag && cl.hold_s > 0)
      gs.wait_sim_time(t0 + cl.hold_s, cl.hold_s * 100 + 60);
    return rc;
  }
  if (*cl.follow) return report(gs.follow_leader(cl.leader));
  if (*cl.teleop) return report(gs.teleop(Eigen::Vector3d(cl.east, cl.north, cl.up)));
  return 0;
}

}  // namespace ddswarm::gs
