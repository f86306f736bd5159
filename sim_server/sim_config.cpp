#include "sim_server/sim_config.hpp"

#include <cmath>

namespace ddswarm::sim {

void load(YamlSection s, SimConfig& c) {
  FieldLoader load(s);
  SimConfig::fields(c, load);
  s.finish();
}

namespace {
bool divides(double big, double small) {
  double r = big / small;
  return std::abs(r - std::round(r)) < 1e-9 && std::round(r) >= 1;
}
}  // namespace

void SimConfig::validate() const {
  FieldChecker check("sim");
  fields(*this, check);
  if (!divides(physics_rate_hz, control_rate_hz))
    throw FieldError("sim.control_rate_hz", to_text(control_rate_hz),
                     "must divide physics_rate_hz (" + to_text(physics_rate_hz) + ")");
  if (!divides(control_rate_hz, sensor_rate_hz))
    throw FieldError("sim.sensor_rate_hz", to_text(sensor_rate_hz),
                     "must divide control_rate_hz (" + to_text(control_rate_hz) + ")");
}

}  // namespace ddswarm::sim
