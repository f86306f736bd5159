#include "agent/drone_brain.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

using namespace ddswarm;
using namespace ddswarm::agent;
using Eigen::Vector3d;

namespace {

constexpr double kRateHz = 50;
constexpr double kDt = 1 / kRateHz;

DroneRow row(int id, const Vector3d& p = Vector3d::Zero(), const Vector3d& v = Vector3d::Zero()) {
  DroneRow r;
  r.id = id;
  r.valid = true;
  r.agent_live = true;
  r.p_world = p;
  r.v_world = v;
  return r;
}

/// Drones on a perfect velocity plant, each flown by its brain from the
/// swarm ticks a server would publish; the ring of recent commands is the
/// test's to fill.
struct Swarm {
  explicit Swarm(int n, AgentConfig a = {}, CommConfig c = {}) : agent(std::move(a)), comm(c) {
    for (int id = 0; id < n; ++id) {
      brains.push_back(std::make_unique<DroneBrain>(id, 0xb0a + id, agent, comm, n));
      p.push_back(Vector3d(3.0 * id, 0, 0));
      v.push_back(Vector3d::Zero());
    }
    for (auto& b : brains) b->start(scene, kRateHz, 7);
  }

  /// The sample of the current tick: every drone live, in the roster.
  const SwarmTick& sample() {
    t.tick = tick;
    t.sim_time_s = static_cast<double>(tick) * kDt;
    t.drones.resize(brains.size());
    t.roster.clear();
    for (std::size_t k = 0; k < brains.size(); ++k) {
      t.drones[k] = row(static_cast<int>(k), p[k], v[k]);
      t.roster.push_back({static_cast<int>(k), p[k], t.sim_time_s, v[k]});
    }
    return t;
  }

  /// Drone k's answer to the current tick (without moving anything).
  TickAnswer ask(std::size_t k = 0) { return brains[k]->tick(sample()); }

  /// One tick: every brain answers, the plant follows its command.
  std::vector<TickAnswer> step() {
    std::vector<TickAnswer> out;
    sample();
    for (auto& b : brains) out.push_back(b->tick(t));
    for (std::size_t k = 0; k < brains.size(); ++k) {
      const Vector3d was = p[k];
      p[k] += kDt * out[k].command.velocity;
      p[k].z() = std::max(p[k].z(), 0.0);
      v[k] = (p[k] - was) / kDt;
    }
    ++tick;
    return out;
  }

  void run(double seconds) {
    for (int k = 0; k < static_cast<int>(seconds / kDt); ++k) step();
  }

  /// Puts a command in the ring, applied by the swarm at the current tick.
  RelayedMission& relay(MissionType type, double value = 0) {
    RelayedMission m;
    m.command.seq = ++seq;
    m.command.type = type;
    m.command.value = value;
    m.command.issuer = "gs";
    m.issuer_instance = 0x9e;
    m.apply_tick = tick;
    t.missions.push_back(m);
    return t.missions.back();
  }

  AgentConfig agent;
  CommConfig comm;
  SceneConfig scene;
  std::vector<std::unique_ptr<DroneBrain>> brains;
  std::vector<Vector3d> p, v;
  SwarmTick t;
  std::uint64_t tick = 0;
  std::uint32_t seq = 0;
};

bool says(const TickAnswer& a, const std::string& text) {
  for (const auto& n : a.notes)
    if (n.text.find(text) != std::string::npos) return true;
  return false;
}

}  // namespace

TEST(DroneBrain, AnswersNothingBeforeItsScene) {
  AgentConfig a;
  CommConfig c;
  DroneBrain b(0, 1, a, c, 1);
  SwarmTick t;
  t.drones.push_back(row(0));
  EXPECT_EQ(b.tick(t).kind, TickAnswer::Kind::kNone);
  EXPECT_FALSE(b.started());
  EXPECT_EQ(b.phase(), Phase::kIdle);
}

TEST(DroneBrain, AcknowledgesACommandOnceAndCarriesItsSeq) {
  Swarm s(1);
  s.relay(MissionType::kTakeoff, 2.0);
  TickAnswer a = s.step()[0];
  ASSERT_EQ(a.kind, TickAnswer::Kind::kFresh);
  ASSERT_EQ(a.acks.size(), 1u);
  EXPECT_TRUE(a.acks[0].ack.accepted);
  EXPECT_EQ(a.acks[0].ack.seq, 1u);
  EXPECT_EQ(a.acks[0].issuer_instance, 0x9eu);
  EXPECT_TRUE(says(a, "drone 0: takeoff seq 1 accepted at tick 0"));
  EXPECT_TRUE(a.command.motors_on);
  EXPECT_EQ(a.command.phase, Phase::kTakeoff);
  EXPECT_EQ(a.command.mission_seq, 1u);
  EXPECT_EQ(a.command.mission_issuer, 0x9eu);
  EXPECT_EQ(a.command.agent_instance, 0xb0au);
  EXPECT_GT(a.command.velocity.z(), 0) << "climbs";
  // The ring holds the command for a while: it is not answered again.
  for (int k = 0; k < 20; ++k) EXPECT_TRUE(s.step()[0].acks.empty());
}

