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
  FieldChecker check("comm");
  fields(*this, check);
  if (source == PeerSourceType::kBeacons && peer_timeout_s < 1.0 / beacon_rate_hz)
    throw FieldError("comm.peer_timeout_s", to_text(peer_timeout_s),
                     "must be >= 1 / beacon_rate_hz (" + to_text(1.0 / beacon_rate_hz) +
                         " s), or every peer drops out between two beacons");
}

void load(YamlSection s, CommConfig& c) {
  FieldLoader load(s);
  CommConfig::fields(c, load);
  s.finish();
}

}  // namespace ddswarm::agent
