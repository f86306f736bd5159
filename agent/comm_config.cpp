#include "agent/comm_config.hpp"

#include <algorithm>
#include <cmath>

namespace ddswarm::agent {

bool CommConfig::ideal() const {
  return source == PeerSourceType::kTruth && latency_s == 0.0 && jitter_s == 0.0 &&
         loss_probability == 0.0 && position_noise_sigma_m == 0.0 && max_range_m == 0.0 &&
         !range_measurements && own_position_noise_sigma_m == 0.0;
}

std::uint64_t CommConfig::beacon_period_ticks(double tick_s) const {
  const double ticks = std::round(1.0 / (beacon_rate_hz * tick_s));
  return static_cast<std::uint64_t>(std::max(1.0, ticks));
}

void CommConfig::validate() const {
  check_positive("comm.beacon_rate_hz", beacon_rate_hz);
  if (beacon_rate_hz > 1000.0)
    throw FieldError("comm.beacon_rate_hz", to_text(beacon_rate_hz), "must be <= 1000");
  // Bounded so a delay in ticks can never overflow; a minute is already absurd for a swarm.
  check_range("comm.latency_s", latency_s, 0.0, 60.0);
  check_range("comm.jitter_s", jitter_s, 0.0, 60.0);
  check_range("comm.loss_probability", loss_probability, 0.0, 1.0);
  check_non_negative("comm.position_noise_sigma_m", position_noise_sigma_m);
  check_non_negative("comm.max_range_m", max_range_m);
  check_non_negative("comm.range_noise_sigma_m", range_noise_sigma_m);
  check_non_negative("comm.own_position_noise_sigma_m", own_position_noise_sigma_m);
  check_positive("comm.peer_timeout_s", peer_timeout_s);
  if (source == PeerSourceType::kBeacons && peer_timeout_s < 1.0 / beacon_rate_hz)
    throw FieldError("comm.peer_timeout_s", to_text(peer_timeout_s),
                     "must be >= 1 / beacon_rate_hz (" + to_text(1.0 / beacon_rate_hz) +
                         " s), or every peer drops out between two beacons");
}

void load(YamlSection s, CommConfig& c) {
  s.get_enum("source", c.source,
             {{"truth", PeerSourceType::kTruth}, {"beacons", PeerSourceType::kBeacons}});
  s.get("beacon_rate_hz", c.beacon_rate_hz);
  s.get("latency_s", c.latency_s);
  s.get("jitter_s", c.jitter_s);
  s.get("loss_probability", c.loss_probability);
  s.get("position_noise_sigma_m", c.position_noise_sigma_m);
  s.get("max_range_m", c.max_range_m);
  s.get("range_measurements", c.range_measurements);
  s.get("range_noise_sigma_m", c.range_noise_sigma_m);
  s.get("own_position_noise_sigma_m", c.own_position_noise_sigma_m);
  s.get("peer_timeout_s", c.peer_timeout_s);
  s.get("seed_salt", c.seed_salt);
  s.finish();
}

}  // namespace ddswarm::agent
