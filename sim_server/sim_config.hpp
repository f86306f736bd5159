#pragma once
// The `sim:` section: clocks, time mode behaviour, failsafes, limits.
#include "common/swarm_metrics.hpp"
#include "common/yaml_section.hpp"

namespace ddswarm::sim {

struct SimConfig {
  double physics_rate_hz = 1000;  ///< Hz, fixed physics step rate; a multiple of control_rate_hz
  double control_rate_hz = 50;    ///< Hz, state publish / command rate (one tick)
  double sensor_rate_hz = 50;     ///< Hz, distance-sensor rate; divides control_rate_hz
  double command_timeout_s =
      0.5;  ///< s sim time: a drone without a fresh command hovers (failsafe)
  double failsafe_land_after_s = 5.0;  ///< s in failsafe before the drone lands by itself
  double agent_timeout_s = 1.0;        ///< s wall time: an agent silent this long is lost
  double max_command_speed_mps =
      50.0;                     ///< m/s: commands above are absurd and rejected (within: clamped)
  bool pause_when_idle = true;  ///< lockstep: hold the clock while every agent is idle
  bool lockstep_pipeline =
      false;  ///< lockstep: step physics while agents answer; commands act one tick later
  double realtime_grace =
      0.25;  ///< realtime: wait up to this fraction of a period past its end for late answers
  bool realtime_pipeline =
      false;  ///< realtime: publish on the period's edge, step after; commands act one tick later
  double lockstep_resend_s = 0.25;       ///< s wall, lockstep: publish again if answers are late
  double status_rate_hz = 2.0;           ///< Hz wall, SimStatus publishing
  bool publish_per_drone_topics = true;  ///< also publish keyed DroneState/DistanceScan
  double task_timeout_s = 600.0;         ///< s sim time before a running task fails
  double airborne_height_m = 0.3;        ///< m above ground: counts as airborne
  /// m, swarm metrics: drones this close or closer are linked in the
  /// communication graph (components, λ₂); (0, 100000]
  double metrics_range_m = 10.0;
  /// m centre to centre, swarm metrics: closer is a near miss; (0, 1000]
  double near_miss_m = 1.0;
  /// swarm metrics: λ₂ (O(N³)) only for swarms up to this size; [0, 1024], 0 = never
  int metrics_lambda2_max_drones = 128;

  int substeps() const { return static_cast<int>(physics_rate_hz / control_rate_hz + 0.5); }
  int sensor_every() const { return static_cast<int>(control_rate_hz / sensor_rate_hz + 0.5); }
  /// The swarm metrics' options (the task referee's).
  SwarmMetricsOptions metrics() const;
  void validate() const;
};

void load(YamlSection s, SimConfig& c);

}  // namespace ddswarm::sim
