#include "agent/law_frame.hpp"

#include <gtest/gtest.h>

#include <random>

#include "agent/law_registry.hpp"

using namespace ddswarm;
using namespace ddswarm::agent;

namespace {

/// A law that answers a fixed velocity and counts its calls.
class FixedLaw final : public law::SwarmLaw {
 public:
  FixedLaw(Eigen::Vector3d v, bool obstacle_term) : v_(v), obstacle_term_(obstacle_term) {}
  law::Command step(const law::Observation&) override {
    ++calls;
    return {v_, 0.25};
  }
  bool uses_obstacle_term() const override { return obstacle_term_; }
  int calls = 0;

 private:
  Eigen::Vector3d v_;
  bool obstacle_term_;
};

/// One drone's tick, random but valid, as the agent hands it to a law.
struct Tick {
  std::vector<Eigen::Vector3d> peers;
  std::vector<float> range, yaw, elevation;
  std::vector<std::uint8_t> hit;
  std::vector<law::Peer> law_peers;
  std::vector<law::Ray> law_rays;
  LawInput in;
  law::Observation o;

  explicit Tick(std::mt19937_64& g) {
    std::uniform_real_distribution<double> u(-1, 1);
    const int n = static_cast<int>(g() % 14);
    in.p_world = Eigen::Vector3d(8 * u(g), 8 * u(g), 2 + u(g));
    for (int j = 0; j < n; ++j) {
      // Some peers close, some far, some on the drone's own altitude.
      const double s = j % 3 == 0 ? 1.5 : 9.0;
      peers.push_back(in.p_world + Eigen::Vector3d(s * u(g), s * u(g), j % 2 ? 0.0 : 0.5 * u(g)));
    }
    const int rays = (g() % 2) ? 12 : 0;
    const bool rows = rays && g() % 2;  // 3 rows of 4, or the ring of 12
    for (int k = 0; k < rays; ++k) {
      yaw.push_back(static_cast<float>(rows ? 2 * M_PI * (k % 4) / 4 : 2 * M_PI * k / rays));
      elevation.push_back(rows ? static_cast<float>(0.3 * (k / 4 - 1)) : 0.0f);
      hit.push_back(g() % 3 == 0);
      range.push_back(static_cast<float>(3.0 + 3.0 * u(g)));
    }
    in.q_world_body = Eigen::Quaterniond(Eigen::AngleAxisd(M_PI * u(g), Eigen::Vector3d::UnitZ()));
    in.peers_world = peers;
    in.ray_range_m = range;
    in.ray_hit = hit;
    in.ray_yaw_body_rad = yaw;
    in.ray_elevation_body_rad = elevation;
    in.mission_velocity = Eigen::Vector3d(u(g), u(g), 0.3 * u(g));
    in.inter_distance_m = 3 + u(g);
    in.swarm_enabled = g() % 4 != 0;
    in.obstacle_avoidance_enabled = g() % 4 != 0;
    in.swarm_horizontal_only = g() % 4 == 0;
    in.altitude_hold = !in.swarm_horizontal_only && g() % 3 != 0;
    in.altitude_target_m = 2 + u(g);
    for (std::size_t j = 0; j < peers.size(); ++j)
      law_peers.push_back({static_cast<int>(j + 1), peers[j], {0, 0, 0}, 0});
    for (std::size_t k = 0; k < range.size(); ++k)
      law_rays.push_back({range[k], hit[k] != 0, yaw[k], elevation[k]});
    o.p_world = in.p_world;
    o.q_world_body = in.q_world_body;
    o.peers = law_peers;
    o.rays = law_rays;
    o.mission_velocity = in.mission_velocity;
    o.inter_distance_m = in.inter_distance_m;
    o.phase = in.swarm_horizontal_only ? law::Phase::kLanding : law::Phase::kTask;
  }
};

/// A drone hovering at 2 m whose one ray hits a pillar 1.5 m ahead (+x).
struct PillarAhead {
  std::vector<float> range{1.5f}, yaw{0.0f};
  std::vector<std::uint8_t> hit{1};
  LawInput in;
  PillarAhead() {
    in.p_world = {0, 0, 2};
    in.altitude_target_m = 2;
    in.ray_range_m = range;
    in.ray_hit = hit;
    in.ray_yaw_body_rad = yaw;
  }
};

}  // namespace

