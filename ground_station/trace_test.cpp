// `ddswarm-gs status --drones`: the per-drone table a user reads off one
// swarm state (distances, collisions, phase, flags).
#include "ground_station/trace.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include "common/config_error.hpp"
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

// `ddswarm-gs trace --metrics`: one row per tick over the drones the referee counts.
TEST(TraceMetrics, OneRowPerTickOverTheDronesNotInFailsafe) {
  msg::SwarmState s;
  s.tick(100);
  s.sim_time_s(2.0);
  auto d0 = drone(0, 0, 0, 2, msg::DRONE_AIRBORNE | msg::DRONE_AGENT_LIVE);
  d0.velocity().y(1);
  auto d1 = drone(1, 0.5, 0, 2, msg::DRONE_AIRBORNE | msg::DRONE_AGENT_LIVE);
  d1.velocity().y(3);
  auto d2 = drone(2, 30, 0, 2, msg::DRONE_AIRBORNE | msg::DRONE_AGENT_LIVE);
  d2.velocity().y(-2);
  // In failsafe, flying the other way right next to drone 0: not counted.
  auto d3 = drone(3, 0, 0.2, 2, msg::DRONE_FAILSAFE);
  d3.velocity().x(5);
  s.drones({d0, d1, d2, d3});
  SwarmMetricsOptions o;  // 10 m range, 1 m near miss
  // 3 drones: order (2 - 4) / 6, speeds 1, 3, 2, nearest 0.5 m, one near pair,
  // drone 2 alone: two components, λ₂ 0.
  EXPECT_EQ(trace_metrics_row(s, o), "100,2.000,3,-0.3333,2.0000,0.5000,1,2,0.0000");
  o.range_m = 29.8;  // 0-1 and 1-2 linked, 0-2 (30 m) not: the path P_3, λ₂ 1
  EXPECT_EQ(trace_metrics_row(s, o), "100,2.000,3,-0.3333,2.0000,0.5000,1,1,1.0000");
  // The header names as many columns as a row has.
  const std::string header = kTraceMetricsHeader;
  EXPECT_EQ(std::count(header.begin(), header.end(), ','), 8);
  msg::SwarmState lone;
  lone.drones({drone(0, 1, 2, 3, msg::DRONE_AGENT_LIVE)});
  EXPECT_EQ(trace_metrics_row(lone, o), "0,0.000,1,nan,0.0000,inf,0,1,nan");
}

TEST(TraceMetrics, OptionsComeFromTheScenariosSimSection) {
  EXPECT_EQ(scenario_metrics_options("").range_m, 10.0);
  const std::string path = ::testing::TempDir() + "/trace_metrics_scenario.yaml";
  std::ofstream(path)
      << "sim:\n  physics_rate_hz: 500\n  metrics_range_m: 25\n  near_miss_m: 0.5\n";
  const SwarmMetricsOptions o = scenario_metrics_options(path);
  EXPECT_EQ(o.range_m, 25.0);
  EXPECT_EQ(o.near_miss_m, 0.5);
  EXPECT_EQ(o.lambda2_max_drones, 128);
  std::ofstream(path, std::ios::trunc) << "sim:\n  near_miss_m: -1\n";
  try {
    scenario_metrics_options(path);
    FAIL() << "a bad near_miss_m must be refused";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), path + ":2: sim.near_miss_m = -1: must be > 0");
  }
  // The server's bounds, from the same declaration.
  std::ofstream(path, std::ios::trunc) << "sim:\n  near_miss_m: 2000\n";
  try {
    scenario_metrics_options(path);
    FAIL() << "a near_miss_m past the server's bound must be refused";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), path + ":2: sim.near_miss_m = 2000: must be <= 1000");
  }
}

}  // namespace
}  // namespace ddswarm::gs
