#pragma once
// The messages the server publishes, built from plain state: Scene,
// DroneState (in SwarmState), SimStatus, TaskStatus, CollisionEvent. Pure: no
// DDS endpoints, no clock, no I/O. Positions and velocities are ENU, world
// frame; times in s.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "CollisionEvent.h"
#include "DistanceScan.h"
#include "DroneState.h"
#include "Scene.h"
#include "SimStatus.h"
#include "SwarmState.h"
#include "TaskStatus.h"
#include "common/mission.hpp"
#include "common/scenario.hpp"
#include "common/scene.hpp"
#include "sim_server/agent_registry.hpp"
#include "sim_server/physics_world.hpp"
#include "sim_server/quadrotor.hpp"
#include "sim_server/sim_config.hpp"
#include "sim_server/task_referee.hpp"
#include "sim_server/wind.hpp"

namespace ddswarm::sim {

/// Collisions counted per drone since the start; a drone-drone contact counts on both drones.
struct CollisionCounts {
  explicit CollisionCounts(int drones)
      : obstacle(static_cast<std::size_t>(drones), 0),
        drone(static_cast<std::size_t>(drones), 0),
        ground(static_cast<std::size_t>(drones), 0) {}
  /// Counts a contact that began: on its drone, and a drone-drone one on the other drone too.
  void add(const ContactEvent& e);
  std::vector<std::uint32_t> obstacle, drone, ground;
};

/// The world and the swarm as this server runs them; published once, as it joins.
msg::Scene scene_message(const ScenarioConfig& scenario, const SimConfig& sim,
                         const SceneConfig& scene, const QuadrotorParams& quadrotor,
                         const SensorConfig& sensors, const std::vector<Eigen::Vector3d>& starts,
                         std::uint64_t server_instance, const WindConfig& wind = {});

/// The wind as a Scene tells viewers of it: the mean, turbulence's
/// intensities (Dryden, at the model's altitude), the gusts' rate and size.
msg::SceneWind scene_wind(const WindConfig& wind);

/// A SwarmState for n drones with what never changes filled in: each scan's
/// drone id, max range and each ray's body yaw (rad, +CCW about body z) and
/// elevation (rad, up from the body x-y plane), in SensorConfig's ray order.
msg::SwarmState swarm_state_frame(int n, const SensorConfig& sensors);

/// One drone at one tick, as its DroneState tells it.
struct DroneFacts {
  int id = 0;
  std::uint64_t tick = 0;
  double sim_time_s = 0;
  RigidState state;
  std::array<double, 4> rotor_rad_s{};
  bool server_failsafe = false;  ///< the server flies it (FailsafePolicy::active)
  Phase phase = Phase::kIdle;    ///< its agent's phase
  bool agent_live = false;
  bool motors_on = false;  ///< of the setpoint that flew the last period
  float command_age_s = 0;
};

/// Fills d (one of SwarmState's drones) from f; the flags compare f's
/// position with the scene's ground, bounds and finish line.
void fill_drone_state(msg::DroneState& d, const DroneFacts& f, const CollisionCounts& collisions,
                      const SceneConfig& scene, double airborne_height_m);

/// Sets each drone's DRONE_AGENT_LIVE from whether its agent is live now.
void refresh_agent_live(std::vector<msg::DroneState>& drones, const AgentRegistry& agents);

/// Fills a scan with the ranges (m) and hits a cast measured at tick.
void fill_scan(msg::DistanceScan& sc, std::uint64_t tick, double sim_time_s,
               const std::vector<float>& range_m, const std::vector<std::uint8_t>& hit);

/// Adds each drone's agent (live, mission seq and issuer, phase) to s.
void add_agents(msg::SimStatus& s, const AgentRegistry& agents);
/// Adds the swarm's totals to s: airborne, failsafe and collisions (each
/// drone-drone contact once).
void add_swarm(msg::SimStatus& s, const std::vector<msg::DroneState>& drones,
               const CollisionCounts& collisions);

/// The referee's report as TaskStatus; start_wall_time_s since the server
/// started, wall_elapsed_s since the task did.
msg::TaskStatus task_message(const TaskReport& r, double start_wall_time_s, double wall_elapsed_s);

/// A contact's kind as CollisionEvent and the referee count it: 0 obstacle, 1 drone, 2 ground.
int collision_kind(ContactKind k);
msg::CollisionEvent collision_message(std::uint64_t tick, double sim_time_s, const ContactEvent& e);

}  // namespace ddswarm::sim
