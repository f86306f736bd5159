#pragma once
// The `sim:` section: clocks, time mode behaviour, failsafes, limits.
#include "common/config_fields.hpp"
#include "common/scene.hpp"
#include "common/swarm_metrics.hpp"
#include "common/yaml_section.hpp"

namespace ddswarm::sim {

struct SimConfig {
  double physics_rate_hz = 1000;
  double control_rate_hz = 50;
  double sensor_rate_hz = 50;
  double command_timeout_s = 0.5;
  double failsafe_land_after_s = 5.0;
  double agent_timeout_s = 1.0;
  double max_command_speed_mps = 50.0;
  bool pause_when_idle = true;
  bool lockstep_pipeline = false;
  double lockstep_resend_s = 0.25;
  double realtime_grace = 0.25;
  bool realtime_pipeline = false;
  double status_rate_hz = 2.0;
  bool publish_per_drone_topics = true;
  double task_timeout_s = 600.0;
  double airborne_height_m = 0.3;
  SwarmMetricsOptions metrics_options;  ///< sim.metrics_range_m, near_miss_m, ...

  template <class Self, class V>
  static void fields(Self& c, V& v) {
    v.field("physics_rate_hz", c.physics_rate_hz, {"Hz", in(50, 20000), "fixed physics step rate"});
    v.field("control_rate_hz", c.control_rate_hz,
            {"Hz", in(kMinControlRateHz, kMaxControlRateHz),
             "one tick: state published, one command per drone; divides physics_rate_hz"});
    v.field("sensor_rate_hz", c.sensor_rate_hz,
            {"Hz", positive(), "distance-scan rate; divides control_rate_hz"});
    v.field("command_timeout_s", c.command_timeout_s,
            {"s (sim)", positive(), "a drone without a fresh command hovers (failsafe)"});
    v.field("failsafe_land_after_s", c.failsafe_land_after_s,
            {"s (sim)", non_negative(), "in failsafe this long, the drone lands"});
    v.field("agent_timeout_s", c.agent_timeout_s,
            {"s (wall)", in(0.1, 60), "an agent silent this long is lost"});
    v.field("max_command_speed_mps", c.max_command_speed_mps,
            {"m/s", positive(), "faster commands are rejected; slower ones clamped"});
    v.field("pause_when_idle", c.pause_when_idle,
            {"", any(), "lockstep: hold the clock while every agent is idle"});
    v.field("lockstep_pipeline", c.lockstep_pipeline,
            {"", any(), "lockstep: step physics while agents answer; commands act a tick later"});
    v.field("lockstep_resend_s", c.lockstep_resend_s,
            {"s (wall)", in(0.005, 10), "lockstep: publish again if answers are late"});
    v.field("realtime_grace", c.realtime_grace,
            {"periods", in(0, 0.9), "realtime: wait this fraction of a period for late answers"});
    v.field("realtime_pipeline", c.realtime_pipeline,
            {"", any(), "realtime: publish on the period's edge, step after"});
    v.field("status_rate_hz", c.status_rate_hz, {"Hz (wall)", in(0.1, 100), "SimStatus rate"});
    v.field("publish_per_drone_topics", c.publish_per_drone_topics,
            {"", any(), "also publish keyed DroneState and DistanceScan, for tools"});
    v.field("task_timeout_s", c.task_timeout_s,
            {"s (sim)", positive(), "a running task fails after this much simulated time"});
    v.field("airborne_height_m", c.airborne_height_m,
            {"m", positive(), "above the ground: counts as airborne"});
    SwarmMetricsOptions::sim_fields(c.metrics_options, v);
  }

  int substeps() const { return static_cast<int>(physics_rate_hz / control_rate_hz + 0.5); }
  int sensor_every() const { return static_cast<int>(control_rate_hz / sensor_rate_hz + 0.5); }
  /// The swarm metrics' options (the task referee's).
  const SwarmMetricsOptions& metrics() const { return metrics_options; }
  void validate() const;  ///< the list's bounds, then the rates that must divide
};

void load(YamlSection s, SimConfig& c);

}  // namespace ddswarm::sim
