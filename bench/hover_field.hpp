#pragma once
// Drones hovering at 2 m with their flight controllers closing the loop: the
// physics the benches time (physics_bench) and put between the bare floor's
// ticks (dds_floor --physics-hz). By default N drones on a 2 m grid over a
// staggered pillar field (radius 1 m, 8 m apart, 12 m tall); or a scenario's
// own scene, start positions, airframe and controller.

#include <cstdint>
#include <random>
#include <vector>

#include "common/scene.hpp"
#include "sim_server/flight_controller.hpp"
#include "sim_server/physics_world.hpp"

namespace ddswarm::bench {

/// What a lockstep server computes per control tick: substeps of every
/// drone's controller and physics, then, every sensor_every-th tick, one
/// sensor frame.
struct TickPlan {
  int substeps = 20;
  sim::SensorConfig sensors;
  int sensor_every = 1;
  /// physics_hz / control_hz substeps; config/thesis_course.yaml's sensors
  /// (8 rays of 6 m) at the control rate.
  static TickPlan at(double physics_hz, double control_hz = 50.0);
};

class HoverField {
 public:
  /// N drones over the pillar field, stock airframe and controller.
  explicit HoverField(int n, double dt = 0.001);
  /// One drone per start position (hovering 2 m above it) in scene.
  HoverField(const SceneConfig& scene, const sim::QuadrotorParams& q,
             const sim::ControllerConfig& c, const std::vector<Eigen::Vector3d>& starts, double dt);

  /// Every drone's controller once, the rotor commands set (no step).
  void control();
  void control_and_step();
  /// Control tick number tick of plan. Returns the share of its rays that hit
  /// something (0 on a tick without a sensor frame).
  double server_tick(const TickPlan& plan, std::uint64_t tick = 0);

  sim::PhysicsWorld& world() { return world_; }

 private:
  double dt_;
  sim::PhysicsWorld world_;
  std::vector<sim::FlightController> fc_;
  sim::VelocitySetpoint sp_;
  std::mt19937_64 rng_{1};
  std::vector<float> range_;
  std::vector<std::uint8_t> hit_;
};

}  // namespace ddswarm::bench
