#include "agent/rejoin_policy.hpp"

#include "common/process.hpp"

#include <algorithm>

namespace ddswarm::agent {

double RejoinPolicy::scene_wait_s() const {
  const double wait = rejoin_patience_s(rejoin_after_s_, no_scene_);
  if (had_scene_ && wait > 0) return std::min(wait, kRejoinedSceneLeases * lease_s_);
  return wait;
}

double handshake_timeout_for(double handshake_timeout_s, int drones) {
  if (handshake_timeout_s <= 0) return 0;
  return std::max(handshake_timeout_s, kHandshakeSecondsPerDrone * drones);
}

double RejoinPolicy::handshake_wait_s() const {
  return rejoin_patience_s(handshake_s_, handshake_stalls_);
}

bool RejoinPolicy::ended(bool cut_off, bool no_scene, bool heard_scene, bool handshake_stall) {
  handshake_stalls_ = handshake_stall ? handshake_stalls_ + 1 : 0;
  const bool rejoined_swarm = had_scene_ && rejoin_after_s_ > 0;
  const bool lost = cut_off || (rejoined_swarm && no_scene);
  no_scene_ = no_scene ? no_scene_ + 1 : 0;
  had_scene_ = heard_scene;
  if (!lost || !shm_) return false;
  shm_ = false;
  return true;
}

}  // namespace ddswarm::agent
