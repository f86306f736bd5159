#pragma once
// The ground station's link to the swarm over DDS: sends mission commands,
// gathers every live agent's acknowledgement, follows status and the task.
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/dds_config.hpp"
#include "common/mission.hpp"
#include "common/swarm_metrics.hpp"
#include "ground_station/commander.hpp"
#include "ground_station/gs_config.hpp"
#include "ground_station/trace.hpp"

namespace ddswarm::msg {
class SwarmState;
}

namespace ddswarm::gs {

/// A finished (or failed) task as the server refereed it.
struct TaskOutcome {
  bool ok = false;
  std::string reason;
  /// failed before the swarm was up (the server never heard every agent):
  /// a start-up failure, not a result of the task
  bool never_up = false;
  double task_time_s = 0;  ///< s sim
  double wall_time_s = 0;  ///< s wall
  double epsilon_m = 0;
  double speed_mps = 0;
  int drones = 0;
  int collisions_obstacle = 0, collisions_drone = 0, collisions_ground = 0;
  double min_inter_drone_m = 0;
  double min_clearance_m = 0;
  std::uint64_t seed = 0;        ///< the scenario's seed (from the server's Scene)
  std::string scenario;          ///< the scenario's name
  std::vector<int> lost_drones;  ///< drones whose agent was lost during the task
  SwarmTaskMetrics metrics;      ///< the task's swarm metrics, as the server gathered them
  std::string line() const;      ///< the one-line result
};

/// What the ground station knows of one agent while it waits for a take-off
/// to end: two words, either of which may be the newer.
struct ClimbWord {
  /// The phase in the agent's latest heartbeat, if that was sent after the
  /// command (in lockstep a whole climb can pass between two heartbeats, so
  /// an older one says nothing).
  std::optional<Phase> heartbeat;
  /// The phase the server relays from the agent's latest answer, if the
  /// server says the agent accepted the command.
  std::optional<Phase> server;
};

/// True once either word has the agent past its climb. A heartbeat sent
/// mid-climb must not outweigh the server's newer word: waiting for the
/// agent's next heartbeat cost a quarter second in half of Table 1's
/// take-offs (docs/performance.md).
bool climb_over(const ClimbWord& w);

/// What a ground station found while it looked for the server: nothing; a
/// secure server still coming up (its participant discovered, its handshake
/// or its endpoints not through yet); a server discovered but unheard with
/// no handshake under way (without DDS Security: a secure swarm's, or one
/// this process cannot reach), which waiting does not mend; or a server it hears.
struct ServerSearch {
  enum class State { kNothing, kComingUp, kUnheard, kHeard };
  State state = State::kNothing;
  std::string found;  ///< one clause for an error line: what was found, what was not
};
/// A server participant discovery announced (RemotePeer, common/participant.hpp).
struct ServerPeer {
  double announced_s;            ///< since its announcement
  double authenticated_after_s;  ///< < 0 while its handshake has not passed
};
/// From the server participants discovered, oldest first, whether DDS
/// Security is on, and whether the server's status was heard.
ServerSearch server_search(const std::vector<ServerPeer>& servers, bool secure, bool status_heard);

/// s: how much longer than its discovery timeout a ground station waits for
/// a server that is coming up (ServerSearch::kComingUp). A secure swarm of
/// 48 agent processes on 2 cores keeps the server busy with handshakes past
/// the default 10 s; a handshake Fast DDS leaves pending for good stops here.
constexpr double kServerComingUpS = 120.0;

/// s: the longest a status waits for the heartbeat of every agent the server
/// hears live (DdsCommander::wait_agent_statuses): a station that has just
/// joined meets the agents one by one, seconds apart on a loaded machine.
constexpr double kAgentHeartbeatsWaitS = 5.0;

class DdsCommander final : public Commander {
 public:
  DdsCommander(const GroundStationConfig& cfg, const DdsConfig& dds);
  ~DdsCommander() override;