TEST(DroneBrain, ACommandRelayedAgainIsAcknowledgedAgainAndAppliedOnce) {
  Swarm s(1);
  s.relay(MissionType::kTakeoff, 2.0);
  s.run(6);
  ASSERT_EQ(s.brains[0]->phase(), Phase::kHold);
  s.relay(MissionType::kLand);
  ASSERT_EQ(s.step()[0].acks.size(), 1u);
  s.run(1);
  ASSERT_EQ(s.brains[0]->phase(), Phase::kLanding);
  // The issuer missed the ack and the server relays the land again, at a
  // new apply tick: acknowledged again, nothing changes.
  s.t.missions.back().apply_tick = s.tick;
  TickAnswer a = s.step()[0];
  ASSERT_EQ(a.acks.size(), 1u);
  EXPECT_TRUE(a.acks[0].ack.accepted);
  EXPECT_EQ(a.command.phase, Phase::kLanding);
}

TEST(DroneBrain, ATickSentAgainGetsTheSameAnswerAndRunsNothing) {
  Swarm s(2);
  s.relay(MissionType::kTakeoff, 2.0);
  s.run(3);
  const TickAnswer first = s.ask(0);
  const std::uint64_t sent = s.brains[0]->sent();
  ASSERT_EQ(first.kind, TickAnswer::Kind::kFresh);
  // The server publishes the tick again (lockstep, an answer was lost); the
  // drones did not move, so a second run would give the same command, but
  // it must not be a second run: the mission machine would step twice.
  const TickAnswer again = s.ask(0);
  EXPECT_EQ(again.kind, TickAnswer::Kind::kRepeat);
  EXPECT_EQ(again.command.tick, first.command.tick);
  EXPECT_EQ(again.command.velocity, first.command.velocity);
  EXPECT_TRUE(again.acks.empty());
  EXPECT_TRUE(again.notes.empty());
  EXPECT_EQ(s.brains[0]->sent(), sent);
}

TEST(DroneBrain, AJoiningDroneCatchesUpWithTheMissionInForce) {
  Swarm s(2);
  s.relay(MissionType::kTakeoff, 2.0);
  s.run(6);
  s.relay(MissionType::kTask, 1.0);
  s.run(1);
  ASSERT_EQ(s.brains[1]->phase(), Phase::kTask);
  // Drone 1's agent restarts: a new brain, the server's ring as it is now.
  s.brains[1] = std::make_unique<DroneBrain>(1, 0xfeed, s.agent, s.comm, 2);
  s.brains[1]->start(s.scene, kRateHz, 7);
  TickAnswer a = s.step()[1];
  EXPECT_TRUE(says(a, "drone 1: joined mid-mission: caught up with takeoff seq 1 of tick 0"));
  EXPECT_TRUE(says(a, "drone 1: joined mid-mission: caught up with task seq 2 of tick 300"));
  ASSERT_EQ(a.acks.size(), 2u);
  EXPECT_TRUE(a.acks[0].ack.accepted && a.acks[1].ack.accepted);
  EXPECT_EQ(s.brains[1]->phase(), Phase::kTask);
  EXPECT_EQ(a.command.mission_seq, 2u);
  EXPECT_GT(a.command.velocity.y(), 0.5) << "flies the task toward the goal, with the swarm";
}

TEST(DroneBrain, ACommandOfTheJoiningTickIsAppliedNotCaughtUp) {
  Swarm s(1);
  s.run(1);
  s.relay(MissionType::kTakeoff, 2.0);
  s.brains[0] = std::make_unique<DroneBrain>(0, 1, s.agent, s.comm, 1);
  s.brains[0]->start(s.scene, kRateHz, 7);
  TickAnswer a = s.step()[0];
  EXPECT_TRUE(says(a, "takeoff seq 1 accepted at tick 50"));
  EXPECT_FALSE(says(a, "joined mid-mission"));
}

