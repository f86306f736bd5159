#include "sim_server/messages.hpp"

#include <algorithm>
#include <cmath>

#include "common/convert.hpp"

namespace ddswarm::sim {

void CollisionCounts::add(const ContactEvent& e) {
  if (e.kind == ContactKind::kGround) {
    ++ground[e.drone];
  } else if (e.kind == ContactKind::kObstacle) {
    ++obstacle[e.drone];
  } else {
    ++drone[e.drone];
    if (e.other >= 0 && e.other < static_cast<int>(drone.size())) ++drone[e.other];
  }
}

msg::Scene scene_message(const ScenarioConfig& scenario, const SimConfig& sim,
                         const SceneConfig& scene, const QuadrotorParams& quadrotor,
                         const SensorConfig& sensors, const std::vector<Eigen::Vector3d>& starts,
                         std::uint64_t server_instance, const WindConfig& wind) {
  msg::Scene s = to_msg(scene);
  s.wind(scene_wind(wind));
  s.name(scenario.name.substr(0, 127));
  s.seed(scenario.seed);
  s.server_instance(server_instance);
  s.num_drones(static_cast<std::uint16_t>(scenario.drones));
  s.mode(scenario.mode == TimeMode::kLockstep ? msg::MODE_LOCKSTEP : msg::MODE_REALTIME);
  s.physics_rate_hz(sim.physics_rate_hz);
  s.control_rate_hz(sim.control_rate_hz);
  for (const auto& p : starts) s.start_positions().push_back(to_msg(p));
  s.drone_radius_m(quadrotor.collision_radius_m);
  s.arm_length_m(quadrotor.arm_length_m);
  s.sensor_count(static_cast<std::uint16_t>(sensors.rays()));
  s.sensor_max_range_m(static_cast<float>(sensors.max_range_m));
  return s;
}

msg::SceneWind scene_wind(const WindConfig& wind) {
  msg::SceneWind w;
  w.steady_mps(to_msg(wind.steady_mps));
  w.turbulence(wind.turbulence);
  if (wind.turbulence) {
    const DrydenScales d = dryden_scales(wind.steady_mps.norm(), wind.turbulence_altitude_m);
    w.turbulence_sigma_mps(
        to_msg(wind.turbulence_scale * Eigen::Vector3d(d.sigma_u, d.sigma_v, d.sigma_w)));
  }
  w.gusts_per_minute(wind.gusts_per_minute);
  w.gust_max_mps(wind.gusts_per_minute > 0 ? wind.gust_amplitude_mps.y() : 0.0);
  return w;
}

msg::SwarmState swarm_state_frame(int n, const SensorConfig& sensors) {
  msg::SwarmState m;
  m.drones().resize(n);
  m.scans().resize(n);
  for (int i = 0; i < n; ++i) {
    auto& sc = m.scans()[i];
    sc.drone_id(static_cast<std::uint16_t>(i));
    sc.max_range_m(static_cast<float>(sensors.max_range_m));
    for (int k = 0; k < sensors.rays(); ++k) {
      sc.angle_body_rad().push_back(static_cast<float>(sensors.ray_yaw_rad(k)));
      sc.elevation_body_rad().push_back(static_cast<float>(sensors.ray_elevation_rad(k)));
    }
  }
  return m;
}

void fill_drone_state(msg::DroneState& d, const DroneFacts& f, const CollisionCounts& collisions,
                      const SceneConfig& scene, double airborne_height_m) {
  const RigidState& st = f.state;
  const int i = f.id;
  d.drone_id(static_cast<std::uint16_t>(i));
  d.tick(f.tick);
  d.sim_time_s(f.sim_time_s);
  d.position(to_msg(st.p_world));
  d.orientation(to_msg(st.q_world_body));
  d.velocity(to_msg(st.v_world));
  d.angular_velocity(to_msg(st.w_body));
  for (int k = 0; k < 4; ++k) d.motor_speed_rad_s()[k] = static_cast<float>(f.rotor_rad_s[k]);
  d.collisions_obstacle(collisions.obstacle[i]);
  d.collisions_drone(collisions.drone[i]);
  d.collisions_ground(collisions.ground[i]);
  std::uint16_t flags = 0;
  bool airborne = st.p_world.z() > scene.ground_z_m + airborne_height_m;
  if (airborne) flags |= msg::DRONE_AIRBORNE;
  // In failsafe: the server flies it (its agent is lost), or its agent
  // does (the drone's swarm law faulted).
  if (f.server_failsafe || f.phase == Phase::kFailsafe) flags |= msg::DRONE_FAILSAFE;
  if (f.agent_live) flags |= msg::DRONE_AGENT_LIVE;
  if ((st.p_world.array() < scene.bounds_min.array()).any() ||
      (st.p_world.array() > scene.bounds_max.array()).any())
    flags |= msg::DRONE_OUT_OF_BOUNDS;
  if (scene.past_finish(st.p_world.head<2>())) flags |= msg::DRONE_PAST_FINISH;
  if (f.motors_on) flags |= msg::DRONE_MOTORS_ON;
  d.flags(flags);
  d.phase(static_cast<std::uint8_t>(f.phase));
  d.command_age_s(f.command_age_s);
}

void refresh_agent_live(std::vector<msg::DroneState>& drones, const AgentRegistry& agents) {
  for (std::size_t i = 0; i < std::min<std::size_t>(agents.size(), drones.size()); ++i) {
    auto& d = drones[i];
    const std::uint16_t others = d.flags() & ~static_cast<std::uint16_t>(msg::DRONE_AGENT_LIVE);
    d.flags(static_cast<std::uint16_t>(
        others | (agents[static_cast<int>(i)].live ? msg::DRONE_AGENT_LIVE : 0)));
  }
}

void fill_scan(msg::DistanceScan& sc, std::uint64_t tick, double sim_time_s,
               const std::vector<float>& range_m, const std::vector<std::uint8_t>& hit) {
  sc.tick(tick);
  sc.sim_time_s(sim_time_s);
  sc.range_m().assign(range_m.begin(), range_m.end());
  sc.hit().assign(hit.begin(), hit.end());
}

void add_agents(msg::SimStatus& s, const AgentRegistry& agents) {
  const int n = agents.size();
  s.mission_seq().resize(static_cast<std::size_t>(n));
  s.mission_issuer().resize(static_cast<std::size_t>(n));
  s.phase().resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    if (agents[i].live) s.live_agents().push_back(static_cast<std::uint16_t>(i));
    s.mission_seq()[k] = agents[i].mission_seq;
    s.mission_issuer()[k] = agents[i].mission_issuer;
    s.phase()[k] = static_cast<std::uint8_t>(agents[i].phase);
  }
  s.agents_live(static_cast<std::uint16_t>(s.live_agents().size()));
}