// Table 1 stays the same to the last digit: the thesis's law asked through
// the interface gives evaluate_law's command bit for bit, whatever the
// options (k nearest, safety distance, slide, altitude hold, landing).
TEST(LawFrame, TheThesisLawThroughTheInterfaceIsBitIdentical) {
  std::mt19937_64 g(7);
  for (int variant = 0; variant < 4; ++variant) {
    AgentConfig c;
    c.activation.neighbours = variant == 1 ? 3 : 0;
    c.sensor_function.safety_distance_m = variant == 2 ? 2.5 : 0.0;
    c.sensor_function.slide_gain = variant == 3 ? 0.0 : 1.0;
    c.sensor_function.type = variant == 3 ? SensorFunctionType::kLog : SensorFunctionType::kFs1;
    law::LawContext ctx;
    auto thesis = make_law(LawConfig{}, ctx, law::Rng(1), c);
    for (int i = 0; i < 2000; ++i) {
      Tick t(g);
      const Eigen::Vector3d want = evaluate_law(t.in, c).velocity;
      const Eigen::Vector3d got = step_law(thesis.get(), t.o, t.in, c).terms.velocity;
      for (int k = 0; k < 3; ++k)
        ASSERT_EQ(got[k], want[k]) << "variant " << variant << ", case " << i << ", axis " << k;
    }
  }
}

TEST(LawFrame, TheLawIsAskedOnlyWhileTheSwarmFlies) {
  std::mt19937_64 g(3);
  Tick t(g);
  AgentConfig c;
  FixedLaw l({1, 0, 0}, true);
  t.in.swarm_enabled = false;  // takeoff: the mission velocity alone
  const LawStep r = step_law(&l, t.o, t.in, c);
  EXPECT_EQ(l.calls, 0);
  EXPECT_EQ(r.terms.velocity, evaluate_law(t.in, c).velocity);
  t.in.swarm_enabled = true;
  step_law(&l, t.o, t.in, c);
  EXPECT_EQ(l.calls, 1);
}

TEST(LawFrame, ALawThatOptsOutOfTheObstacleTermIsNotPushedByIt) {
  PillarAhead ahead;
  LawInput& in = ahead.in;
  AgentConfig c;
  FixedLaw keeps({0, 0.5, 0}, true), own({0, 0.5, 0}, false);
  const Eigen::Vector3d pushed = step_law(&keeps, {}, in, c).terms.velocity;
  const Eigen::Vector3d not_pushed = step_law(&own, {}, in, c).terms.velocity;
  EXPECT_LT(pushed.x(), -1.0) << "fs1 at 1.5 m pushes back along -x";
  EXPECT_DOUBLE_EQ(not_pushed.x(), 0.0);
  EXPECT_DOUBLE_EQ(not_pushed.y(), 0.5);
  EXPECT_DOUBLE_EQ(step_law(&own, {}, in, c).yaw_rate_rad_s, 0.25);
}

TEST(LawFrame, LandingKeepsTheMissionsDescentAndTheLimitsHold) {
  LawInput in;
  in.p_world = {0, 0, 1};
  in.swarm_horizontal_only = true;
  in.altitude_hold = false;
  in.mission_velocity = {0, 0, -0.5};
  AgentConfig c;
  FixedLaw climbs({10, 0, 5}, true);
  const Eigen::Vector3d v = step_law(&climbs, {}, in, c).terms.velocity;
  EXPECT_LE(v.norm(), c.max_speed_mps + 1e-12);
  EXPECT_LT(v.z(), 0) << "the law's climb does not hold a landing drone up";
}

