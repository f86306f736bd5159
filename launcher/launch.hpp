#pragma once
// ddswarm-launch as an application: its command line (LaunchCommandLine),
// and LaunchApp, which starts the server and one agent process per drone (and
// optionally ground-station commands), prefixes their logs and supervises
// them until they end, --duration passes, a signal or stop().
#include <yaml-cpp/yaml.h>
#include <CLI/CLI.hpp>

#include <atomic>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "common/dds_config.hpp"
#include "common/domain_claim.hpp"
#include "common/scenario_check.hpp"
#include "ground_station/gs_file_config.hpp"
#include "launcher/launcher.hpp"

namespace ddswarm::gs {

/// Everything ddswarm-launch's command line sets, with the defaults --help shows.
struct LaunchCommandLine {
  std::string scenario, only = "all", ids_text, on_death = "stop", gs_script, log_dir;
  std::optional<int> drones;
  std::optional<std::string> mode;
  std::optional<std::uint64_t> seed;
  double duration_s = 0;
  bool gs_interactive = false;
  bool check = false;  ///< --check: check the scenario, start nothing
  int agent_hosts = 0;
  std::string record_dir;
  std::vector<std::string> sets;
  DdsConfig dds_cli;
  std::string ds_text = "auto";  ///< the launcher's own --discovery-server
};

/// Adds ddswarm-launch's arguments and options to app, bound to cl.
void add_launch_command_line(CLI::App& app, LaunchCommandLine& cl);

/// Splits a --gs script at ';', trimming blanks and dropping empty steps.
std::vector<std::string> split_script(const std::string& s);

/// How long --gs waits for the agents before its first step: the bring-up,
/// plus the longest first join of an agent that heard no scene before it came
/// back as a new participant (agent.rejoin_after_s as a swarm of `drones`,
/// secure or not, uses it: rejoin_after_for, common/agent_rejoin.hpp).
double agents_wait_s(const std::string& scenario, int drones, bool secure);

/// A file removed when this goes (a launch's scenario copy outside its log
/// directory): at a normal end, at an error, and after SIGINT or SIGTERM,
/// which end ddswarm-launch through its normal end.
class RemovedAtExit {
 public:
  RemovedAtExit() = default;
  RemovedAtExit(const RemovedAtExit&) = delete;
  RemovedAtExit& operator=(const RemovedAtExit&) = delete;
  ~RemovedAtExit();
  void set(std::string path) { path_ = std::move(path); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

class LaunchApp {
 public:
  /// Checks the parsed command line; writes the run's scenario when --set
  /// (or the discovery server it starts) overrides it; checks that scenario
  /// as every process the launch starts will read it (ddswarm-sim --check,
  /// ddswarm-agent --check, and the ground station's reader); and claims the
  /// domain when it runs a server (not with --check). Starts nothing. Throws
  /// FieldError/ConfigError naming what is wrong as the user typed it: the
  /// --set flag, or the scenario file and its line.
  LaunchApp(const CLI::App& app, LaunchCommandLine cl);
  LaunchApp(const LaunchApp&) = delete;
  LaunchApp& operator=(const LaunchApp&) = delete;

  /// Starts every process, runs --gs or the console or waits, then stops
  /// them all. Returns the exit code: 1 when a process died (policy
  /// permitting) or a --gs step failed. With --check, prints the one-line
  /// summary of the check the constructor passed and returns 0.
  int run();
  /// The one line --check prints: what was checked, as whom.
  std::string check_summary() const;
  /// The scenario every process reads: the user's, or its copy with the overrides.
  const std::string& scenario() const { return cl_.scenario; }
  /// Ends run() from any thread as SIGINT would (the processes are stopped).
  void stop() { stop_ = true; }
  /// A stop was asked for: stop() or a signal (stop_requested()).
  bool stopping() const;

 private:
  /// Writes the run's scenario, the user's with overrides (why says which);
  /// every process then reads that file.
  void derive(const YAML::Node& scenario, const std::string& why);
  /// What a discovery server the launch starts changes in the scenario
  /// (root: the scenario with --set), unless the scenario names it.
  std::map<std::string, YAML::Node> discovery_server_overrides(const YAML::Node& root) const;
  /// The ground station's reading of the run's scenario; errors in the user's terms.
  GsFileConfig read_gs_config() const;
  /// The run's scenario when it is a copy of the user's; "" when it is theirs.
  std::string derived_path() const;
  /// Runs --check of the server and of the first agent as they will start.
  void check_readers() const;
  std::vector<std::string> server_args() const;
  /// The arguments of each agent process (or agent host) the launch starts.
  std::vector<ChildSpec> agent_specs() const;
  void start_discovery_server();
  void start_recorder();
  /// Waits (at most kRecorderWaitS) until the recorder hears the server.
  void wait_for_recorder();
  void start_server();
  void warn_about_participant_ids();
  void start_agents();
  /// Reaps the children that ended, applies --on-death, and says whether to stop.
  bool deaths();
  /// --gs, --gs-interactive, or wait for --duration or the end of every process.
  int supervise();
  std::vector<std::string> agent_args(const std::string& agent_ids, bool host) const;
  std::vector<std::string> gs_argv(const std::vector<std::string>& sub) const;
  /// Runs a child in the foreground with this terminal; returns its exit status.
  int run_foreground(const std::vector<std::string>& argv);

  LaunchCommandLine cl_;
  std::string user_scenario_;  ///< the scenario file the user named
  ScenarioOrigin origin_;      ///< what was written into its copy, to name it in errors
  RemovedAtExit copy_;         ///< the copy, when it is not in the log directory
  std::string why_;            ///< what the copy changes ("" when there is none)
  bool start_ds_ = false;      ///< the launch starts a discovery server
  DdsConfig file_dds_;         ///< the scenario's dds section alone
  DdsConfig dds_;              ///< the swarm's domain and network: the file, then the flags
  std::optional<DomainClaim> claim_;
  int n_ = 0;
  std::vector<int> ids_;
  DiscoveryServerChoice ds_;
  std::vector<std::string> dds_args_;  ///< flags every child shares
  bool localhost_discovery_ = false;
  bool whole_swarm_ = false;
  std::string bin_;
  std::optional<DeathPolicy> death_policy_;
  std::optional<Launcher> procs_;
  std::atomic<bool> stop_{false};
};

}  // namespace ddswarm::gs
