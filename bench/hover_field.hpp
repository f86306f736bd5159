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
  /// What a lockstep server computes for one control tick: substeps of
  /// controller and physics, then, when rays, one sensor frame (sensors.count
  /// rays per drone). Returns the share of rays that hit something.
  double server_tick(int substeps, const sim::SensorConfig& sensors, bool rays = true);

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