void add_swarm(msg::SimStatus& s, const std::vector<msg::DroneState>& drones,
               const CollisionCounts& collisions) {
  int airborne = 0, failsafe = 0;
  std::uint32_t co = 0, cd = 0, cg = 0;
  for (std::size_t i = 0; i < drones.size(); ++i) {
    airborne += drones[i].flags() & msg::DRONE_AIRBORNE ? 1 : 0;
    failsafe += (drones[i].flags() & msg::DRONE_FAILSAFE) ? 1 : 0;
    co += collisions.obstacle[i];
    cd += collisions.drone[i];
    cg += collisions.ground[i];
  }
  s.airborne(static_cast<std::uint16_t>(airborne));
  s.failsafe(static_cast<std::uint16_t>(failsafe));
  s.collisions_obstacle(co);
  s.collisions_drone(cd / 2);  // each drone-drone contact counted on both drones
  s.collisions_ground(cg);
}

msg::TaskStatus task_message(const TaskReport& r, double start_wall_time_s, double wall_elapsed_s) {
  msg::TaskStatus m;
  m.seq(r.seq);
  m.phase(static_cast<std::uint8_t>(r.phase));
  m.reason(r.reason.substr(0, 127));
  m.start_sim_time_s(r.start_sim_time_s);
  m.elapsed_s(r.elapsed_s);
  m.start_wall_time_s(start_wall_time_s);
  m.wall_elapsed_s(wall_elapsed_s);
  m.epsilon_m(r.epsilon_m);
  m.speed_mps(r.speed_mps);
  m.drones(static_cast<std::uint16_t>(r.drones));
  m.past_finish(static_cast<std::uint16_t>(r.past_finish));
  m.max_pair_distance_m(r.max_pair_distance_m);
  m.min_inter_drone_m(std::isfinite(r.min_inter_drone_m) ? r.min_inter_drone_m : -1);
  m.min_clearance_m(std::isfinite(r.min_clearance_m) ? r.min_clearance_m : -1);
  m.collisions_obstacle(r.collisions_obstacle);
  m.collisions_drone(r.collisions_drone);
  m.collisions_ground(r.collisions_ground);
  for (int id : r.lost_drones) m.lost_drones().push_back(static_cast<std::uint16_t>(id));
  m.order(r.order);
  m.order_mean(r.metrics.order_mean);
  m.order_min(r.metrics.order_min);
  m.speed_mean_mps(r.metrics.speed_mean_mps);
  m.near_misses(r.metrics.near_misses);
  m.components(static_cast<std::uint16_t>(r.components));
  m.components_max(static_cast<std::uint16_t>(r.metrics.components_max));
  m.lambda2(r.lambda2);
  m.lambda2_min(r.metrics.lambda2_min);
  m.metrics_range_m(r.metrics.range_m);
  m.near_miss_m(r.metrics.near_miss_m);
  return m;
}

int collision_kind(ContactKind k) {
  return k == ContactKind::kObstacle ? 0 : k == ContactKind::kDrone ? 1 : 2;
}

msg::CollisionEvent collision_message(std::uint64_t tick, double sim_time_s,
                                      const ContactEvent& e) {
  msg::CollisionEvent m;
  m.tick(tick);
  m.sim_time_s(sim_time_s);
  m.drone_id(static_cast<std::uint16_t>(e.drone));
  m.kind(static_cast<std::uint8_t>(collision_kind(e.kind)));
  m.other(e.other);
  m.where(to_msg(e.where_world));
  return m;
}

}  // namespace ddswarm::sim
