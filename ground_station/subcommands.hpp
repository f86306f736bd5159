#pragma once
// ddswarm-gs's command line and what each of its subcommands does, one
// function each, so that main (ground_station/main.cpp) only parses, builds
// and runs, and a test can run a subcommand in its own process.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "common/dds_config.hpp"
#include "ground_station/dds_commander.hpp"
#include "ground_station/gs_file_config.hpp"

namespace ddswarm::gs {

/// Everything ddswarm-gs's command line sets, with the defaults --help shows.
struct GsCommandLine {
  std::string config;
  DdsConfig dds_cli;
  // --web
  std::string web_addr, web_root;
  bool web_remote = false;
  double web_upload_mb = 512, web_duration = 0;
  // The subcommands (owned by the CLI::App), null before add_gs_command_line.
  CLI::App *menu = nullptr, *wait_agents = nullptr, *takeoff = nullptr, *move = nullptr,
           *distance = nullptr, *land = nullptr, *hold = nullptr, *follow = nullptr,
           *teleop = nullptr, *task = nullptr, *status = nullptr, *trace = nullptr,
           *experiment = nullptr, *compare = nullptr;
  // wait-agents
  int wait_count = -1;
  double wait_timeout = 30;
  // takeoff, move, land, hold: --wait
  double altitude = 0;
  bool wait_flag = false;
  // move, teleop
  double north = 0, east = 0, up = 0, time_s = 0;
  // distance, hold, follow
  double d_int = 0;
  double hold_s = 0;
  int leader = 0;
  // task
  double speed = 0, epsilon = 0;
  bool no_wait = false, fly = false, attach = false;
  std::string csv;
  // status
  bool status_drones = false;
  // trace
  std::string trace_out;
  int trace_every = 5;
  double trace_duration = 0;
  std::string trace_metrics;
  double trace_metrics_range = 0;
  // experiment
  std::string exp_file, out_dir = "results", record_dir;
  int jobs = 1;
  int exp_agent_hosts = 0;
  std::vector<std::string> exp_sets;
  // compare
  std::vector<std::string> cmp_files, cmp_labels;
  std::string cmp_plot;
  bool cmp_fail = false;
};

/// Adds ddswarm-gs's options and subcommands to app, bound to cl.
void add_gs_command_line(CLI::App& app, GsCommandLine& cl);

/// Runs what a parsed command line asks for; returns the exit code (the
/// console without a subcommand). Throws ConfigError/FieldError on bad input.
int run_gs(CLI::App& app, GsCommandLine& cl);

/// `ddswarm-gs compare`: each CSV after the first against the first; 1 with
/// fail_if_different when a set differs. No DDS.
int compare_experiments(const std::vector<std::string>& files, std::vector<std::string> labels,
                        const std::string& plot_dir, bool fail_if_different);

/// `--web`: serves the live view until SIGINT/SIGTERM (docs/web_view.md);
/// mesh_dir: what a Scene's relative mesh file names are relative to.
int serve_web(const GsFileConfig& file, const std::string& addr, const std::string& root,
              bool remote, double upload_mb, double duration_s,
              const std::filesystem::path& mesh_dir = ".");

/// `ddswarm-gs experiment`.
int experiment_command(const GsFileConfig& file, const GsCommandLine& cl);

/// `ddswarm-gs trace`: config is the scenario (its sim.metrics_range_m).
int trace_command(const std::string& config, const GsFileConfig& file, const GsCommandLine& cl);

/// Appends a task's outcome to the results CSV (nothing when csv is empty).
void append_result(const std::string& csv, const TaskOutcome& o, int drones);

/// Joins the swarm and waits for the server (for its status when
/// wait_for_status), joining again through a discovery server that does not
/// answer; ready says whether it was heard. Never null.
std::unique_ptr<DdsCommander> join_swarm(const GsFileConfig& file, bool wait_for_status,
                                         bool& ready);

/// The interactive console (thesis Fig. 9) on stdin/stdout.
int console(std::unique_ptr<DdsCommander> commander, const GsFileConfig& file);

/// s: past its --timeout, `wait-agents` waits on until no new agent has come
/// for this long (GrowingWait). A secure swarm of 128 agents on 2 cores still
/// gains agents every few seconds 90 s into its bring-up.
inline constexpr double kAgentsGrowingS = 30.0;

/// `ddswarm-gs wait-agents`: count < 0 = every drone. Waits timeout_s, and
/// longer while agents keep coming.
int wait_agents_command(DdsCommander& gs, int count, double timeout_s);

/// `ddswarm-gs status [--drones]`.
int status_command(DdsCommander& gs, const GsFileConfig& file, bool drones);

/// `ddswarm-gs task`.
int task_command(DdsCommander& gs, const GsFileConfig& file, const GsCommandLine& cl);

/// takeoff, move, distance, land, hold, follow, teleop: the one-shot
/// commands; 0 when cl names none of them.
int swarm_command(DdsCommander& gs, const GsCommandLine& cl);

}  // namespace ddswarm::gs
