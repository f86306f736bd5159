#include "sim_server/messages.hpp"

#include <gtest/gtest.h>

#include <limits>

using namespace ddswarm;
using namespace ddswarm::sim;

TEST(Messages, ADronesFlagsSayWhatTheServerKnowsOfIt) {
  SceneConfig scene;  // ground at 0, bounds (-100, -100, 0)..(100, 100, 50)
  CollisionCounts counts(2);
  counts.obstacle[1] = 3;
  DroneFacts f;
  f.id = 1;
  f.tick = 9;
  f.sim_time_s = 0.18;
  f.state.p_world = {1, 2, 1.0};
  f.phase = Phase::kFailsafe;  // its law faulted: its agent flies the failsafe
  f.agent_live = true;
  f.motors_on = true;
  f.command_age_s = 0.04f;
  msg::DroneState d;
  fill_drone_state(d, f, counts, scene, 0.3);
  EXPECT_EQ(d.drone_id(), 1);
  EXPECT_EQ(d.tick(), 9u);
  EXPECT_EQ(d.collisions_obstacle(), 3u);
  EXPECT_EQ(d.phase(), static_cast<std::uint8_t>(Phase::kFailsafe));
  EXPECT_FLOAT_EQ(d.command_age_s(), 0.04f);
  const std::uint16_t want =
      msg::DRONE_AIRBORNE | msg::DRONE_FAILSAFE | msg::DRONE_AGENT_LIVE | msg::DRONE_MOTORS_ON;
  EXPECT_EQ(d.flags() & ~msg::DRONE_PAST_FINISH, want);
  // On the ground, out of bounds, flown by the server's failsafe.
  f.state.p_world = {500, 0, 0.1};
  f.phase = Phase::kHold;
  f.server_failsafe = true;
  f.agent_live = false;
  f.motors_on = false;
  fill_drone_state(d, f, counts, scene, 0.3);
  EXPECT_EQ(d.flags() & ~msg::DRONE_PAST_FINISH, msg::DRONE_FAILSAFE | msg::DRONE_OUT_OF_BOUNDS);
}

TEST(Messages, TheStatusCountsEachDroneContactOnce) {
  std::vector<msg::DroneState> drones(3);
  drones[0].flags(msg::DRONE_AIRBORNE);
  drones[1].flags(msg::DRONE_AIRBORNE | msg::DRONE_FAILSAFE);
  CollisionCounts counts(3);
  counts.drone[0] = counts.drone[2] = 1;  // one contact, counted on both drones
  counts.ground[1] = 2;
  msg::SimStatus s;
  add_swarm(s, drones, counts);
  EXPECT_EQ(s.airborne(), 2);
  EXPECT_EQ(s.failsafe(), 1);
  EXPECT_EQ(s.collisions_drone(), 1u);
  EXPECT_EQ(s.collisions_ground(), 2u);
  EXPECT_EQ(s.collisions_obstacle(), 0u);
}

TEST(Messages, TheStatusListsLiveAgentsAndTheirMissions) {
  AgentRegistry agents(3, true, Pipeline::kNone);
  agents.heartbeat(2, 0xa, 0.0);
  CommandRecord c;
  c.phase = Phase::kHold;
  c.mission_seq = 4;
  c.mission_issuer = 0xbeef;
  agents.record(2, 0xa, c, 0.0);
  msg::SimStatus s;
  add_agents(s, agents);
  EXPECT_EQ(s.agents_live(), 1);
  EXPECT_EQ(s.live_agents(), std::vector<std::uint16_t>{2});
  EXPECT_EQ(s.mission_seq(), (std::vector<std::uint32_t>{0, 0, 4}));
  EXPECT_EQ(s.mission_issuer()[2], 0xbeefu);
  EXPECT_EQ(s.phase()[2], static_cast<std::uint8_t>(Phase::kHold));
  // A tick published again carries who is live now.
  std::vector<msg::DroneState> drones(3);
  drones[0].flags(msg::DRONE_AGENT_LIVE | msg::DRONE_AIRBORNE);
  refresh_agent_live(drones, agents);
  EXPECT_EQ(drones[0].flags(), msg::DRONE_AIRBORNE);
  EXPECT_EQ(drones[2].flags(), msg::DRONE_AGENT_LIVE);
}

