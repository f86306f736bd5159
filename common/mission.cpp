#include "common/mission.hpp"

namespace ddswarm {

const char* to_string(MissionType t) {
  switch (t) {
    case MissionType::kNone:
      return "none";
    case MissionType::kTakeoff:
      return "takeoff";
    case MissionType::kMove:
      return "move";
    case MissionType::kSetDistance:
      return "distance";
    case MissionType::kLand:
      return "land";
    case MissionType::kFollowLeader:
      return "follow";
    case MissionType::kTask:
      return "task";
    case MissionType::kHold:
      return "hold";
    case MissionType::kTeleop:
      return "teleop";
  }
  return "unknown";
}

const char* to_string(Phase p) {
  switch (p) {
    case Phase::kIdle:
      return "idle";
    case Phase::kTakeoff:
      return "takeoff";
    case Phase::kHold:
      return "hold";
    case Phase::kMove:
      return "move";
    case Phase::kTask:
      return "task";
    case Phase::kSwarm:
      return "swarm";
    case Phase::kFollow:
      return "follow";
    case Phase::kLanding:
      return "landing";
    case Phase::kFailsafe:
      return "failsafe";
  }
  return "unknown";
}

}  // namespace ddswarm
