#include "launcher/launch.hpp"

#include <fmt/format.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <thread>

#include "common/agent_rejoin.hpp"
#include "common/cli_checks.hpp"
#include "common/config_error.hpp"
#include "common/participant.hpp"
#include "common/process.hpp"
#include "common/scenario.hpp"
#include "common/scenario_overrides.hpp"
#include "common/scene.hpp"
#include "common/topics.hpp"
#include "ground_station/gs_file_config.hpp"
#include "launcher/preflight.hpp"

namespace ddswarm::gs {

namespace {

/// ground_station.discovery_timeout_s in a swarm for which the launcher starts
/// a discovery server, unless its scenario names one. A ground station that
/// hears no server through a discovery server joins again after 20 s; at the
/// default 10 s it would give up first. Restarted after a crash, the
/// discovery server knows a participant again only when that participant's
/// lease of the old one lapses (docs/faults.md), and a ground station that
/// joined meanwhile needs its own re-join.
constexpr double kDiscoveryServerGsTimeoutS = 60.0;

std::vector<std::string> words(const std::string& s) {
  std::vector<std::string> w;
  std::stringstream ss(s);
  std::string x;
  while (ss >> x) w.push_back(x);
  return w;
}

}  // namespace

void add_launch_command_line(CLI::App& app, LaunchCommandLine& cl) {
  app.add_option("scenario", cl.scenario, "scenario YAML")->required();
  app.add_option("--drones", cl.drones, "number of drones (overrides the scenario)");
  app.add_option("--mode", cl.mode, "lockstep | realtime")
      ->check(CLI::IsMember({"lockstep", "realtime"}));
  app.add_option("--seed", cl.seed, "scenario seed");
  app.add_option("--only", cl.only, "start only: server | agents | all")
      ->check(CLI::IsMember({"server", "agents", "all"}));
  app.add_option("--ids", cl.ids_text, "agents to start, e.g. 3-5,7 (default: all)");
  app.add_option("--agent-hosts", cl.agent_hosts,
                 "fly the agents in K agent-host processes (ddswarm-agent --ids) instead of one "
                 "process per drone")
      ->check(CLI::Range(1, 1024));
  app.add_option("--on-death", cl.on_death,
                 "when a process dies: stop (stop everything, exit 1) | keep (report, keep "
                 "flying) | restart (start a crashed agent again, up to 3 times each; it "
                 "rejoins the mission in force; anything else that dies stops everything)")
      ->check(CLI::IsMember({"stop", "keep", "restart"}));
  app.add_option(
      "--gs", cl.gs_script,
      "ground-station commands to run once every agent is online (waited for up to 30 s plus "
      "1.5 agent.rejoin_after_s, 90 s by default), e.g. \"takeoff --wait; task\"; "
      "everything stops when they finish");
  app.add_flag("--gs-interactive", cl.gs_interactive, "open the ground-station console here");
  app.add_flag("--check", cl.check,
               "check the scenario, with --set and the other options, as every process this "
               "launch would start reads it; print one line and exit (0: valid, 2: the error); "
               "starts nothing");
  app.add_option("--log-dir", cl.log_dir,
                 "write each process's log to DIR/<name>.log instead of the terminal");
  app.add_option("--duration", cl.duration_s, "stop everything after this many wall seconds")
      ->check(finite_range(0.0, 1e9));
  app.add_option("--record", cl.record_dir, "record the run's DDS traffic to DIR/run-<time>.mcap");
  app.add_option(
      "--set", cl.sets,
      "override a scenario key for this run, e.g. --set comm.latency_s=0.3 (repeatable)");
  add_dds_options(app, cl.dds_cli);
  // The launcher's own --discovery-server: it may run the server itself.
  app.remove_option(app.get_option("--discovery-server"));
  app.add_option(
         "--discovery-server", cl.ds_text,
         fmt::format("Fast DDS discovery server: auto (start one on 127.0.0.1 above {} drones), "
                     "on (always start one), off, or IP:PORT of a running one",
                     kAutoDiscoveryServerAbove))
      ->group("Networking (default: this machine only)");
}

std::vector<std::string> split_script(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string part;
  while (std::getline(ss, part, ';')) {
    auto a = part.find_first_not_of(" \t");
    if (a == std::string::npos) continue;
    out.push_back(part.substr(a, part.find_last_not_of(" \t") - a + 1));
  }
  return out;
}

double agents_wait_s(const std::string& scenario, int drones, bool secure) {
  // A fixed 30 s would give up on an agent cut off at start-up that comes
  // back at 40-60 s (mp_comm_task).
  const double rejoin_after = rejoin_after_for(scenario_rejoin_after_s(scenario), drones, secure);
  return 30.0 + std::max(longest_scene_wait_s(rejoin_after), 0.0);
}

LaunchApp::LaunchApp(const CLI::App& app, LaunchCommandLine cl)
    : cl_(std::move(cl)), user_scenario_(cl_.scenario) {
  const auto sets = parse_set_options(cl_.sets);
  if (app.count("--participant-id"))
    throw FieldError(
        "--participant-id", app.get_option("--participant-id")->as<std::string>(),
        "names one process; the launcher starts many (see docs/networking.md, large swarms)");
  // The user's file alone first: its syntax errors name it. Errors found in
  // its copy are told by where their field came from (origin_).
  const YamlDocument user = YamlDocument::load_file(user_scenario_);
  origin_.file = user_scenario_;
  origin_.lines = key_lines(user.root());
  std::map<std::string, std::string> typed;  // key -> its last --set, as typed
  for (const auto& text : cl_.sets) typed[text.substr(0, text.find('='))] = "--set " + text;
  for (const auto& [key, where] : typed) origin_.overrides.push_back({key, where, true});
  YAML::Node root = user.root();
  if (!sets.empty()) {
    try {
      root = apply_overrides(root, sets);
    } catch (const OverrideError& e) {
      throw ConfigError(typed.at(e.key()) + ": " + e.reason());
    }
    derive(root, "--set overrides");
  }
  auto file = read_gs_config();
  file_dds_ = file.dds;
  dds_ = file.dds;
  merge_cli(dds_, cl_.dds_cli, app);
  n_ = cl_.drones.value_or(file.drones);
  if (n_ < 1 || n_ > 1024) throw FieldError("--drones", std::to_string(n_), "must be in [1, 1024]");
  if (cl_.only != "server") {
    if (cl_.ids_text.empty())
      for (int i = 0; i < n_; ++i) ids_.push_back(i);
    else
      try {
        ids_ = parse_id_ranges(cl_.ids_text, n_);
      } catch (const std::invalid_argument& e) {
        throw FieldError("--ids", cl_.ids_text, e.what());
      }
  }
  try {
    ds_ = parse_discovery_server(cl_.ds_text);
  } catch (const std::invalid_argument&) {
    throw FieldError("--discovery-server", cl_.ds_text, "must be auto, on, off or IPv4:port");
  }
  if (dds_.secure() && (ds_.kind == DiscoveryServerChoice::Kind::kOn ||
                        ds_.kind == DiscoveryServerChoice::Kind::kExternal))
    throw FieldError("--discovery-server", cl_.ds_text,
                     "cannot be used with --secure: Fast DDS 2.9 has no secure discovery server "
                     "(docs/security.md)");
  // Flags every child shares: the domain and the network opt-ins, verbatim.
  if (ds_.kind == DiscoveryServerChoice::Kind::kExternal) {
    dds_args_.push_back("--discovery-server");
    dds_args_.push_back(ds_.address);
  }
  for (const char* opt : {"--domain", "--dds-interface", "--dds-local-ip", "--dds-profiles",
                          "--dds-peers", "--secure"}) {
    if (app.count(opt)) {
      auto* o = app.get_option(opt);
      dds_args_.push_back(opt);
      std::string v;
      for (const auto& r : o->results()) v += (v.empty() ? "" : ",") + r;
      dds_args_.push_back(v);
    }
  }
  // Its value, not just the flag: --best-effort-streams=false must reach the children as false.
  if (app.count("--best-effort-streams"))
    dds_args_.push_back(std::string("--best-effort-streams=") +
                        (cl_.dds_cli.best_effort_streams ? "true" : "false"));
  localhost_discovery_ = file_dds_.discovery == Discovery::kLocalhost &&
                         !app.count("--dds-interface") && !app.count("--dds-peers");
  // The whole swarm with its server (not --ids, --only): agent_command's
  // agents skip their duplicate probe.
  whole_swarm_ = cl_.only == "all" && cl_.ids_text.empty();
  bin_ = Launcher::self_dir();
  // What discovery scales with is participants: with agent hosts, a few.
  // Not under DDS Security: Fast DDS 2.9's discovery server has none.
  const int participants = cl_.agent_hosts > 0 ? std::min<int>(cl_.agent_hosts, n_) + 1 : n_;
  start_ds_ = wants_local_discovery_server(ds_, participants, whole_swarm_,
                                           localhost_discovery_ && !dds_.secure());
  if (start_ds_) {
    const auto for_ds = discovery_server_overrides(root);
    if (!for_ds.empty()) {
      std::string why;
      for (const auto& [key, value] : for_ds) {
        const std::string set = fmt::format("{}: {}", key, value.as<std::string>());
        why += (why.empty() ? "" : ", ") + set;
        origin_.overrides.push_back({key, "ddswarm-launch's " + set + " for its discovery server"});
      }
      derive(apply_overrides(root, for_ds),
             (sets.empty() ? "" : "--set overrides, ") + why + " (a discovery server)");
      (void)read_gs_config();
    }
  }
  // Every process reads the same file: checked as each will read it before
  // any starts, so a bad value is one line here, not one per process.
  check_readers();
  // A launch that runs a server owns its domain on this host while it runs:
  // an experiment passes over it, and a second launch says who has it
  // (common/domain_claim.hpp). Agents alone join a swarm; they claim nothing.
  if (cl_.only != "agents" && !cl_.check) {
    claim_.emplace(dds_.domain_id);
    if (!claim_->held())
      throw FieldError(
          app.count("--domain") ? "--domain" : "dds.domain_id", std::to_string(dds_.domain_id),
          "claimed on this host by " + claim_->holder() +
              "; two swarms on one domain take each other's commands, so choose another");
  }
  if (!why_.empty() && !cl_.check)
    std::cerr << "ddswarm-launch: scenario with " << why_ << " written to " << cl_.scenario
              << (copy_.path().empty() ? "" : " (removed at exit)") << "\n";
}

bool LaunchApp::stopping() const { return stop_ || stop_requested(); }

RemovedAtExit::~RemovedAtExit() {
  std::error_code ec;
  if (!path_.empty()) std::filesystem::remove(path_, ec);
}

void LaunchApp::derive(const YAML::Node& scenario, const std::string& why) {
  // In the log directory it stays with the run's logs, as the record of what
  // every process read; elsewhere it is removed at exit.
  std::string path;
  if (cl_.log_dir.empty()) {
    path = (std::filesystem::temp_directory_path() /
            ("ddswarm-scenario-" + std::to_string(getpid()) + ".yaml"))
               .string();
    copy_.set(path);
  } else {
    std::filesystem::create_directories(cl_.log_dir);
    path = cl_.log_dir + "/scenario-" + std::to_string(getpid()) + ".yaml";
  }
  // Mesh files are named relative to the user's scenario, not to the copy.
  YAML::Node derived = YAML::Clone(scenario);
  anchor_mesh_files(derived, std::filesystem::path(user_scenario_).parent_path().string());
  std::ofstream f(path);
  f << "# " << user_scenario_ << " with " << why << "\n" << YAML::Dump(derived) << "\n";
  if (!f) throw std::runtime_error("cannot write " + path);
  cl_.scenario = path;
  why_ = why;
}

std::map<std::string, YAML::Node> LaunchApp::discovery_server_overrides(
    const YAML::Node& root) const {
  // A longer lease for the swarm's own participants, unless the scenario
  // names one: under a 128-process bring-up the discovery server, short of
  // CPU, drops datagrams, and at the default 3 s it lets the server's lease
  // lapse and loses it for good (docs/performance.md).
  // And ground stations patient enough for their own re-join through it
  // (ground_station/subcommands.cpp: after 20 s without a server), which also
  // carries them over a restart of the discovery server (docs/faults.md).
  // And no shared-memory transport, unless the scenario names it: a
  // sender opening a peer's port waits a third of dds.shm_health_check_s
  // (3.3 s) whenever the port's idle listener was just checked, with
  // every send of its participant held. In 128-process bring-ups the
  // server stalls 10-20 s that way and loses up to 119 of 128 agents;
  // over UDP (the swarm state still by data-sharing) it does not
  // (docs/dds.md).
  std::map<std::string, YAML::Node> for_ds;
  auto unless_named = [&](const char* section, const char* key, const YAML::Node& value) {
    if (!(root.IsMap() && root[section] && root[section].IsMap() && root[section][key]))
      for_ds[fmt::format("{}.{}", section, key)] = value;
  };
  unless_named("dds", "lease_duration_s", YAML::Node(kDiscoveryServerLeaseS));
  unless_named("dds", "shm_transport", YAML::Node(false));
  unless_named("ground_station", "discovery_timeout_s", YAML::Node(kDiscoveryServerGsTimeoutS));
  return for_ds;
}

GsFileConfig LaunchApp::read_gs_config() const {
  try {
    return load_gs_config(cl_.scenario);
  } catch (const ConfigError& e) {
    throw ConfigError(explain_scenario_error(e.what(), derived_path(), origin_));
  }
}

std::string LaunchApp::derived_path() const {
  return cl_.scenario == user_scenario_ ? "" : cl_.scenario;
}

std::vector<std::string> LaunchApp::server_args() const {
  std::vector<std::string> a = {bin_ + "/ddswarm-sim", "--scenario", cl_.scenario, "--drones",
                                std::to_string(n_)};
  if (cl_.mode) {
    a.push_back("--mode");
    a.push_back(*cl_.mode);
  }
  if (cl_.seed) {
    a.push_back("--seed");
    a.push_back(std::to_string(*cl_.seed));
  }
  a.insert(a.end(), dds_args_.begin(), dds_args_.end());
  return a;
}

std::vector<ChildSpec> LaunchApp::agent_specs() const {
  // Agent hosts: K processes, each flying a contiguous share of the ids.
  std::vector<ChildSpec> specs;
  const auto shares = agent_host_shares(ids_, cl_.agent_hosts);
  for (std::size_t h = 0; h < shares.size(); ++h)
    specs.push_back({"agent host " + std::to_string(h), agent_args(shares[h], true)});
  for (int id : cl_.agent_hosts > 0 ? std::vector<int>{} : ids_) {
    auto a = agent_args(std::to_string(id), false);
    if (const int pid = agent_participant_id(n_, id); pid >= 0) {
      a.push_back("--participant-id");
      a.push_back(std::to_string(pid));
    }
    specs.push_back({"agent " + std::to_string(id), a});
  }
  return specs;
}

void LaunchApp::check_readers() const {
  // The server and one agent as they will start (the others differ in their
  // id alone, which this launcher checked); the ground station's reader ran
  // in read_gs_config. Every section of the scenario has one of the three
  // as its reader (common/scenario.cpp, check_sections).
  std::vector<ChildSpec> checks;
  if (cl_.only != "agents") checks.push_back({"sim check", server_args()});
  if (const auto agents = agent_specs(); !agents.empty()) checks.push_back(agents.front());
  for (auto& c : checks) c.argv.push_back("--check");
  const std::string error = first_check_error(checks);
  if (!error.empty()) throw ConfigError(explain_scenario_error(error, derived_path(), origin_));
}

std::string LaunchApp::check_summary() const {
  std::string with;
  for (const auto& text : cl_.sets) with += (with.empty() ? " with --set " : ", --set ") + text;
  std::vector<std::string> readers;
  if (cl_.only != "agents") readers.push_back("the server");
  if (!ids_.empty())
    readers.push_back(cl_.agent_hosts > 0
                          ? fmt::format("{} agent host(s) of {} drones",
                                        std::min<int>(cl_.agent_hosts, ids_.size()), ids_.size())
                          : fmt::format("{} agent(s)", ids_.size()));
  readers.push_back("the ground station");
  std::string as;
  for (std::size_t i = 0; i < readers.size(); ++i)
    as += (i == 0 ? "" : i + 1 == readers.size() ? " and " : ", ") + readers[i];
  return fmt::format("ddswarm-launch: ok: {}{} is valid as {} will read it ({} drones)",
                     user_scenario_, with, as, n_);
}

int LaunchApp::run() {
  if (cl_.check) {
    std::cout << check_summary() << std::endl;
    return 0;
  }
  if (stopping()) return 0;  // a signal while the scenario was checked: nothing started
  death_policy_.emplace(parse_on_death(cl_.on_death));
  procs_.emplace(cl_.gs_interactive && cl_.log_dir.empty() ? "ddswarm-logs" : cl_.log_dir);
  if (start_ds_) start_discovery_server();
  if (!cl_.record_dir.empty()) start_recorder();
  if (cl_.only != "agents") start_server();
  if (!cl_.record_dir.empty() && cl_.only != "agents") wait_for_recorder();
  warn_about_participant_ids();
  start_agents();
  std::cerr << fmt::format("ddswarm-launch: started {} process(es); policy on death: {}\n",
                           procs_->running(), cl_.on_death);
  const int rc = supervise();
  if (death_policy_->stop()) std::cerr << "ddswarm-launch: a process died; stopping everything\n";
  // A clean shutdown is exit code 0 after our SIGTERM; anything else is worth saying.
  for (const auto& e : procs_->stop_all(3.0))
    if ((e.signal != 0 && e.signal != SIGTERM) || (e.signal == 0 && e.exit_code != 0))
      std::cerr << "ddswarm-launch: at shutdown " << e.describe() << "\n";
  std::cerr << "ddswarm-launch: all processes stopped\n";
  if (rc != 0) return 1;
  return death_policy_->stop() ? 1 : 0;
}

void LaunchApp::start_discovery_server() {
  // First, so every participant finds it; clients retry until it answers.
  const int port = free_udp_port();
  const ChildSpec ds_spec = discovery_server_spec(port);
  procs_->start(ds_spec);
  death_policy_->always_restart(ds_spec);  // on the same port: the address its clients were given
  procs_->rejoin_dropped_participants("discovery-server");
  // Its overrides of the scenario were written and checked before anything
  // started (discovery_server_overrides).
  const std::string address = "127.0.0.1:" + std::to_string(port);
  dds_args_.push_back("--discovery-server");
  dds_args_.push_back(address);
  std::cerr << "ddswarm-launch: discovery server on " << address
            << " (other tools join with --discovery-server " << address << ")\n";
}

void LaunchApp::start_recorder() {
  // First, so it hears everything; SIGTERM at the end makes it finalize the file.
  std::filesystem::create_directories(cl_.record_dir);
  const std::string out = cl_.record_dir + "/run-" + std::to_string(std::time(nullptr)) + ".mcap";
  std::vector<std::string> a = {bin_ + "/ddswarm-record", "-o", out};
  a.insert(a.end(), dds_args_.begin(), dds_args_.end());
  procs_->start({"record", a, kRecorderMatchedServer});
  std::cerr << "ddswarm-launch: recording to " << out << "\n";
}

void LaunchApp::wait_for_recorder() {
  // The agents start once the recorder hears the server, so the recording
  // holds the whole flight (a lockstep task flies in a second or two).
  if (!procs_->wait_ready("record", kRecorderWaitS) && !stopping())
    std::cerr << fmt::format(
        "ddswarm-launch: warning: the recorder has not matched the server's swarm state "
        "within {:g} s; starting the agents anyway (the recording may miss the start)\n",
        kRecorderWaitS);
}

void LaunchApp::start_server() { procs_->start({"sim", server_args()}); }

void LaunchApp::warn_about_participant_ids() {
  if (cl_.agent_hosts == 0 && !ids_.empty() && agent_participant_id(n_, ids_.back()) < 0 &&
      n_ > kExplicitParticipantIdsAbove)
    std::cerr << fmt::format(
        "ddswarm-launch: warning: {} drones: agents past drone {} get automatic participant "
        "ids, and past ~100 participants per host Fast DDS leaves them unreachable "
        "(dds.participant_id stops at {}; docs/performance.md)\n",
        n_, kMaxParticipantId - kFirstAgentParticipantId, kMaxParticipantId);
  if (cl_.agent_hosts == 0 && !ids_.empty() && agent_participant_id(n_, ids_.front()) >= 0) {
    const std::string w =
        ephemeral_port_warning(dds_.domain_id, agent_participant_id(n_, ids_.front()),
                               agent_participant_id(n_, ids_.back()), ephemeral_port_range());
    if (!w.empty()) std::cerr << "ddswarm-launch: warning: " << w << "\n";
  }
}

std::vector<std::string> LaunchApp::agent_args(const std::string& agent_ids, bool host) const {
  auto a = agent_command(bin_, agent_ids, host, cl_.scenario, whole_swarm_);
  a.insert(a.end(), {"--drones", std::to_string(n_)});
  a.insert(a.end(), dds_args_.begin(), dds_args_.end());
  return a;
}

void LaunchApp::start_agents() {
  for (const auto& spec : agent_specs()) {
    procs_->start(spec);
    death_policy_->restartable(spec);  // what --on-death restart may start again
  }
}

bool LaunchApp::deaths() {
  for (const auto& e : procs_->reap()) {
    std::cerr << "ddswarm-launch: " << e.describe() << "\n";
    if (const auto again = death_policy_->ended(e)) {
      std::cerr << fmt::format("ddswarm-launch: restarting {} ({} of {})\n", e.name,
                               death_policy_->restarts(e.name), kMaxRestarts);
      procs_->start(*again);
    }
  }
  return death_policy_->stop();
}

std::vector<std::string> LaunchApp::gs_argv(const std::vector<std::string>& sub) const {
  std::vector<std::string> a = {bin_ + "/ddswarm-gs", "--config", cl_.scenario};
  a.insert(a.end(), dds_args_.begin(), dds_args_.end());
  a.insert(a.end(), sub.begin(), sub.end());
  return a;
}

int LaunchApp::supervise() {
  int rc = 0;
  if (!cl_.gs_script.empty()) {
    std::vector<std::string> steps = {fmt::format("wait-agents --count {} --timeout {:g}",
                                                  ids_.size(),
                                                  agents_wait_s(cl_.scenario, n_, dds_.secure()))};
    for (const auto& s : split_script(cl_.gs_script)) steps.push_back(s);
    for (const auto& step : steps) {
      if (stopping() || death_policy_->stop()) break;
      std::cerr << "ddswarm-launch: gs " << step << "\n";
      rc = run_foreground(gs_argv(words(step)));
      if (rc != 0) {
        std::cerr << fmt::format("ddswarm-launch: 'ddswarm-gs {}' failed (exit {})\n", step, rc);
        break;
      }
    }
  } else if (cl_.gs_interactive) {
    rc = run_foreground(gs_argv({"menu"}));
  } else {
    double end = cl_.duration_s > 0 ? wall_seconds() + cl_.duration_s : 1e300;
    while (!stopping() && wall_seconds() < end && procs_->running() > 0) {
      if (deaths()) break;
      wait_for_stop(std::chrono::milliseconds(100));
    }
  }
  return rc;
}

int LaunchApp::run_foreground(const std::vector<std::string>& argv) {
  pid_t pid = fork();
  if (pid == 0) {
    unblock_signals_for_exec();
    std::vector<char*> a;
    for (const auto& s : argv) a.push_back(const_cast<char*>(s.c_str()));
    a.push_back(nullptr);
    execv(a[0], a.data());
    _exit(127);
  }
  int status = 0;
  while (waitpid(pid, &status, WNOHANG) == 0) {
    if (deaths()) kill(pid, SIGTERM);
    if (stopping()) kill(pid, SIGINT);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

}  // namespace ddswarm::gs
