#pragma once
// The agent process: one drone's brain. It turns what it receives over DDS
// (its state and scan, peers, mission commands) into a velocity command.
// An agent host runs many drones' brains in one process (one participant,
// one SwarmState sample per tick for all of them); each brain still sees only
// what its drone would receive and keeps its own mission and peer state.
#include <memory>
#include <string>
#include <vector>

#include "agent/agent_app_config.hpp"
#include "agent/join_watch.hpp"

namespace ddswarm::agent {

/// Raised when another live agent already flies this drone id.
class DuplicateAgent : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class AgentApp {
 public:
  /// Joins DDS and checks that no other agent flies this drone (throws DuplicateAgent).
  explicit AgentApp(AgentAppConfig cfg);
  ~AgentApp();
  using End = JoinEnd;
  /// Runs until stop_requested() or duration_s of wall time (<= 0: forever):
  /// kStopped. kRejoinRequested on take_rejoin_request() (SIGUSR1),
  /// kOutlivedLease when this process was stopped or starved for longer than
  /// its DDS lease (dds.lease_duration_s), so its peers may have dropped it,
  /// or the end that why_join_again() gives (kUnheard, kDeaf,
  /// kHandshakeStall, kNoScene): the caller should destroy this app and join
  /// again.
  End run(double duration_s);
  /// Whether this participant has heard the server's scene.
  bool heard_scene() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ddswarm::agent
