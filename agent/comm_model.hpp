#pragma once
// The drone-to-drone communication model: what a receiving drone hears of
// its peers, and when. Pure: no DDS, no clock; time is the lockstep tick.
//
// A CommChannel belongs to one receiving drone. Every message a peer sends
// (its true position from the server, or its beacon) passes through it:
//
//   range     a sender farther than comm.max_range_m (true distance at the
//             send tick) is never heard;
//   loss      dropped with probability comm.loss_probability;
//   noise     N(0, position_noise_sigma_m^2) per axis added to the reported
//             position;
//   range     optional: a UWB-like distance, the true distance at the send
//   meas.     tick plus N(0, range_noise_sigma_m^2), clamped at 0. It is as
//             old as the position it travels with;
//   delay     latency_s + U[0, jitter_s], quantised to ticks:
//             deliver_tick = tick_sent + max(0, round(delay / tick_s)).
//
// Determinism. Every draw is a pure function of (seed, comm.seed_salt,
// receiver id, sender id, tick sent, what is drawn): a counter-based
// generator (SplitMix64), not one shared stream. So the fate of a message
// does not depend on the order messages arrive in (beacons come in DDS order),
// on how many other messages there were, or on which other effects are on:
// switching noise on loses exactly the same messages. Uniforms are built from
// raw 64-bit draws and normals by Box-Muller, not std::*_distribution, whose
// algorithms differ between standard libraries; results are bit-identical
// wherever std::log/sin/cos are (glibc everywhere we run).
#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <tuple>
#include <vector>

#include "agent/comm_config.hpp"
#include "agent/peer_source.hpp"

namespace ddswarm::agent {

/// One message from a peer, as it leaves the sender.
struct PeerMessage {
  int sender = -1;              ///< drone id
  std::uint64_t tick_sent = 0;  ///< lockstep tick it was sent at
  double stamp_s = 0;           ///< s sim time the reported position refers to (sender's clock)
  Eigen::Vector3d reported_p{0, 0, 0};  ///< m ENU, the position the sender reports
  /// m ENU, the sender's true position at tick_sent. Only the model reads it
  /// (range limit, range measurement); it never reaches the law.
  Eigen::Vector3d sender_true_p{0, 0, 0};
};

/// One message as the receiver gets it.
struct Delivered {
  int sender = -1;
  std::uint64_t tick_sent = 0;
  std::uint64_t tick_due = 0;              ///< tick the model delivers it at
  double stamp_s = 0;                      ///< s, the sender's timestamp, unchanged
  Eigen::Vector3d p_world{0, 0, 0};        ///< m ENU, the reported position plus receiver noise
  std::optional<double> measured_range_m;  ///< m, with comm.range_measurements only
};

/// What happened to the messages offered to a channel.
struct CommStats {
  std::uint64_t sent = 0;          ///< offered to send()
  std::uint64_t out_of_range = 0;  ///< dropped: farther than max_range_m
  std::uint64_t lost = 0;          ///< dropped: packet loss
  std::uint64_t delivered = 0;     ///< returned by deliver()
  /// Arrived after its due tick had already been delivered (a beacon slower
  /// through DDS than the model's delay); delivered at the next deliver().
  std::uint64_t late = 0;
};

/// The link into one receiving drone. Deterministic for a given seed.
class CommChannel {
 public:
  /// seed: scenario.seed; receiver_id: this drone; tick_s: control period, > 0.
  /// Throws FieldError if c does not validate, std::invalid_argument on tick_s.
  CommChannel(const CommConfig& c, std::uint64_t seed, int receiver_id, double tick_s);

  /// Offers m to this receiver, whose true position at m.tick_sent is
  /// receiver_true_p. Applies range, loss, noise and delay, and queues it.
  /// min_delay_ticks floors the delay (beacons: 1, see ModelledPeerSource).
  void send(const PeerMessage& m, const Eigen::Vector3d& receiver_true_p,
            std::uint64_t min_delay_ticks = 0);

  /// Removes and returns every queued message due by tick, ordered by due
  /// tick, then sender, then tick sent, then send order.
  std::vector<Delivered> deliver(std::uint64_t tick);

  /// p plus N(0, own_position_noise_sigma_m^2) per axis: this drone's own
  /// position as it knows it at tick. The same tick gives the same value.
  Eigen::Vector3d noisy_own_position(const Eigen::Vector3d& p, std::uint64_t tick) const;

  std::size_t in_flight() const { return queue_.size(); }
  const CommStats& stats() const { return stats_; }
  const CommConfig& config() const { return cfg_; }
  int receiver_id() const { return receiver_; }
  double tick_s() const { return tick_s_; }

