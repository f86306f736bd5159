#include "sim_server/sim_config.hpp"

#include <cmath>

#include "common/scene.hpp"

namespace ddswarm::sim {

void load(YamlSection s, SimConfig& c) {
  s.get("physics_rate_hz", c.physics_rate_hz);
  s.get("control_rate_hz", c.control_rate_hz);
  s.get("sensor_rate_hz", c.sensor_rate_hz);
  s.get("command_timeout_s", c.command_timeout_s);
  s.get("failsafe_land_after_s", c.failsafe_land_after_s);
  s.get("agent_timeout_s", c.agent_timeout_s);
  s.get("max_command_speed_mps", c.max_command_speed_mps);
  s.get("pause_when_idle", c.pause_when_idle);
  s.get("lockstep_pipeline", c.lockstep_pipeline);
  s.get("realtime_grace", c.realtime_grace);
  s.get("realtime_pipeline", c.realtime_pipeline);
  s.get("lockstep_resend_s", c.lockstep_resend_s);
  s.get("status_rate_hz", c.status_rate_hz);
  s.get("publish_per_drone_topics", c.publish_per_drone_topics);
  s.get("task_timeout_s", c.task_timeout_s);
  s.get("airborne_height_m", c.airborne_height_m);
  s.get("metrics_range_m", c.metrics_range_m);
  s.get("near_miss_m", c.near_miss_m);
  s.get("metrics_lambda2_max_drones", c.metrics_lambda2_max_drones);
  s.finish();
}

namespace {
bool divides(double big, double small) {
  double r = big / small;
  return std::abs(r - std::round(r)) < 1e-9 && std::round(r) >= 1;
}
}  // namespace

void SimConfig::validate() const {
  check_range("sim.physics_rate_hz", physics_rate_hz, 50.0, 20000.0);
  check_range("sim.control_rate_hz", control_rate_hz, kMinControlRateHz, kMaxControlRateHz);
  if (!divides(physics_rate_hz, control_rate_hz))
    throw FieldError("sim.control_rate_hz", to_text(control_rate_hz),
                     "must divide physics_rate_hz (" + to_text(physics_rate_hz) + ")");
  check_positive("sim.sensor_rate_hz", sensor_rate_hz);
  if (!divides(control_rate_hz, sensor_rate_hz))
    throw FieldError("sim.sensor_rate_hz", to_text(sensor_rate_hz),
                     "must divide control_rate_hz (" + to_text(control_rate_hz) + ")");
  check_positive("sim.command_timeout_s", command_timeout_s);
  check_non_negative("sim.failsafe_land_after_s", failsafe_land_after_s);
  check_range("sim.agent_timeout_s", agent_timeout_s, 0.1, 60.0);
  check_positive("sim.max_command_speed_mps", max_command_speed_mps);
  check_range("sim.realtime_grace", realtime_grace, 0.0, 0.9);
  check_range("sim.lockstep_resend_s", lockstep_resend_s, 0.005, 10.0);
  check_range("sim.status_rate_hz", status_rate_hz, 0.1, 100.0);
  check_positive("sim.task_timeout_s", task_timeout_s);
  check_positive("sim.airborne_height_m", airborne_height_m);
  check_positive("sim.metrics_range_m", metrics_range_m);
  if (metrics_range_m > 100000.0)
    throw FieldError("sim.metrics_range_m", to_text(metrics_range_m), "must be <= 100000");
  check_positive("sim.near_miss_m", near_miss_m);
  if (near_miss_m > 1000.0)
    throw FieldError("sim.near_miss_m", to_text(near_miss_m), "must be <= 1000");
  check_range("sim.metrics_lambda2_max_drones", metrics_lambda2_max_drones, 0, 1024);
}

SwarmMetricsOptions SimConfig::metrics() const {
  SwarmMetricsOptions o;
  o.range_m = metrics_range_m;
  o.near_miss_m = near_miss_m;
  o.lambda2_max_drones = metrics_lambda2_max_drones;
  return o;
}

}  // namespace ddswarm::sim