TEST(Messages, ATaskWithoutAMinimumYetSaysMinusOne) {
  TaskReport r;
  r.phase = TaskPhase::kRunning;
  r.min_inter_drone_m = std::numeric_limits<double>::infinity();
  r.min_clearance_m = 0.85;
  r.lost_drones = {3, 5};
  r.reason = std::string(300, 'x');
  const auto m = task_message(r, 2.0, 1.5);
  EXPECT_EQ(m.min_inter_drone_m(), -1);
  EXPECT_EQ(m.min_clearance_m(), 0.85);
  EXPECT_EQ(m.lost_drones(), (std::vector<std::uint16_t>{3, 5}));
  EXPECT_EQ(m.reason().size(), 127u);
  EXPECT_EQ(m.start_wall_time_s(), 2.0);
  EXPECT_EQ(m.wall_elapsed_s(), 1.5);
}

TEST(Messages, AContactsKindAsCollisionEventTellsIt) {
  EXPECT_EQ(collision_kind(ContactKind::kObstacle), 0);
  EXPECT_EQ(collision_kind(ContactKind::kDrone), 1);
  EXPECT_EQ(collision_kind(ContactKind::kGround), 2);
  ContactEvent e;
  e.drone = 2;
  e.kind = ContactKind::kDrone;
  e.other = 4;
  e.where_world = {1, 2, 3};
  const auto m = collision_message(50, 1.0, e);
  EXPECT_EQ(m.tick(), 50u);
  EXPECT_EQ(m.drone_id(), 2);
  EXPECT_EQ(m.kind(), 1);
  EXPECT_EQ(m.other(), 4);
  EXPECT_EQ(m.where().z(), 3);
}

TEST(Messages, TheSwarmFrameCarriesEachScansRays) {
  SensorConfig sensors;
  sensors.count = 4;
  sensors.yaw_offset_rad = 0;
  const auto m = swarm_state_frame(2, sensors);
  ASSERT_EQ(m.drones().size(), 2u);
  ASSERT_EQ(m.scans().size(), 2u);
  EXPECT_EQ(m.scans()[1].drone_id(), 1);
  ASSERT_EQ(m.scans()[1].angle_body_rad().size(), 4u);
  EXPECT_FLOAT_EQ(m.scans()[1].angle_body_rad()[1], static_cast<float>(M_PI / 2));
  ASSERT_EQ(m.scans()[1].elevation_body_rad().size(), 4u);
  EXPECT_EQ(m.scans()[1].elevation_body_rad()[3], 0.0f);  // the ring lies in the body x-y plane
}

TEST(Messages, ARowPatternCarriesEachRaysYawAndElevationRowByRow) {
  SensorConfig sensors;
  sensors.count = 4;
  sensors.rows = 3;
  sensors.vertical_fov_deg = 40;
  const auto m = swarm_state_frame(1, sensors);
  const auto& sc = m.scans()[0];
  ASSERT_EQ(sc.angle_body_rad().size(), 12u);
  ASSERT_EQ(sc.elevation_body_rad().size(), 12u);
  // Ray 6 = row 1 (the middle, level), column 2 (behind).
  EXPECT_FLOAT_EQ(sc.angle_body_rad()[6], static_cast<float>(M_PI));
  EXPECT_EQ(sc.elevation_body_rad()[6], 0.0f);
  EXPECT_FLOAT_EQ(sc.elevation_body_rad()[0], static_cast<float>(-20 * M_PI / 180));
  EXPECT_FLOAT_EQ(sc.elevation_body_rad()[11], static_cast<float>(20 * M_PI / 180));
  const auto s = scene_message({}, {}, {}, {}, sensors, {}, 0);
  EXPECT_EQ(s.sensor_count(), 12);  // rays per scan
}

TEST(Messages, ADroneContactCountsOnBothDrones) {
  CollisionCounts c(3);
  ContactEvent e;
  e.drone = 0;
  e.kind = ContactKind::kDrone;
  e.other = 2;
  c.add(e);
  e.kind = ContactKind::kObstacle;
  e.other = 7;  // an obstacle index, not a drone
  c.add(e);
  e.kind = ContactKind::kGround;
  e.drone = 1;
  e.other = -1;
  c.add(e);
  EXPECT_EQ(c.drone, (std::vector<std::uint32_t>{1, 0, 1}));
  EXPECT_EQ(c.obstacle, (std::vector<std::uint32_t>{1, 0, 0}));
  EXPECT_EQ(c.ground, (std::vector<std::uint32_t>{0, 1, 0}));
}
