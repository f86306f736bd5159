#pragma once
// Where an agent's knowledge of its peers comes from. The law sees only what
// a PeerSource hands it: positions it could have received, and when.
#include <Eigen/Core>
#include <span>
#include <vector>

namespace ddswarm::agent {

/// One other drone as observed at sim time stamp_s.
struct PeerObservation {
  int id = -1;
  Eigen::Vector3d p_world{0, 0, 0};  ///< m, ENU
  double stamp_s = 0;                ///< s sim time the position refers to
};

class PeerSource {
 public:
  virtual ~PeerSource() = default;
  /// The server's exact positions of the other drones at sim time t.
  virtual void on_truth(double t, std::span<const PeerObservation> others) = 0;
  /// Peer positions this drone may use at sim time t.
  virtual const std::vector<Eigen::Vector3d>& peers(double t) = 0;
};

/// The thesis's source: the simulator's exact positions, no delay.
class TruthPeerSource final : public PeerSource {
 public:
  void on_truth(double, std::span<const PeerObservation> others) override {
    peers_.clear();
    for (const auto& o : others) peers_.push_back(o.p_world);
  }
  const std::vector<Eigen::Vector3d>& peers(double) override { return peers_; }

 private:
  std::vector<Eigen::Vector3d> peers_;
};

}  // namespace ddswarm::agent
