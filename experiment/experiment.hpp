#pragma once
// Runs the thesis task end to end, once (fly_task) or as an experiment of
// repeated, seeded, real multi-process runs (run_experiment, thesis Table 1).
#include <functional>
#include <ostream>
#include <string>

#include "common/dds_config.hpp"
#include "experiment/experiment_config.hpp"
#include "experiment/report.hpp"
#include "ground_station/dds_commander.hpp"
#include "ground_station/gs_config.hpp"

namespace ddswarm::gs {

/// Waits for `drones` agents, takes off, waits until airborne, starts the
/// task and waits for its result. Failures come back as an outcome with a reason.
/// give_up (optional) ends the wait for the swarm at once, e.g. when a
/// process of the run has died. A swarm not up within swarm_wait_s fails
/// with never_up set.
/// How long an experiment run and fly_task wait for the swarm to come up (s).
inline constexpr double kSwarmWaitS = 30.0;

TaskOutcome fly_task(DdsCommander& gs, int drones, const TaskConfig& task,
                     const std::function<void(const std::string&)>& progress,
                     const std::function<bool()>& give_up = {}, double swarm_wait_s = kSwarmWaitS);

/// The outcome of a swarm that was waited for waited_s and is not up: never_up
/// set, and a reason naming how many agents are online and heard by the
/// server; or, when give_up() says a process of the run ended, that instead.
TaskOutcome swarm_not_up(DdsCommander& gs, int drones, double waited_s,
                         const std::function<bool()>& give_up = {});

/// Times an experiment starts a run whose swarm never came up, before it
/// records the run as failed.
inline constexpr int kRunStarts = 3;
/// Whether to start a run again: its swarm never came up (a discovery
/// failure of Fast DDS, rare but possible: the server hears none of six
/// agents that the ground station hears), no process of it died, and it
/// has starts left. A lockstep run's result depends on its seed alone.
inline bool start_run_again(const TaskOutcome& o, bool a_process_died, int starts) {
  return o.never_up && !a_process_died && starts < kRunStarts;
}

/// rec with a flown task's outcome: ok, failure reason, task and wall time,
/// collisions, clearances and swarm metrics (the task time is NaN on failure).
RunRecord with_outcome(RunRecord rec, const TaskOutcome& o);

struct ExperimentOptions {
  std::string out_dir = "results";  ///< CSV, table, plots, per-run scenarios and logs go here
  DdsConfig dds;                    ///< domain and network of every run
  GroundStationConfig gs;
  std::string bin_dir;     ///< where ddswarm-sim / ddswarm-agent live (default: next to us)
  std::string record_dir;  ///< when set, each run's DDS traffic goes to <record_dir>/<run>.mcap
  int jobs = 1;  ///< runs at a time, each job on a domain of its own from dds.domain_id up
  /// 0: one ddswarm-agent process per drone; K > 0: each run's agents in K
  /// agent-host processes (ddswarm-agent --ids). Lockstep results are the same
  /// to the last digit (mp_agent_host, mp_experiment_short); large swarms fly
  /// several times faster (docs/performance.md).
  int agent_hosts = 0;
};

/// Runs every set's runs (jobs at a time, each on its own domain; a lockstep
/// run's result does not depend on what else runs); returns 0 when every run
/// completed, 1 when some failed (they are recorded with their reason),
/// throws on setup errors. Prints how the wall time split between start-up,
/// flight and teardown.
int run_experiment(const ExperimentConfig& cfg, const ExperimentOptions& opt, std::ostream& out);

}  // namespace ddswarm::gs