 private:
  // deliver tick, sender, tick sent, send sequence: unique, and the delivery order.
  using Key = std::tuple<std::uint64_t, int, std::uint64_t, std::uint64_t>;

  CommConfig cfg_;
  int receiver_;
  double tick_s_;
  std::uint64_t key_;  // hash of (seed, salt, receiver): the root of every draw
  std::map<Key, Delivered> queue_;
  std::uint64_t seq_ = 0;
  std::optional<std::uint64_t> last_delivered_tick_;
  CommStats stats_;
};

/// A PeerSource whose peers come through a CommChannel: from the server's
/// truth (comm.source truth) or from the agents' beacons (comm.source beacons).
///
/// Per tick k, at sim time t, the application calls:
///   set_tick(k, t, own true position);
///   on_truth(t, swarm)             every drone's true position (its own
///                                  skipped); with source truth each one is
///                                  sent through the channel, stamped with
///                                  its sample time;
///   on_beacon(m, ...)              for each beacon received (source beacons;
///                                  ignored with truth, and for our own id);
///   peers(t) / heard(t)            the peers the law may use.
/// With defaults (CommConfig::ideal()) peers(t) equals the truth, bit for bit,
/// at the same tick.
///
/// Each peer's latest message is kept: a message replaces it only when its
/// stamp is newer, so an older one arriving late never wins. A peer whose
/// kept message was heard more than comm.peer_timeout_s ago drops out.
/// Beacons are delayed at least one tick: a beacon sent at tick k cannot be
/// relied on to reach another agent before that agent answers tick k, so
/// delivering it within k would make lockstep runs depend on DDS timing.
class ModelledPeerSource final : public PeerSource {
 public:
  /// seed: scenario.seed; self_id: this drone; tick_s: control period, > 0.
  ModelledPeerSource(const CommConfig& c, std::uint64_t seed, int self_id, double tick_s);

  /// Starts tick `tick` at sim time t; self_true_p is this drone's true
  /// position (m ENU), used for range limits and range measurements of the
  /// truth messages sent this tick. Call before on_truth and peers.
  void set_tick(std::uint64_t tick, double t, const Eigen::Vector3d& self_true_p);

  /// With source truth, sends each other drone's position through the
  /// channel as sent at the current tick. NaN positions are ignored, counted.
  /// A t other than set_tick's starts tick round(t / tick_s) (the server's sim
  /// time is tick × period), keeping the last own position.
  void on_truth(double t, std::span<const PeerObservation> swarm) override;

  /// A beacon heard from another agent (source beacons). receiver_true_p is
  /// this drone's true position at m.tick_sent. Ignored with source truth and
  /// for our own id; a non-finite position is ignored and counted.
  void on_beacon(const PeerMessage& m, const Eigen::Vector3d& receiver_true_p);

  /// Positions (m ENU) of peers heard within comm.peer_timeout_s of t, by id.
  const std::vector<Eigen::Vector3d>& peers(double t) override;

  /// The same peers with ids and the senders' stamps.
  std::vector<PeerObservation> heard(double t);

  /// Measured distance (m) to peer from its kept message; empty without
  /// comm.range_measurements, or if the peer is not heard (as of set_tick's t).
  std::optional<double> range_to(int peer);

  /// Whether this drone publishes a beacon at tick (every beacon period).
  bool beacon_due(std::uint64_t tick) const { return tick % beacon_period_ == 0; }

  /// The beacon this drone publishes at tick, sim time t: its own position as
  /// it knows it (channel().noisy_own_position, the same the law uses).
  PeerMessage beacon(std::uint64_t tick, double t, const Eigen::Vector3d& self_true_p) const;

  const CommChannel& channel() const { return channel_; }
  std::uint64_t rejected() const { return rejected_; }  ///< non-finite inputs ignored

 private:
  struct Kept {
    Delivered msg;
    double heard_s = 0;  // sim time it was delivered
  };
  void update();  // takes what the channel has due at the current tick
  bool fresh(const Kept& k, double t) const { return t - k.heard_s <= cfg_.peer_timeout_s; }

  CommConfig cfg_;
  int self_;
  CommChannel channel_;
  std::uint64_t beacon_period_;
  std::uint64_t tick_ = 0;
  double now_s_ = 0;
  Eigen::Vector3d self_p_{0, 0, 0};
  std::map<int, Kept> kept_;  // by id: a fixed order makes the law's sum deterministic
  std::vector<Eigen::Vector3d> peers_;
  std::uint64_t rejected_ = 0;
};

}  // namespace ddswarm::agent
