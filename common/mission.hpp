#pragma once
// Mission commands as plain structs: what the ground station asks of the
// swarm, and what each agent answers. The wire types live in idl/; the
// conversion is in common/convert.
#include <Eigen/Core>
#include <cstdint>
#include <string>

namespace ddswarm {

enum class MissionType : std::uint8_t {
  kNone = 0,
  kTakeoff = 1,       ///< climb to value (m above ground; 0 = agent's default) and hold
  kMove = 2,          ///< fly the swarm at velocity for duration_s, then hold
  kSetDistance = 3,   ///< change D_int to value (m); mode unchanged
  kLand = 4,          ///< descend and stop motors
  kFollowLeader = 5,  ///< leader_id flies velocity (teleop); the rest swarm around it
  kTask = 6,    ///< fly toward the goal at speed value (m/s) until past the finish, then swarm
  kHold = 7,    ///< stop mission motion, keep swarming in place
  kTeleop = 8,  ///< new velocity for the leader during kFollowLeader
};

/// Agent's flight phase, reported in every command and heartbeat.
enum class Phase : std::uint8_t {
  kIdle = 0,  ///< on the ground, motors off
  kTakeoff = 1,
  kHold = 2,  ///< airborne, swarming in place
  kMove = 3,
  kTask = 4,
  kSwarm = 5,  ///< task: past the finish line, gathering
  kFollow = 6,
  kLanding = 7,
  kFailsafe = 8,  ///< no server samples; not commanding
};

const char* to_string(MissionType t);
const char* to_string(Phase p);

struct MissionCommand {
  std::uint32_t seq = 0;  ///< increasing per ground station session
  MissionType type = MissionType::kNone;
  std::int32_t target = -1;           ///< drone id, or -1 for every drone
  Eigen::Vector3d velocity{0, 0, 0};  ///< m/s ENU (kMove, kTeleop)
  double duration_s = 0;              ///< s (kMove)
  double value = 0;             ///< kTakeoff altitude m, kSetDistance D_int m, kTask speed m/s
  std::int32_t leader_id = -1;  ///< kFollowLeader
  double epsilon_m = 0;         ///< kTask swarm-condition size (0 = default)
  std::string issuer;           ///< ground station instance name
};

struct MissionAck {
  std::uint16_t drone_id = 0;
  std::uint32_t seq = 0;
  bool accepted = false;
  std::string reason;          ///< empty when accepted
  Phase phase = Phase::kIdle;  ///< phase after applying
  std::uint64_t tick = 0;      ///< tick at which it was applied
};

}  // namespace ddswarm

namespace ddswarm {
/// Default size epsilon (m) of the task's swarm condition (thesis Eq. 3.1)
/// for inter-drone distance d_int: 2 * D_int + 1 m. Why: six drones under
/// the default linear law settle as a pentagon around a centre drone whose
/// widest pair is ~1.53 D_int; 2 D_int + 1 m stops the timer once the
/// gathering has converged to within about one spacing (agent/swarm_law.hpp).
inline double default_epsilon(double d_int_m) { return 2.0 * d_int_m + 1.0; }
}  // namespace ddswarm
