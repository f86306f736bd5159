#pragma once
// Drone-to-drone communication: YAML section `comm`.
//
// Where an agent's peer positions come from (the server's truth, or the
// beacons the agents publish) and what the link does to them on the way to
// each receiving drone: latency and jitter, loss, position noise, a range
// limit, optional noisy range measurements, own-position noise, and a timeout
// after which a silent peer drops out. The model is agent/comm_model.hpp.
// The defaults are ideal: truth, no delay, no loss, no noise, so the thesis
// behaviour is unchanged unless a scenario asks for more.
#include <cstdint>

#include "common/yaml_section.hpp"

namespace ddswarm::agent {

enum class PeerSourceType {
  kTruth,    ///< the server's exact positions, every tick
  kBeacons,  ///< each agent's own estimate, published at beacon_rate_hz
};

struct CommConfig {
  PeerSourceType source = PeerSourceType::kTruth;  ///< truth | beacons
  /// Hz, beacons: how often each agent publishes its state; (0, 1000], and it
  /// must divide the control rate (checked by the application, which knows it).
  double beacon_rate_hz = 10.0;
  double latency_s = 0.0;         ///< s, fixed delay of every message; [0, 60]
  double jitter_s = 0.0;          ///< s, each message waits latency_s + U[0, jitter_s]; [0, 60]
  double loss_probability = 0.0;  ///< chance a message never reaches a given receiver; [0, 1]
  /// m, per axis: Gaussian noise on a received position, drawn per receiver
  /// and per message; >= 0.
  double position_noise_sigma_m = 0.0;
  /// m, a peer farther than this (true distance when it sends) is never
  /// heard; 0 = unlimited; >= 0.
  double max_range_m = 0.0;
  bool range_measurements = false;   ///< UWB-like: a noisy distance comes with each heard message
  double range_noise_sigma_m = 0.1;  ///< m, Gaussian noise on a measured distance; >= 0
  /// m, per axis: GPS-like noise on the drone's own position, as its law sees
  /// it and as its beacons report it; fresh each tick; >= 0.
  double own_position_noise_sigma_m = 0.0;
  /// s (sim), a peer not heard for longer than this drops out of the
  /// repulsion-attraction sum; > 0; beacons: >= 1 / beacon_rate_hz.
  double peer_timeout_s = 1.0;
  std::uint64_t seed_salt = 0;  ///< mixed with scenario.seed: same scenario, other draws

  /// True when the model changes nothing: truth, no delay, loss, noise or
  /// range limit. An application may then keep the plain TruthPeerSource.
  bool ideal() const;

  /// Whole ticks between two beacons at control period tick_s (>= 1).
  std::uint64_t beacon_period_ticks(double tick_s) const;

  void validate() const;  ///< throws FieldError("comm.…")
};

/// Reads section `comm`; unknown keys throw ConfigError with file and line.
/// Does not validate.
void load(YamlSection s, CommConfig& c);

}  // namespace ddswarm::agent
