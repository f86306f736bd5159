#pragma once
// The simulation server: steps every quadrotor, casts their sensors, counts
// collisions, referees the task, and talks DDS. One per swarm.
#include <memory>
#include <string>

#include "common/dds_config.hpp"
#include "common/scenario.hpp"
#include "common/scene.hpp"
#include "sim_server/aero.hpp"
#include "sim_server/airframe.hpp"
#include "sim_server/flight_controller.hpp"
#include "sim_server/physics_world.hpp"
#include "sim_server/quadrotor.hpp"
#include "sim_server/sim_config.hpp"
#include "sim_server/wind.hpp"

namespace ddswarm::sim {

/// Everything the server reads from a scenario file.
struct ServerConfig {
  ScenarioConfig scenario;
  SimConfig sim;
  QuadrotorParams quadrotor;                   ///< every drone's airframe, but those in a group
  ControllerConfig controller;                 ///< its gains
  std::vector<AirframeGroup> airframe_groups;  ///< quadrotor.groups
  SensorConfig sensors;
  SceneConfig scene;
  WindConfig wind;
  AeroConfig aero;
  DdsConfig dds;
  /// What scene.generate added (load_server_config generates it), for the log.
  std::string generated_world;
  void validate() const;
  /// Every drone's airframe (quadrotor, controller and the groups).
  Fleet fleet() const;
};

/// Loads and validates path; throws ConfigError "file:line: field = value: reason".
ServerConfig load_server_config(const std::string& path);

class SimServer {
 public:
  /// Builds the world and joins DDS; throws on failure (message names what failed).
  explicit SimServer(ServerConfig cfg);
  ~SimServer();
  enum class End { kStopped, kRejoinRequested, kRivalServer };
  /// Runs until stop_requested() or duration_s of wall time (<= 0: forever):
  /// kStopped. kRejoinRequested on take_rejoin_request() (SIGUSR1) before any
  /// mission command came: the caller should destroy this server and start a
  /// new one (a new world, which before a mission loses nothing).
  /// kRivalServer when another server was already on the domain as this one
  /// joined (rival_instance() names it): the caller should exit.
  End run(double duration_s);
  /// The other server's instance after kRivalServer, else 0.
  std::uint64_t rival_instance() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ddswarm::sim
