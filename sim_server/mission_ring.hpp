#pragma once
// The ring of recent mission commands carried by every SwarmState.
//
// Agents apply new commands from it, and an agent that (re)joins mid-mission
// learns the current mission from it. So trimming keeps, for each class of
// command, the latest one, which together define the mission in force:
//   altitude  takeoff | land
//   distance  set distance
//   motion    move | task | follow | hold
//   teleop    teleop
// and drops the oldest superseded entries first. Pure.
#include <cstddef>
#include <deque>

#include "MissionCommand.h"

namespace ddswarm::sim {

/// Trims ring (oldest first) to at most cap entries, dropping the oldest
/// command that a later one of its class supersedes; only when none is
/// superseded (cap below the number of classes) the oldest goes.
void trim_recent(std::deque<msg::MissionCommand>& ring, std::size_t cap);

}  // namespace ddswarm::sim
