#pragma once
// Two servers on one domain would fly one swarm in two worlds: the agents
// follow whichever scene they heard first. One leaves, the other says so
// once and stays:
// - a server that has accepted a mission command never leaves;
// - one that has not leaves when the other's status shows a mission
//   (leaves_for_status), whatever the clocks say;
// - between two that have none, each scene's source timestamp (published
//   once, as the server joins) decides: the newer leaves, even if the other
//   swarm's agents already answer it. Hosts' clocks may differ; by the rules
//   above, a swarm in flight never yields to a newcomer.
// Pure: no DDS, no clock of its own; times are system-clock ns.
#include <cstdint>
#include <vector>

namespace ddswarm::sim {

class RivalArbiter {
 public:
  enum class Move {
    kLeave,       ///< this server yields to the other
    kStayAndSay,  ///< this one stays; the first time: log that the other should leave
    kStay,        ///< this one stays, and said so before
  };
  /// This server's scene went out at published_ns (its source timestamp).
  void published(std::int64_t published_ns) { published_ns_ = published_ns; }
  std::int64_t published_ns() const { return published_ns_; }
  /// Another server's scene, published at other_ns. now_ns stands for this
  /// server's own timestamp while its scene has not gone out yet.
  Move on_scene(std::int64_t other_ns, std::int64_t now_ns, bool mission_begun);
  /// Another server's status, with its drones' mission seqs: true when this one leaves.
  static bool leaves_for_status(bool mission_begun, const std::vector<std::uint32_t>& other_seqs);

 private:
  std::int64_t published_ns_ = 0;
  bool said_ = false;
};

}  // namespace ddswarm::sim
