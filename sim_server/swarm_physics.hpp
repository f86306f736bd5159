#pragma once
// The swarm's bodies and flight controllers. Each control period, every
// drone's controller turns its velocity setpoint into rotor commands at the
// physics rate and the Bullet world steps. Pure: no DDS, no clock (sim time
// advances only by step), no I/O. Positions ENU in m, world frame.
#include <array>
#include <cstdint>
#include <random>
#include <vector>

#include "common/scene.hpp"
#include "sim_server/aero.hpp"
#include "sim_server/airframe.hpp"
#include "sim_server/flight_controller.hpp"
#include "sim_server/physics_world.hpp"
#include "sim_server/quadrotor.hpp"
#include "sim_server/wind.hpp"

namespace ddswarm::sim {

class SwarmPhysics {
 public:
  /// starts: one per drone, m; every drone starts level at yaw scene.start.yaw_rad.
  /// seed: the scenario's; each drone's sensor noise has its own generator.
  /// wind and aero: calm and off unless asked (sim/wind.hpp, sim/aero.hpp).
  SwarmPhysics(const SceneConfig& scene, const QuadrotorParams& quadrotor,
               const ControllerConfig& controller, const std::vector<Eigen::Vector3d>& starts,
               std::uint64_t seed, const WindConfig& wind = {}, const AeroConfig& aero = {});
  /// A swarm of several airframes: drone i flies fleet.quadrotors[fleet.airframe_of[i]]
  /// with fleet.controllers[...] (sim/airframe.hpp); starts.size() == airframe_of.size().
  SwarmPhysics(const SceneConfig& scene, const Fleet& fleet,
               const std::vector<Eigen::Vector3d>& starts, std::uint64_t seed,
               const WindConfig& wind = {}, const AeroConfig& aero = {});

  /// Steps one control period: substeps physics steps of dt_s s, drone i
  /// flying setpoints[i]. The wind at each drone is taken once a period, at
  /// its start (its turbulence changes over seconds, a period is 20 ms).
  /// Returns the contacts that began, in step order.
  std::vector<ContactEvent> step(const std::vector<VelocitySetpoint>& setpoints, int substeps,
                                 double dt_s);

  RigidState state(int drone) const { return world_.state(drone); }
  /// The airframe drone flies.
  const QuadrotorParams& airframe(int drone) const { return world_.params(drone); }
  const FlightController& controller(int drone) const { return controllers_[drone]; }
  /// rad/s, actual (lagged) rotor speeds.
  std::array<double, 4> rotor_speeds(int drone) const { return world_.rotor_speeds(drone); }
  /// Casts the drone's distance sensors (PhysicsWorld::cast_rays) with its own generator.
  void cast_rays(int drone, const SensorConfig& sensors, std::vector<float>& range_m,
                 std::vector<std::uint8_t>& hit);

 private:
  PhysicsWorld world_;
  WindField wind_;
  std::vector<FlightController> controllers_;
  std::vector<std::mt19937_64> sensor_rng_;
};

}  // namespace ddswarm::sim