  /// Waits until the server is heard, count agents are online both to this
  /// process and in the server's own status (count < 0: as many as the
  /// server's scenario has), and this process's writers and readers are
  /// matched: everything a mission needs before its first command. Returns
  /// false on timeout, or at once when give_up() says so (polled every
  /// 100 ms: e.g. a process of the swarm has died).
  bool wait_for_swarm(int count, double timeout_s, const std::function<bool()>& give_up = {});
  /// Waits until the server is heard and count agents are online in its view
  /// (count < 0: as many as the scenario has), whatever this process hears
  /// itself, and without waiting for its own connections to each agent: for
  /// `wait-agents`, whose process exits right after. Returns false on timeout.
  bool wait_for_online(int count, double timeout_s);
  /// Waits until the server's status is heard, the mission writer is matched,
  /// and a heartbeat has arrived from every agent the server hears.
  bool wait_for_server(double timeout_s);
  /// Waits until a SimStatus arrives (a live server or a replay). False on timeout.
  bool wait_for_status(double timeout_s);
  /// What this process found of the server so far (server_search).
  ServerSearch server_search() const;
  /// Waits until sim time reaches t (s). False on timeout (wall) or stop.
  bool wait_sim_time(double t, double timeout_s);
  /// Waits until `airborne` drones are airborne (or on the ground when 0).
  bool wait_airborne(int count, double timeout_s);
  /// Waits until `count` drones are airborne and no online agent is still
  /// taking off (all reached their altitude). False on timeout.
  bool wait_takeoff_done(int count, double timeout_s);

  CommandResult takeoff(double altitude_m) override;
  CommandResult move(const Eigen::Vector3d& v_enu, double duration_s) override;
  CommandResult set_distance(double d_int_m) override;
  CommandResult land() override;
  CommandResult follow_leader(int leader_id) override;
  CommandResult teleop(const Eigen::Vector3d& v_enu) override;
  CommandResult hold() override { return hold_for(0); }
  /// Holds and swarms in place for duration_s of sim time (the lockstep clock runs meanwhile).
  CommandResult hold_for(double duration_s);
  CommandResult task(double speed_mps, double epsilon_m) override;
  std::string wait_task(std::function<void(const std::string&)> on_progress) override;
  /// Follows the task the server referees now (or last refereed) as if this
  /// ground station had started it, so wait_task() reports it: a new ground
  /// station after the first one died. False when no task is heard in timeout_s.
  bool attach_task(double timeout_s);
  /// Waits until the server's (latched) task status has arrived, if it has
  /// one. False on timeout (e.g. no task was ever run).
  bool wait_task_status(double timeout_s);
  /// Waits up to timeout_s until a heartbeat (AgentStatus) was heard from
  /// every agent the server's latest status lists live (a station that has
  /// just joined meets the agents one by one; a dead agent is not waited
  /// for); false when some were not.
  bool wait_agent_statuses(double timeout_s);
  SwarmStatus status() override;
  /// Every drone as the latest swarm state shows it (the first call waits up
  /// to timeout_s; a new reader gets the server's newest state at once);
  /// nullopt if none came. Read on this ground station's own participant,
  /// already matched with the server: no second join just to look.
  std::optional<SwarmSnapshot> swarm_snapshot(double timeout_s);

  /// Calls read with the latest swarm state newer than after_tick (-1: any),
  /// waiting up to timeout_s for one; false when none came. Shares
  /// swarm_snapshot's reader.
  bool read_swarm_state(double timeout_s, std::int64_t after_tick,
                        const std::function<void(const msg::SwarmState&)>& read);

  /// While on, every blocking call returns as on a stop request (SIGINT),
  /// for a caller that waits on another thread and is interrupted there
  /// (the Python binding: Ctrl-C and per-call timeouts).
  void set_interrupted(bool on);

  /// The last task's outcome, once wait_task() returned.
  std::optional<TaskOutcome> last_task() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ddswarm::gs
