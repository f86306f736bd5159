#include "sim_server/mission_ring.hpp"

#include "common/mission.hpp"

namespace ddswarm::sim {
namespace {

int command_class(std::uint8_t type) {
  switch (static_cast<MissionType>(type)) {
    case MissionType::kTakeoff:
    case MissionType::kLand:
      return 0;
    case MissionType::kSetDistance:
      return 1;
    case MissionType::kMove:
    case MissionType::kTask:
    case MissionType::kFollowLeader:
    case MissionType::kHold:
      return 2;
    case MissionType::kTeleop:
      return 3;
    case MissionType::kNone:
      break;
  }
  return 4;  // unknown: never defines the mission
}

}  // namespace

void trim_recent(std::deque<msg::MissionCommand>& ring, std::size_t cap) {
  while (ring.size() > cap) {
    auto victim = ring.begin();  // fallback: the oldest
    for (auto it = ring.begin(); it != ring.end(); ++it) {
      const int k = command_class(it->type());
      bool superseded = k == 4;
      for (auto later = it + 1; later != ring.end() && !superseded; ++later)
        superseded = command_class(later->type()) == k;
      if (superseded) {
        victim = it;
        break;
      }
    }
    ring.erase(victim);
  }
}

}  // namespace ddswarm::sim
