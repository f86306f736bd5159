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

#include "common/config_fields.hpp"
#include "common/yaml_section.hpp"

namespace ddswarm::agent {

enum class PeerSourceType {
  kTruth,    ///< the server's exact positions, every tick
  kBeacons,  ///< each agent's own estimate, published at beacon_rate_hz
};

struct CommConfig {
  PeerSourceType source = PeerSourceType::kTruth;
  double beacon_rate_hz = 10.0;
  double latency_s = 0.0;
  double jitter_s = 0.0;
  double loss_probability = 0.0;
  double position_noise_sigma_m = 0.0;
  double max_range_m = 0.0;
  bool range_measurements = false;
  double range_noise_sigma_m = 0.1;
  double own_position_noise_sigma_m = 0.0;
  double peer_timeout_s = 1.0;
  std::uint64_t seed_salt = 0;

  /// Every field once: name, unit, bounds, what it does (common/config_fields.hpp).
  template <class Self, class V>
  static void fields(Self& c, V& v) {
    static const Choices<PeerSourceType> kSources{{"truth", PeerSourceType::kTruth},
                                                  {"beacons", PeerSourceType::kBeacons}};
    v.choice(
        "source", c.source, kSources,
        {"", any(),
         "truth: the server's exact positions every tick; beacons: each agent's own estimate"});
    // The application checks that the rate divides the control rate (it knows it).
    v.field("beacon_rate_hz", c.beacon_rate_hz,
            {"Hz", up_to(1000), "how often a drone sends its beacon"});
    // Bounded so a delay in ticks can never overflow; a minute is already absurd for a swarm.
    v.field("latency_s", c.latency_s,
            {"s", in(0, 60), "fixed delay of every message (rounded to ticks)"});
    v.field("jitter_s", c.jitter_s,
            {"s", in(0, 60), "each message waits latency_s + U[0, jitter_s]"});
    v.field("loss_probability", c.loss_probability,
            {"", in(0, 1), "chance a message never reaches a given receiver"});
    v.field("position_noise_sigma_m", c.position_noise_sigma_m,
            {"m", non_negative(),
             "Gaussian noise per axis on a received position, per receiver and message"});
    v.field(
        "max_range_m", c.max_range_m,
        {"m", non_negative(),
         "a peer farther than this (true distance when it sends) is never heard; 0 = unlimited"});
    v.field("range_measurements", c.range_measurements,
            {"", any(), "UWB-like: a noisy distance comes with each heard message"});
    v.field("range_noise_sigma_m", c.range_noise_sigma_m,
            {"m", non_negative(), "Gaussian noise on a measured distance"});
    v.field("own_position_noise_sigma_m", c.own_position_noise_sigma_m,
            {"m", non_negative(),
             "GPS-like noise on the drone's own position, as its law sees it and its beacons "
             "report it"});
    v.field("peer_timeout_s", c.peer_timeout_s,
            {"s (sim)", positive(),
             "a peer not heard for longer drops out of the repulsion-attraction sum"});
    v.field("seed_salt", c.seed_salt,
            {"", any(), "mixed with scenario.seed: same scenario, other draws"});
  }

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