TEST(LawFrame, ANonFiniteAnswerOrAThrowIsAFaultAndTheMissionFliesAlone) {
  std::mt19937_64 g(11);
  Tick t(g);
  t.in.swarm_enabled = true;
  AgentConfig c;
  law::LawContext ctx;
  Eigen::Vector3d swarm_off;
  {
    LawInput off = t.in;
    off.swarm_enabled = false;
    swarm_off = evaluate_law(off, c).velocity;
  }
  for (auto fault : {LawConfig::Fault::kNaN, LawConfig::Fault::kThrow}) {
    LawConfig lc;
    lc.type = LawType::kReynolds;
    lc.fault = fault;
    lc.fault_after_s = 1.0;
    auto l = make_law(lc, ctx, law::Rng(2), c);
    t.o.sim_time_s = 0.5;  // before the fault: the law's own answer
    LawStep before = step_law(l.get(), t.o, t.in, c);
    EXPECT_TRUE(before.fault.empty()) << before.fault;
    EXPECT_TRUE(before.terms.velocity.allFinite());
    t.o.sim_time_s = 1.0;
    LawStep r = step_law(l.get(), t.o, t.in, c);
    EXPECT_EQ(r.fault, fault == LawConfig::Fault::kNaN
                           ? "answered a non-finite command (velocity nan nan nan, yaw rate 0)"
                           : "threw: injected fault (agent.law.fault: throw)");
    EXPECT_EQ(r.terms.velocity, swarm_off);
  }
}

TEST(LawFrame, EveryBuiltInLawBuildsWithItsDefaultsAndAnswersFinitely) {
  std::mt19937_64 g(5);
  AgentConfig c;
  law::LawContext ctx;
  for (auto type :
       {LawType::kThesis, LawType::kReynolds, LawType::kOlfatiSaber, LawType::kVasarhelyi}) {
    LawConfig lc;
    lc.type = type;
    EXPECT_NO_THROW(lc.validate()) << to_string(type);
    auto l = make_law(lc, ctx, law::Rng(1), c);
    for (int i = 0; i < 200; ++i) {
      Tick t(g);
      t.in.swarm_enabled = true;
      t.o.tick = static_cast<std::uint64_t>(i);
      const LawStep r = step_law(l.get(), t.o, t.in, c);
      ASSERT_TRUE(r.fault.empty()) << to_string(type) << ": " << r.fault;
      ASSERT_LE(r.terms.velocity.norm(), c.max_speed_mps + 1e-9) << to_string(type);
    }
  }
}

TEST(LawFrame, ALawsSeedDependsOnTheScenarioSeedAndTheDroneAlone) {
  EXPECT_EQ(law_seed(3, 4), law_seed(3, 4));
  EXPECT_NE(law_seed(3, 4), law_seed(3, 5));
  EXPECT_NE(law_seed(3, 4), law_seed(4, 4));
  law::Rng a(law_seed(9, 1)), b(law_seed(9, 1));
  for (int i = 0; i < 100; ++i) ASSERT_EQ(a.next(), b.next());
}

TEST(LawFrame, ObstaclesCanBeLeftToTheFrameworkOrToTheLaw) {
  // A pillar 1.5 m ahead: the framework's fs1 pushes back; a law of its own
  // sees the ray unless the framework takes obstacles over.
  PillarAhead ahead;
  LawInput& in = ahead.in;
  const std::vector<law::Ray> rays{{1.5, true, 0.0, 0.0}};
  law::Observation o;
  o.p_world = in.p_world;
  o.rays = rays;
  o.inter_distance_m = 4;
  o.max_speed_mps = 3;
  AgentConfig c;
  law::LawContext ctx;
  LawConfig own;
  own.type = LawType::kVasarhelyi;
  LawConfig by_framework = own;
  by_framework.obstacles = LawConfig::Obstacles::kFramework;
  auto l_own = make_law(own, ctx, law::Rng(1), c);
  auto l_fw = make_law(by_framework, ctx, law::Rng(1), c);
  EXPECT_FALSE(l_own->uses_obstacle_term());
  EXPECT_TRUE(l_fw->uses_obstacle_term());
  EXPECT_LT(l_own->step(o).velocity_world.x(), 0) << "its shill agent pushes it back";
  EXPECT_EQ(l_fw->step(o).velocity_world.x(), 0) << "it sees no ray";
  EXPECT_LT(step_law(l_fw.get(), o, in, c).terms.velocity.x(), -1.0) << "the framework's fs1 does";
  LawConfig thesis_alone;
  thesis_alone.obstacles = LawConfig::Obstacles::kLaw;
  auto blind = make_law(thesis_alone, ctx, law::Rng(1), c);
  EXPECT_EQ(step_law(blind.get(), o, in, c).terms.velocity.x(), 0) << "no obstacle term at all";
}
