#pragma once
// Carries mission commands from ground stations to the agents: takes them in
// (DDS threads), releases at most one new one per tick into the ring every
// SwarmState carries (mission_ring.hpp), stamped with the tick it applies
// at. Pure: no DDS, no clock, no I/O; the server calls it with its mutex held.
#include <cstdint>
#include <deque>
#include <optional>
#include <set>
#include <string>
#include <utility>

#include "MissionCommand.h"

namespace ddswarm::sim {

class MissionRelay {
 public:
  /// server_instance: this server's, which a command may be addressed to.
  explicit MissionRelay(std::uint64_t server_instance) : instance_(server_instance) {}

  enum class Intake {
    kNew,        ///< queued for release
    kRepeat,     ///< seen before; queued again so agents acknowledge it again
    kMalformed,  ///< rejected: problem says why
    kStale,      ///< addressed to another server (one that is gone): ignored
  };
  /// A command as it arrives; problem is set for kMalformed.
  Intake take(const msg::MissionCommand& m, std::string& problem);

  /// Tick `tick` goes out: puts the repeats waiting at the front of the queue
  /// into the ring, then releases at most one new command, returned. Repeats
  /// take no slot, so a re-sent command never delays the next one (lockstep
  /// determinism).
  std::optional<msg::MissionCommand> release(std::uint64_t tick);

  /// The ring of recent commands, oldest first.
  const std::deque<msg::MissionCommand>& ring() const { return ring_; }
  /// A mission command (valid, for this server) has come.
  bool begun() const { return !seen_.empty(); }
  /// Commands wait for release.
  bool pending() const { return !pending_.empty(); }
  /// m, the inter-drone distance the last released set-distance command set; 0: none.
  double distance_m() const { return distance_m_; }

 private:
  using Key = std::pair<std::uint64_t, std::uint32_t>;  // issuer instance, seq
  void forward(msg::MissionCommand m, std::uint64_t tick);

  std::uint64_t instance_;
  std::deque<msg::MissionCommand> pending_;
  std::deque<msg::MissionCommand> ring_;
  std::set<Key> seen_;
  std::set<Key> released_;
  double distance_m_ = 0;
};

}  // namespace ddswarm::sim
