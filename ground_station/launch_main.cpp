// ddswarm-launch: starts the server and one agent process per drone (and
// optionally ground-station commands), prefixes their logs, supervises them.
#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <thread>

#include "agent/agent_config.hpp"
#include "common/cli_checks.hpp"
#include "common/participant.hpp"
#include "common/process.hpp"
#include "common/scenario.hpp"
#include "ground_station/domain_claim.hpp"
#include "ground_station/experiment_config.hpp"
#include "ground_station/gs_app.hpp"
#include "ground_station/launcher.hpp"

using namespace ddswarm;
using namespace ddswarm::gs;

namespace {

/// ground_station.discovery_timeout_s in a swarm for which the launcher starts
/// a discovery server, unless its scenario names one. A ground station that
/// hears no server through a discovery server joins again after 20 s; at the
/// default 10 s it would give up first. Restarted after a crash, the
/// discovery server knows a participant again only when that participant's
/// lease of the old one lapses (docs/faults.md), and a ground station that
/// joined meanwhile needs its own re-join.
constexpr double kDiscoveryServerGsTimeoutS = 60.0;

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

std::vector<std::string> words(const std::string& s) {
  std::vector<std::string> w;
  std::stringstream ss(s);
  std::string x;
  while (ss >> x) w.push_back(x);
  return w;
}

/// Runs a child in the foreground with this terminal; returns its exit status.
/// deaths() reaps the other children and says whether to stop.
int run_foreground(const std::vector<std::string>& argv, Launcher& procs,
                   const std::function<bool()>& deaths) {
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
    if (stop_requested()) kill(pid, SIGINT);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

/// How long --gs waits for the agents before its first step: the bring-up,
/// plus the longest first join of an agent that heard no scene before it came
/// back as a new participant. A fixed 30 s would give up on an agent cut off
/// at start-up that comes back at 40-60 s (mp_comm_task).
double agents_wait_s(const std::string& scenario) {
  ddswarm::agent::AgentConfig agent;
  try {
    load(load_scenario(scenario).section("agent"), agent);
  } catch (const std::exception&) {
    agent = {};  // the agents name a bad section themselves
  }
  return 30.0 + std::max(agent.longest_scene_wait_s(), 0.0);
}

}  // namespace

int main(int argc, char** argv) {
  const int code = run_main("ddswarm-launch", [&]() -> int {
    CLI::App app{"ddswarm-launch: start the server and one agent process per drone"};
    std::string scenario, only = "all", ids_text, on_death = "stop", gs_script, log_dir;
    std::optional<int> drones;
    std::optional<std::string> mode;
    std::optional<std::uint64_t> seed;
    double duration_s = 0;
    bool gs_interactive = false;
    DdsConfig dds_cli;
    app.add_option("scenario", scenario, "scenario YAML")->required();
    app.add_option("--drones", drones, "number of drones (overrides the scenario)");
    app.add_option("--mode", mode, "lockstep | realtime")->check(CLI::IsMember({"lockstep", "realtime"}));
    app.add_option("--seed", seed, "scenario seed");
    app.add_option("--only", only, "start only: server | agents | all")->check(CLI::IsMember({"server", "agents", "all"}));
    app.add_option("--ids", ids_text, "agents to start, e.g. 3-5,7 (default: all)");
    int agent_hosts = 0;
    app.add_option("--agent-hosts", agent_hosts,
                   "fly the agents in K agent-host processes (ddswarm-agent --ids) instead of one process per drone")
        ->check(CLI::Range(1, 1024));
    app.add_option("--on-death", on_death,
                   "when a process dies: stop (stop everything, exit 1) | keep (report, keep "
                   "flying) | restart (start a crashed agent again, up to 3 times each; it "
                   "rejoins the mission in force; anything else that dies stops everything)")
        ->check(CLI::IsMember({"stop", "keep", "restart"}));
    app.add_option(
        "--gs", gs_script,
        "ground-station commands to run once every agent is online (waited for up to 30 s plus "
        "1.5 agent.rejoin_after_s, 90 s by default), e.g. \"takeoff --wait; task\"; "
        "everything stops when they finish");
    app.add_flag("--gs-interactive", gs_interactive, "open the ground-station console here");
    app.add_option("--log-dir", log_dir, "write each process's log to DIR/<name>.log instead of the terminal");
    app.add_option("--duration", duration_s, "stop everything after this many wall seconds")
        ->check(finite_range(0.0, 1e9));
    std::string record_dir;
    app.add_option("--record", record_dir, "record the run's DDS traffic to DIR/run-<time>.mcap");
    std::vector<std::string> sets;
    app.add_option("--set", sets,
                   "override a scenario key for this run, e.g. --set comm.latency_s=0.3 (repeatable)");
    add_dds_options(app, dds_cli);
    // The launcher's own --discovery-server: it may run the server itself.
    app.remove_option(app.get_option("--discovery-server"));
    std::string ds_text = "auto";
    app.add_option("--discovery-server", ds_text,
                   fmt::format("Fast DDS discovery server: auto (start one on 127.0.0.1 above {} drones), "
                               "on (always start one), off, or IP:PORT of a running one",
                               kAutoDiscoveryServerAbove))
        ->group("Networking (default: this machine only)");
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
      return app.exit(e) == 0 ? 0 : 2;
    }
    // Derives the run's scenario with overrides; every process then reads the same file.
    auto derive = [&](const std::map<std::string, YAML::Node>& overrides, const std::string& why) {
      YAML::Node derived = apply_overrides(YamlDocument::load_file(scenario).root(), overrides);
      const std::string dir = log_dir.empty() ? std::filesystem::temp_directory_path().string() : log_dir;
      std::filesystem::create_directories(dir);
      const std::string path = dir + "/scenario-" + std::to_string(getpid()) + ".yaml";
      std::ofstream(path) << "# " << scenario << " with " << why << "\n" << YAML::Dump(derived) << "\n";
      std::cerr << "ddswarm-launch: scenario with " << why << " written to " << path << "\n";
      scenario = path;
    };
    if (!sets.empty()) {
      derive(parse_set_options(sets), "--set overrides");
    }
    if (app.count("--participant-id"))
      throw FieldError("--participant-id", app.get_option("--participant-id")->as<std::string>(),
                       "names one process; the launcher starts many (see docs/networking.md, large swarms)");
    auto file = load_gs_config(scenario);
    // A launch that runs a server owns its domain on this host while it runs:
    // an experiment passes over it, and a second launch says who has it
    // (ground_station/domain_claim.hpp). Agents alone join a swarm; they claim nothing.
    DdsConfig dds = file.dds;  // the swarm's domain and network: the file, then the flags
    merge_cli(dds, dds_cli, app);
    std::optional<DomainClaim> claim;
    if (only != "agents") {
      claim.emplace(dds.domain_id);
      if (!claim->held())
        throw FieldError(app.count("--domain") ? "--domain" : "dds.domain_id", std::to_string(dds.domain_id),
                         "claimed on this host by " + claim->holder() +
                             "; two swarms on one domain take each other's commands, so choose another");
    }
    const int n = drones.value_or(file.drones);
    if (n < 1 || n > 1024) throw FieldError("--drones", std::to_string(n), "must be in [1, 1024]");
    std::vector<int> ids;
    if (only != "server") {
      if (ids_text.empty())
        for (int i = 0; i < n; ++i) ids.push_back(i);
      else
        try {
          ids = parse_id_ranges(ids_text, n);
        } catch (const std::invalid_argument& e) {
          throw FieldError("--ids", ids_text, e.what());
        }
    }
    DiscoveryServerChoice ds;
    try {
      ds = parse_discovery_server(ds_text);
    } catch (const std::invalid_argument&) {
      throw FieldError("--discovery-server", ds_text, "must be auto, on, off or IPv4:port");
    }
    if (dds.secure() && (ds.kind == DiscoveryServerChoice::Kind::kOn ||
                         ds.kind == DiscoveryServerChoice::Kind::kExternal))
      throw FieldError("--discovery-server", ds_text,
                       "cannot be used with --secure: Fast DDS 2.9 has no secure discovery server "
                       "(docs/security.md)");
    // Flags every child shares: the domain and the network opt-ins, verbatim.
    std::vector<std::string> dds_args;
    if (ds.kind == DiscoveryServerChoice::Kind::kExternal) {
      dds_args.push_back("--discovery-server");
      dds_args.push_back(ds.address);
    }
    for (const char* opt : {"--domain", "--dds-interface", "--dds-local-ip",
                            "--dds-profiles", "--dds-peers", "--secure"}) {
      if (app.count(opt)) {
        auto* o = app.get_option(opt);
        dds_args.push_back(opt);
        std::string v;
        for (const auto& r : o->results()) v += (v.empty() ? "" : ",") + r;
        dds_args.push_back(v);
      }
    }
    // Its value, not just the flag: --best-effort-streams=false must reach the children as false.
    if (app.count("--best-effort-streams"))
      dds_args.push_back(std::string("--best-effort-streams=") + (dds_cli.best_effort_streams ? "true" : "false"));
    const std::string bin = Launcher::self_dir();
    install_stop_signals();
    DeathPolicy death_policy(parse_on_death(on_death));
    Launcher procs(gs_interactive && log_dir.empty() ? "ddswarm-logs" : log_dir);
    const bool localhost_discovery = file.dds.discovery == Discovery::kLocalhost &&
                                     !app.count("--dds-interface") && !app.count("--dds-peers");
    // What discovery scales with is participants: with agent hosts, a few.
    const int participants = agent_hosts > 0 ? std::min<int>(agent_hosts, n) + 1 : n;
    // Not under DDS Security: Fast DDS 2.9's discovery server has none.
    if (wants_local_discovery_server(ds, participants, only == "all" && ids_text.empty(),
                                     localhost_discovery && !dds.secure())) {
      // First, so every participant finds it; clients retry until it answers.
      const int port = free_udp_port();
      const ChildSpec ds_spec = discovery_server_spec(port);
      procs.start(ds_spec);
      death_policy.always_restart(ds_spec);  // on the same port: the address its clients were given
      procs.rejoin_dropped_participants("discovery-server");
      // A longer lease for the swarm's own participants, unless the scenario
      // names one: under a 128-process bring-up the discovery server, short of
      // CPU, drops datagrams, and at the default 3 s it lets the server's lease
      // lapse and loses it for good (docs/performance.md).
      // And ground stations patient enough for their own re-join through it
      // (ground_station/main.cpp: after 20 s without a server), which also
      // carries them over a restart of the discovery server (docs/faults.md).
      // And no shared-memory transport, unless the scenario names it: a
      // sender opening a peer's port waits a third of dds.shm_health_check_s
      // (3.3 s) whenever the port's idle listener was just checked, with
      // every send of its participant held. In 128-process bring-ups the
      // server stalls 10-20 s that way and loses up to 119 of 128 agents;
      // over UDP (the swarm state still by data-sharing) it does not
      // (docs/dds.md).
      const YAML::Node root = YamlDocument::load_file(scenario).root();
      std::map<std::string, YAML::Node> for_ds;
      auto unless_named = [&](const char* section, const char* key, const YAML::Node& value) {
        if (!(root[section] && root[section][key]))
          for_ds[fmt::format("{}.{}", section, key)] = value;
      };
      unless_named("dds", "lease_duration_s", YAML::Node(kDiscoveryServerLeaseS));
      unless_named("dds", "shm_transport", YAML::Node(false));
      unless_named("ground_station", "discovery_timeout_s", YAML::Node(kDiscoveryServerGsTimeoutS));
      if (!for_ds.empty()) {
        std::string why;
        for (const auto& [key, value] : for_ds)
          why += fmt::format("{}{}: {}", why.empty() ? "" : ", ", key, value.as<std::string>());
        derive(for_ds, why + " (a discovery server)");
      }
      const std::string address = "127.0.0.1:" + std::to_string(port);
      dds_args.push_back("--discovery-server");
      dds_args.push_back(address);
      std::cerr << "ddswarm-launch: discovery server on " << address
                << " (other tools join with --discovery-server " << address << ")\n";
    }
    if (!record_dir.empty()) {
      // First, so it hears everything; SIGTERM at the end makes it finalize the file.
      std::filesystem::create_directories(record_dir);
      const std::string out = record_dir + "/run-" + std::to_string(std::time(nullptr)) + ".mcap";
      std::vector<std::string> a = {bin + "/ddswarm-record", "-o", out};
      a.insert(a.end(), dds_args.begin(), dds_args.end());
      procs.start({"record", a});
      std::cerr << "ddswarm-launch: recording to " << out << "\n";
      wait_for_stop(std::chrono::milliseconds(500));
    }
    if (only != "agents") {
      std::vector<std::string> a = {bin + "/ddswarm-sim", "--scenario", scenario, "--drones", std::to_string(n)};
      if (mode) {
        a.push_back("--mode");
        a.push_back(*mode);
      }
      if (seed) {
        a.push_back("--seed");
        a.push_back(std::to_string(*seed));
      }
      a.insert(a.end(), dds_args.begin(), dds_args.end());
      procs.start({"sim", a});
    }
    if (agent_hosts == 0 && !ids.empty() && agent_participant_id(n, ids.back()) < 0 && n > kExplicitParticipantIdsAbove)
      std::cerr << fmt::format("ddswarm-launch: warning: {} drones: agents past drone {} get automatic participant "
                               "ids, and past ~100 participants per host Fast DDS leaves them unreachable "
                               "(dds.participant_id stops at {}; docs/performance.md)\n",
                               n, kMaxParticipantId - kFirstAgentParticipantId, kMaxParticipantId);
    if (agent_hosts == 0 && !ids.empty() && agent_participant_id(n, ids.front()) >= 0) {
      const std::string w =
          ephemeral_port_warning(dds.domain_id, agent_participant_id(n, ids.front()),
                                 agent_participant_id(n, ids.back()), ephemeral_port_range());
      if (!w.empty()) std::cerr << "ddswarm-launch: warning: " << w << "\n";
    }
    // The whole swarm with its server (not --ids, --only): agent_command's
    // agents skip their duplicate probe.
    const bool whole_swarm = only == "all" && ids_text.empty();
    const auto agent_args = [&](const std::string& agent_ids, bool host) {
      auto a = agent_command(bin, agent_ids, host, scenario, whole_swarm);
      a.insert(a.end(), {"--drones", std::to_string(n)});
      a.insert(a.end(), dds_args.begin(), dds_args.end());
      return a;
    };
    // Agent hosts: K processes, each flying a contiguous share of the ids.
    const auto shares = agent_host_shares(ids, agent_hosts);
    const auto start_agent = [&](const ChildSpec& spec) {
      procs.start(spec);
      death_policy.restartable(spec);  // what --on-death restart may start again
    };
    for (std::size_t h = 0; h < shares.size(); ++h)
      start_agent({"agent host " + std::to_string(h), agent_args(shares[h], true)});
    for (int id : agent_hosts > 0 ? std::vector<int>{} : ids) {
      auto a = agent_args(std::to_string(id), false);
      if (const int pid = agent_participant_id(n, id); pid >= 0) {
        a.push_back("--participant-id");
        a.push_back(std::to_string(pid));
      }
      start_agent({"agent " + std::to_string(id), a});
    }
    std::cerr << fmt::format("ddswarm-launch: started {} process(es); policy on death: {}\n",
                             procs.running(), on_death);
    int rc = 0;
    // Reaps the children that ended, applies --on-death, and says whether to stop.
    const auto deaths = [&] {
      for (const auto& e : procs.reap()) {
        std::cerr << "ddswarm-launch: " << e.describe() << "\n";
        if (const auto again = death_policy.ended(e)) {
          std::cerr << fmt::format("ddswarm-launch: restarting {} ({} of {})\n", e.name,
                                   death_policy.restarts(e.name), kMaxRestarts);
          procs.start(*again);
        }
      }
      return death_policy.stop();
    };
    auto gs_argv = [&](const std::vector<std::string>& sub) {
      std::vector<std::string> a = {bin + "/ddswarm-gs", "--config", scenario};
      a.insert(a.end(), dds_args.begin(), dds_args.end());
      a.insert(a.end(), sub.begin(), sub.end());
      return a;
    };
    if (!gs_script.empty()) {
      std::vector<std::string> steps = {fmt::format("wait-agents --count {} --timeout {:g}",
                                                    ids.size(), agents_wait_s(scenario))};
      for (const auto& s : split_script(gs_script)) steps.push_back(s);
      for (const auto& step : steps) {
        if (stop_requested() || death_policy.stop()) break;
        std::cerr << "ddswarm-launch: gs " << step << "\n";
        rc = run_foreground(gs_argv(words(step)), procs, deaths);
        if (rc != 0) {
          std::cerr << fmt::format("ddswarm-launch: 'ddswarm-gs {}' failed (exit {})\n", step, rc);
          break;
        }
      }
    } else if (gs_interactive) {
      rc = run_foreground(gs_argv({"menu"}), procs, deaths);
    } else {
      double end = duration_s > 0 ? wall_seconds() + duration_s : 1e300;
      while (!stop_requested() && wall_seconds() < end && procs.running() > 0) {
        if (deaths()) break;
        wait_for_stop(std::chrono::milliseconds(100));
      }
    }
    if (death_policy.stop()) std::cerr << "ddswarm-launch: a process died; stopping everything\n";
    // A clean shutdown is exit code 0 after our SIGTERM; anything else is worth saying.
    for (const auto& e : procs.stop_all(3.0))
      if ((e.signal != 0 && e.signal != SIGTERM) || (e.signal == 0 && e.exit_code != 0))
        std::cerr << "ddswarm-launch: at shutdown " << e.describe() << "\n";
    std::cerr << "ddswarm-launch: all processes stopped\n";
    if (rc != 0) return 1;
    return death_policy.stop() ? 1 : 0;
  });
  return ddswarm::end_process(code);
}
