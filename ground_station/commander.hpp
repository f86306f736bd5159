#pragma once
// What the ground station's console asks of the swarm.
//
// The menu (menu.hpp) drives a Commander; the DDS implementation sends
// MissionCommands and gathers MissionAcks, tests use a fake. Every call
// blocks until the swarm has answered (or a timeout), and reports the answer
// as one line a user can act on. World frame ENU (x east, y north, z up),
// metres, seconds.
#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace ddswarm::gs {

/// The swarm's answer to one command.
struct CommandResult {
  CommandResult() = default;
  CommandResult(bool accepted, std::string line) : ok(accepted), message(std::move(line)) {}

  bool ok = false;           ///< every addressed drone accepted
  std::string message;       ///< e.g. "6/6 acknowledged", "no ack from drones 3, 5",
                             ///< "rejected by 2: not airborne"
  std::vector<int> missing;  ///< drones that did not answer, for callers that name them
  std::vector<std::pair<int, std::string>> rejected;  ///< drone and its reason, per rejection
};

/// A snapshot of the swarm for the console's status line.
struct SwarmStatus {
  double sim_time_s = 0;        ///< s, simulation time of the latest sample
  double real_time_factor = 0;  ///< sim seconds per wall second (NaN: unknown)
  int drones_online = 0;        ///< drones heard from recently
  int drones_total = 0;         ///< drones in the scenario (ids 0..drones_total-1)
  int airborne = 0;             ///< drones off the ground
  int collisions = 0;           ///< collisions since the simulation started
  std::string mode;             ///< e.g. "lockstep", "realtime"
  std::string task_phase;       ///< e.g. "idle", "hold", "task", "swarm"
  double d_int_m = 0;           ///< m, current wanted inter-drone distance D_int
  /// Hostile or broken samples rejected (never applied) since start, by reason:
  /// the server's SimStatus rejected_* counters, then "agents" (the sum of every
  /// agent's AgentStatus.rejected_samples). Empty when nothing was heard.
  std::vector<std::pair<std::string, std::uint64_t>> rejected;
  int failsafe = 0;  ///< drones in failsafe (agent lost: hovering or landing)
  /// Velocity commands the server applied since start, and (real time) those
  /// that arrived after the step they answered; -1 = no server heard.
  std::int64_t commands_applied = -1;
  std::int64_t commands_late = -1;
  /// Lockstep: ticks the server published again, answers missing (SimStatus.lockstep_resends).
  std::int64_t lockstep_resends = -1;
  std::string task;  ///< the refereed task, e.g. "running 12.0 s, 2/6 past finish"; "" = none
  int drones_server_hears = -1;  ///< drones whose agent the server lists live (-1: no server heard)
  std::string
      laws;  ///< the swarm laws the agents fly, e.g. "4 thesis, 2 vasarhelyi"; "" = none heard
  /// Drones whose law faulted, e.g. "drone 3 (reynolds): threw: ...".
  std::vector<std::string> law_faults;
};

/// The commands of the thesis console (Fig. 9), plus hold and teleop.
/// Implementations may throw std::exception on transport failure; the menu
/// reports it and carries on.
class Commander {
 public:
  virtual ~Commander() = default;

  /// Climb to altitude_m above ground and hold; 0 = each agent's default.
  virtual CommandResult takeoff(double altitude_m) = 0;
  /// Fly the swarm at v_enu (m/s) for duration_s, then hold.
  virtual CommandResult move(const Eigen::Vector3d& v_enu, double duration_s) = 0;
  /// Change the wanted inter-drone distance D_int (m, > 0).
  virtual CommandResult set_distance(double d_int_m) = 0;
  /// Descend and stop motors.
  virtual CommandResult land() = 0;
  /// leader_id flies by teleop (teleop()); the others swarm around it.
  virtual CommandResult follow_leader(int leader_id) = 0;
  /// New leader velocity (m/s, ENU) while following.
  virtual CommandResult teleop(const Eigen::Vector3d& v_enu) = 0;
  /// Stop mission motion; keep swarming in place.
  virtual CommandResult hold() = 0;
  /// Start the thesis task at speed_mps; epsilon_m is the swarm-condition
  /// size (0 = agents' default). Returns once the swarm accepted it.
  virtual CommandResult task(double speed_mps, double epsilon_m) = 0;
  /// Blocks until the task started by task() completes or fails, calling
  /// on_progress with one-line progress reports; returns the result line.
  virtual std::string wait_task(std::function<void(const std::string& progress)> on_progress) = 0;
  /// The latest status (never blocks for long).
  virtual SwarmStatus status() = 0;
};

}  // namespace ddswarm::gs