TEST(DroneBrain, RefusesMalformedCommandsAndCountsThem) {
  Swarm s(1);
  s.relay(MissionType::kMove).problem = "velocity is not finite";
  TickAnswer a = s.step()[0];
  ASSERT_EQ(a.acks.size(), 1u);
  EXPECT_FALSE(a.acks[0].ack.accepted);
  EXPECT_EQ(a.acks[0].ack.reason, "velocity is not finite");
  EXPECT_EQ(s.brains[0]->rejected(), 1u);
  EXPECT_EQ(s.brains[0]->phase(), Phase::kIdle);
}

TEST(DroneBrain, IgnoresCommandsForOtherDrones) {
  Swarm s(2);
  s.relay(MissionType::kTakeoff, 2.0).command.target = 1;
  const auto a = s.step();
  EXPECT_TRUE(a[0].acks.empty());
  EXPECT_EQ(a[1].acks.size(), 1u);
  EXPECT_EQ(s.brains[0]->phase(), Phase::kIdle);
  EXPECT_EQ(s.brains[1]->phase(), Phase::kTakeoff);
}

TEST(DroneBrain, ARowItCannotFlyFromIsRefusedAndCounted) {
  Swarm s(2);
  s.sample();
  s.t.drones[0].valid = false;
  EXPECT_EQ(s.brains[0]->tick(s.t).kind, TickAnswer::Kind::kNone);
  s.t.drones[0].valid = true;
  s.t.drones[0].id = 1;  // row 0 names another drone
  EXPECT_EQ(s.brains[0]->tick(s.t).kind, TickAnswer::Kind::kNone);
  s.t.drones.resize(0);
  EXPECT_EQ(s.brains[1]->tick(s.t).kind, TickAnswer::Kind::kNone);
  EXPECT_EQ(s.brains[0]->rejected(), 2u);
  EXPECT_EQ(s.brains[1]->rejected(), 1u);
}

TEST(DroneBrain, ANonFiniteRayIsNoHitAndIsCounted) {
  Swarm s(1);
  s.relay(MissionType::kTakeoff, 2.0);
  s.run(6);
  const std::vector<float> range{0.5f, NAN}, yaw{0.0f, 3.14f}, elevation{0.0f, 0.0f};
  const std::vector<std::uint8_t> hit{1, 1};
  s.sample();
  s.t.drones[0].ray_range_m = range;
  s.t.drones[0].ray_hit = hit;
  s.t.drones[0].ray_yaw_body_rad = yaw;
  s.t.drones[0].ray_elevation_body_rad = elevation;
  TickAnswer a = s.brains[0]->tick(s.t);
  EXPECT_EQ(s.brains[0]->rejected(), 1u);
  // The one sound ray, half a metre ahead: the sensor term pushes back.
  EXPECT_LT(a.command.velocity.x(), -0.1);
}

TEST(DroneBrain, AScanWithMismatchedSequencesOrANonFiniteElevationIsRefusedAndCounted) {
  Swarm s(1);
  s.relay(MissionType::kTakeoff, 2.0);
  s.run(6);
  const std::vector<float> range{0.5f, 0.5f}, yaw{0.0f, 0.0f}, bad_elevation{0.0f, NAN},
      short_elevation{0.0f};
  const std::vector<std::uint8_t> hit{1, 1};
  for (const auto* elevation : {&bad_elevation, &short_elevation}) {
    s.sample();
    s.t.drones[0].ray_range_m = range;
    s.t.drones[0].ray_hit = hit;
    s.t.drones[0].ray_yaw_body_rad = yaw;
    s.t.drones[0].ray_elevation_body_rad = *elevation;
    const std::uint64_t before = s.brains[0]->rejected();
    TickAnswer a = s.brains[0]->tick(s.t);
    EXPECT_EQ(s.brains[0]->rejected(), before + 1);
    // Two hits half a metre ahead would push back hard; the refused scan does not.
    EXPECT_GT(a.command.velocity.x(), -0.05);
    s.run(0.02);  // the next tick
  }
}

