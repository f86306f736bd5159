#pragma once
// Where an agent's knowledge of its peers comes from. The law sees only what
// a PeerSource hands it: positions it could have received, and when.
#include <Eigen/Core>
#include <cmath>
#include <span>
#include <vector>

namespace ddswarm::agent {

/// One other drone as observed at sim time stamp_s.
struct PeerObservation {
  int id = -1;
  Eigen::Vector3d p_world{0, 0, 0};  ///< m, ENU
  double stamp_s = 0;                ///< s sim time the position refers to
  /// m/s, ENU; NaN where the source carries no velocity (the communication
  /// model's messages carry positions only).
  Eigen::Vector3d v_world{NAN, NAN, NAN};
};

class PeerSource {
 public:
  virtual ~PeerSource() = default;
  /// The server's exact positions of the swarm's drones at sim time t. The
  /// span may hold this drone's own entry too: a source skips its own id, so
  /// an agent hands every brain the same roster without copying it.
  virtual void on_truth(double t, std::span<const PeerObservation> swarm) = 0;
  /// Peer positions this drone may use at sim time t.
  virtual const std::vector<Eigen::Vector3d>& peers(double t) = 0;
};

/// The thesis's source: the simulator's exact positions, no delay.
class TruthPeerSource final : public PeerSource {
 public:
  /// self_id: this drone, whose own entry is no peer.
  explicit TruthPeerSource(int self_id) : self_(self_id) {}
  void on_truth(double, std::span<const PeerObservation> swarm) override {
    peers_.clear();
    for (const auto& o : swarm)
      if (o.id != self_) peers_.push_back(o.p_world);
  }
  const std::vector<Eigen::Vector3d>& peers(double) override { return peers_; }

 private:
  int self_;
  std::vector<Eigen::Vector3d> peers_;
};

}  // namespace ddswarm::agent
