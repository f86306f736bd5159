// `ddswarm-gs status --drones`: the per-drone table a user reads off one
// swarm state (distances, collisions, phase, flags).
#include "ground_station/trace.hpp"

#include <gtest/gtest.h>

#include "common/mission.hpp"
#include "common/topics.hpp"

namespace ddswarm::gs {
namespace {

msg::DroneState drone(std::uint16_t id, double x, double y, double z, std::uint16_t flags) {
  msg::DroneState d;
  d.drone_id(id);
  d.position().x(x);
  d.position().y(y);
  d.position().z(z);
  d.flags(flags);
  return d;
}

TEST(SwarmSnapshot, DistancesCollisionsAndFlagsOfOneState) {
  msg::SwarmState s;
  s.tick(250);
  s.sim_time_s(5.0);
  auto d0 = drone(0, 0, 0, 2, msg::DRONE_AIRBORNE | msg::DRONE_AGENT_LIVE);
  d0.velocity().x(3);
  d0.velocity().y(4);
  d0.phase(static_cast<std::uint8_t>(Phase::kHold));
  auto d1 = drone(1, 3, 4, 2, msg::DRONE_AIRBORNE | msg::DRONE_AGENT_LIVE);
  d1.collisions_drone(2);
  d1.collisions_obstacle(1);
  auto d2 = drone(2, 0, 12, 2, msg::DRONE_FAILSAFE);  // its agent is not heard
  s.drones({d0, d1, d2});

  const SwarmSnapshot snap = snapshot_of(s);
  EXPECT_EQ(snap.tick, 250u);
  ASSERT_EQ(snap.drones.size(), 3u);
  EXPECT_DOUBLE_EQ(snap.min_pair_m, 5.0);   // drones 0 and 1
  EXPECT_DOUBLE_EQ(snap.max_pair_m, 12.0);  // drones 0 and 2
  EXPECT_DOUBLE_EQ(snap.drones[0].speed_mps, 5.0);
  EXPECT_DOUBLE_EQ(snap.drones[0].nearest_peer_m, 5.0);
  EXPECT_NEAR(snap.drones[2].nearest_peer_m, std::hypot(3.0, 8.0), 1e-12);  // drone 1
  EXPECT_EQ(snap.drones[1].collisions, 3);
  EXPECT_EQ(snap.drones[0].phase, "hold");
  EXPECT_EQ(snap.drones[0].flags, "airborne");
  EXPECT_EQ(snap.drones[2].flags, "failsafe,no-agent");
  const std::string table = snap.table();
  EXPECT_NE(table.find("pairwise distance: min 5.00 m, max 12.00 m"), std::string::npos) << table;
}

TEST(SwarmSnapshot, OneDroneHasNoPairs) {
  msg::SwarmState s;
  s.drones({drone(0, 1, 2, 3, msg::DRONE_AGENT_LIVE)});
  const SwarmSnapshot snap = snapshot_of(s);
  EXPECT_EQ(snap.min_pair_m, 0.0);
  EXPECT_EQ(snap.max_pair_m, 0.0);
  EXPECT_EQ(snap.drones[0].nearest_peer_m, 0.0);
  EXPECT_EQ(snap.drones[0].flags, "");
}

}  // namespace
}  // namespace ddswarm::gs