TEST(DroneBrain, AFaultedLawHoversThenLandsAndRefusesMissions) {
  AgentConfig cfg;
  LawOverride faulty;
  faulty.ids = {0};
  faulty.law.fault = LawConfig::Fault::kNaN;
  faulty.law.fault_after_s = 4.0;
  cfg.overrides.push_back(faulty);
  Swarm s(2, cfg);
  s.relay(MissionType::kTakeoff, 2.0);
  s.run(3.9);
  ASSERT_TRUE(s.brains[0]->law_fault().empty());
  bool noted = false;
  for (int k = 0; k < 20; ++k)
    noted |= says(s.step()[0], "drone 0: the thesis law faulted at sim time 4.00 s");
  EXPECT_TRUE(noted);
  EXPECT_EQ(s.brains[0]->phase(), Phase::kFailsafe);
  EXPECT_NE(s.brains[0]->law_fault().find("non-finite"), std::string::npos)
      << s.brains[0]->law_fault();
  // Hovers: no horizontal motion, commands finite and marked failsafe.
  TickAnswer a = s.step()[0];
  EXPECT_EQ(a.command.phase, Phase::kFailsafe);
  EXPECT_LT(a.command.velocity.head<2>().norm(), 1e-9);
  EXPECT_TRUE(a.command.velocity.allFinite());
  s.relay(MissionType::kTask, 1.0);
  a = s.step()[0];
  ASSERT_EQ(a.acks.size(), 1u);
  EXPECT_FALSE(a.acks[0].ack.accepted);
  EXPECT_NE(a.acks[0].ack.reason.find("swarm law faulted: "), std::string::npos);
  // Then lands, and switches its motors off on the ground.
  s.run(12);
  EXPECT_LT(s.p[0].z(), 0.15) << "down (the plant has no gravity once the motors stop)";
  EXPECT_FALSE(s.step()[0].command.motors_on);
  EXPECT_GE(s.brains[0]->law_faults(), 1u);
  EXPECT_TRUE(s.brains[1]->law_fault().empty()) << "a law's fault stays its drone's";
}

TEST(DroneBrain, SendsItsBeaconWhenDueAndOnlyOnceATick) {
  CommConfig comm;
  comm.source = PeerSourceType::kBeacons;
  comm.beacon_rate_hz = 10;  // every 5 ticks at 50 Hz
  Swarm s(2, {}, comm);
  TickAnswer a = s.ask(0);
  ASSERT_TRUE(a.command.beacon.has_value());
  EXPECT_TRUE(a.publish_beacon);
  EXPECT_EQ(a.command.beacon->reported_p, s.p[0]);
  TickAnswer again = s.ask(0);
  EXPECT_EQ(again.kind, TickAnswer::Kind::kRepeat);
  EXPECT_TRUE(again.command.beacon.has_value()) << "the command carries it as before";
  EXPECT_FALSE(again.publish_beacon);
  s.step();
  for (int k = 1; k < 5; ++k) EXPECT_FALSE(s.step()[0].command.beacon.has_value());
  EXPECT_TRUE(s.step()[0].command.beacon.has_value());
}

TEST(DroneBrain, HearsItsPeersOnlyThroughTheirBeacons) {
  CommConfig comm;
  comm.source = PeerSourceType::kBeacons;
  Swarm s(2, {}, comm);
  s.relay(MissionType::kTakeoff, 2.0);
  s.run(6);
  // No beacon relayed: drone 0 has heard of nobody, whatever the truth says.
  EXPECT_TRUE(s.brains[0]->modelled() != nullptr);
  auto* heard = const_cast<ModelledPeerSource*>(s.brains[0]->modelled());
  EXPECT_TRUE(heard->heard(s.t.sim_time_s).empty());
  s.sample();
  s.t.beacons.push_back({1, s.tick, s.t.sim_time_s, s.p[1], s.p[1]});
  s.t.beacons.push_back({0, s.tick, s.t.sim_time_s, s.p[0], s.p[0]});  // its own: ignored
  s.t.beacons.push_back({7, s.tick, s.t.sim_time_s, s.p[1], s.p[1]});  // no such drone
  s.brains[0]->tick(s.t);
  ++s.tick;  // delivered at the next tick at the earliest
  s.sample();
  s.t.beacons.clear();
  s.brains[0]->tick(s.t);
  const auto peers = heard->heard(s.t.sim_time_s);
  ASSERT_EQ(peers.size(), 1u);
  EXPECT_EQ(peers[0].id, 1);
}

TEST(DroneBrain, ANewServerStartsTheMissionOverFromItsRing) {
  Swarm s(1);
  s.relay(MissionType::kTakeoff, 2.0);
  s.run(6);
  s.brains[0]->reset();
  EXPECT_FALSE(s.brains[0]->started());
  EXPECT_EQ(s.ask(0).kind, TickAnswer::Kind::kNone);
  s.brains[0]->start(s.scene, kRateHz, 7);
  EXPECT_TRUE(says(s.step()[0], "joined mid-mission: caught up with takeoff seq 1"));
  EXPECT_EQ(s.brains[0]->phase(), Phase::kHold);
}
