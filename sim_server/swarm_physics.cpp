#include "sim_server/swarm_physics.hpp"

namespace ddswarm::sim {

namespace {
Fleet one_airframe(const QuadrotorParams& q, const ControllerConfig& c, std::size_t drones) {
  return Fleet{{q}, {c}, std::vector<int>(drones, 0)};
}
}  // namespace

SwarmPhysics::SwarmPhysics(const SceneConfig& scene, const QuadrotorParams& quadrotor,
                           const ControllerConfig& controller,
                           const std::vector<Eigen::Vector3d>& starts, std::uint64_t seed,
                           const WindConfig& wind, const AeroConfig& aero)
    : SwarmPhysics(scene, one_airframe(quadrotor, controller, starts.size()), starts, seed, wind,
                   aero) {}

SwarmPhysics::SwarmPhysics(const SceneConfig& scene, const Fleet& fleet,
                           const std::vector<Eigen::Vector3d>& starts, std::uint64_t seed,
                           const WindConfig& wind, const AeroConfig& aero)
    : world_(scene, fleet.quadrotors, fleet.airframe_of, starts, scene.start.yaw_rad),
      wind_(wind, seed) {
  world_.set_aero(aero);
  const int n = static_cast<int>(starts.size());
  for (int i = 0; i < n; ++i) {
    const int a = fleet.airframe_of[i];
    controllers_.emplace_back(fleet.quadrotors[a], fleet.controllers[a]);
    controllers_.back().reset(scene.start.yaw_rad);
    // One generator per drone: a drone's noise does not depend on the others.
    sensor_rng_.emplace_back(seed * 1000003ULL + static_cast<std::uint64_t>(i));
  }
}

std::vector<ContactEvent> SwarmPhysics::step(const std::vector<VelocitySetpoint>& setpoints,
                                             int substeps, double dt_s) {
  const int n = static_cast<int>(controllers_.size());
  if (wind_.enabled()) {
    const double t = world_.time_s();
    wind_.advance_to(t);
    for (int i = 0; i < n; ++i) world_.set_air_velocity(i, wind_.at(world_.state(i).p_world, t));
  }
  for (int k = 0; k < substeps; ++k) {
    for (int i = 0; i < n; ++i) {
      auto omega = controllers_[i].update(world_.state(i), setpoints[i], dt_s);
      world_.set_rotor_commands(i, omega);
    }
    world_.step(dt_s);
  }
  return world_.take_contact_events();
}

void SwarmPhysics::cast_rays(int drone, const SensorConfig& sensors, std::vector<float>& range_m,
                             std::vector<std::uint8_t>& hit) {
  world_.cast_rays(drone, sensors, sensor_rng_[drone], range_m, hit);
}

}  // namespace ddswarm::sim
