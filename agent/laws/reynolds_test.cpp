#include "reynolds.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <string>
#include <vector>

#include "flock_sim.hpp"

namespace ddswarm::agent::laws {
namespace {

using Eigen::Vector3d;

law::Peer peer(const Vector3d& p, const Vector3d& v = Vector3d::Zero()) {
  law::Peer q;
  q.p_world = p;
  q.v_world = v;
  return q;
}

const Vector3d kP{10, -5, 2};  // the drone under test, off the origin

// --- separation -------------------------------------------------------------

TEST(ReynoldsSeparation, PushesAwayFromACloseNeighbourWithInverseDistanceWeight) {
  const std::vector<law::Peer> east{peer(kP + Vector3d(2, 0, 0))};
  const Vector3d s = separation(kP, east, 4.0, 1.0);
  // 1/s * 4 m * (4/2 - 1) = 4 m/s, straight away from the peer
  EXPECT_NEAR(s.x(), -4.0, 1e-12);
  EXPECT_NEAR(s.y(), 0.0, 1e-12);
  EXPECT_NEAR(s.z(), 0.0, 1e-12);
  // Closer pushes harder, more than linearly: 4 m * (4/1 - 1) = 12 m/s at 1 m.
  const std::vector<law::Peer> close{peer(kP + Vector3d(1, 0, 0))};
  EXPECT_NEAR(separation(kP, close, 4.0, 1.0).x(), -12.0, 1e-12);
  // The gain scales it.
  EXPECT_NEAR(separation(kP, east, 4.0, 0.5).x(), -2.0, 1e-12);
}

TEST(ReynoldsSeparation, IsZeroFromTheSeparationDistanceOnAndContinuousThere) {
  for (double d : {4.0, 4.5, 20.0}) {
    const std::vector<law::Peer> q{peer(kP + Vector3d(0, d, 0))};
    EXPECT_EQ(separation(kP, q, 4.0, 1.0), Vector3d::Zero()) << d;
  }
  const std::vector<law::Peer> just_inside{peer(kP + Vector3d(0, 3.99, 0))};
  const Vector3d s = separation(kP, just_inside, 4.0, 1.0);
  EXPECT_LT(s.y(), 0.0);
  EXPECT_LT(s.norm(), 0.02);  // no step as a peer crosses the separation distance
}

TEST(ReynoldsSeparation, SumsNeighboursAndIgnoresUndefinedOnes) {
  // Two peers either side cancel; a third only counts when finite and apart.
  const std::vector<law::Peer> both{peer(kP + Vector3d(2, 0, 0)), peer(kP - Vector3d(2, 0, 0))};
  EXPECT_LT(separation(kP, both, 4.0, 1.0).norm(), 1e-12);
  const std::vector<law::Peer> odd{peer(kP), peer(Vector3d(NAN, 0, 0)),
                                   peer(kP + Vector3d(0, 2, 0))};
  const Vector3d s = separation(kP, odd, 4.0, 1.0);
  ASSERT_TRUE(s.allFinite());
  EXPECT_NEAR(s.y(), -4.0, 1e-12);
  EXPECT_NEAR(s.x(), 0.0, 1e-12);
}

// --- alignment --------------------------------------------------------------

TEST(ReynoldsAlignment, DrivesTowardTheNeighboursMeanVelocity) {
  const Neighbourhood n{10.0, 360.0};
  const std::vector<law::Peer> q{peer(kP + Vector3d(3, 0, 0), Vector3d(1, 0, 0)),
                                 peer(kP + Vector3d(0, 3, 0), Vector3d(1, 1, 0))};
  const Vector3d own(0, 0.2, 0);
  const Vector3d a = alignment(kP, own, q, n, 2.0);  // mean (1, 0.5, 0)
  EXPECT_NEAR(a.x(), 2.0 * 1.0, 1e-12);
  EXPECT_NEAR(a.y(), 2.0 * 0.3, 1e-12);
  EXPECT_NEAR(a.z(), 0.0, 1e-12);
  // Matched: nothing to do.
  EXPECT_LT(alignment(kP, Vector3d(1, 0.5, 0), q, n, 2.0).norm(), 1e-12);
}

TEST(ReynoldsAlignment, SkipsPeersWithoutVelocityAndBeyondTheRadius) {
  const Neighbourhood n{10.0, 360.0};
  const std::vector<law::Peer> q{peer(kP + Vector3d(3, 0, 0), Vector3d(1, 0, 0)),
                                 peer(kP + Vector3d(0, 3, 0), Vector3d(NAN, NAN, NAN)),
                                 peer(kP + Vector3d(10.5, 0, 0), Vector3d(0, -5, 0))};
  const Vector3d a = alignment(kP, Vector3d::Zero(), q, n, 1.0);
  ASSERT_TRUE(a.allFinite());
  EXPECT_NEAR((a - Vector3d(1, 0, 0)).norm(), 0.0, 1e-12);
  // Nobody usable: zero, not NaN.
  const std::vector<law::Peer> none{q[1], q[2]};
  EXPECT_EQ(alignment(kP, Vector3d(0.3, 0, 0), none, n, 1.0), Vector3d::Zero());
  // radius 0: every peer counts, however far.
  const Vector3d all = alignment(kP, Vector3d::Zero(), q, Neighbourhood{0.0, 360.0}, 1.0);
  EXPECT_NEAR((all - Vector3d(0.5, -2.5, 0)).norm(), 0.0, 1e-12);
}

// --- cohesion ---------------------------------------------------------------

TEST(ReynoldsCohesion, PointsToTheNeighboursCentroid) {
  const Neighbourhood n{10.0, 360.0};
  const std::vector<law::Peer> q{peer(kP + Vector3d(2, 0, 0)), peer(kP + Vector3d(0, 4, 0)),
                                 peer(kP + Vector3d(-20, 0, 0))};  // beyond the radius
  const Vector3d c = cohesion(kP, Vector3d::Zero(), q, n, 0.3);
  EXPECT_NEAR((c - 0.3 * Vector3d(1, 2, 0)).norm(), 0.0, 1e-12);
  // Far from the origin the offsets keep full precision.
  const Vector3d far(1e7, -1e7, 2);
  std::vector<law::Peer> shifted;
  for (const auto& p : q) shifted.push_back(peer(p.p_world - kP + far));
  EXPECT_NEAR((cohesion(far, Vector3d::Zero(), shifted, n, 0.3) - c).norm(), 0.0, 1e-9);
  EXPECT_EQ(cohesion(kP, Vector3d::Zero(), std::span<const law::Peer>{}, n, 0.3), Vector3d::Zero());
}

// --- the neighbourhood ------------------------------------------------------

TEST(ReynoldsNeighbourhood, RadiusAndFieldOfViewAroundTheVelocity) {
  const Neighbourhood n{10.0, 90.0};  // +-45 deg about the velocity
  const Vector3d v(1, 0, 0);
  const auto at = [](double deg, double r) {
    const double a = deg * std::numbers::pi / 180.0;
    return Vector3d(r * std::cos(a), r * std::sin(a), 0);
  };
  EXPECT_TRUE(in_neighbourhood(at(0, 10.0), v, n));  // on the radius: in
  EXPECT_FALSE(in_neighbourhood(at(0, 10.01), v, n));
  EXPECT_TRUE(in_neighbourhood(at(44, 5), v, n));
  EXPECT_FALSE(in_neighbourhood(at(46, 5), v, n));
  EXPECT_FALSE(in_neighbourhood(at(180, 1), v, n));  // right behind
  // Hovering, the heading is undefined: the view is all around.
  EXPECT_TRUE(in_neighbourhood(at(180, 1), Vector3d(0.05, 0, 0), n));
  EXPECT_TRUE(in_neighbourhood(at(180, 1), v, Neighbourhood{10.0, 360.0}));
  EXPECT_FALSE(in_neighbourhood(Vector3d(NAN, 0, 0), v, Neighbourhood{0.0, 360.0}));

  // Cohesion and alignment ignore the peer behind; separation does not.
  const std::vector<law::Peer> behind{peer(kP + Vector3d(-2, 0, 0), Vector3d(0, 1, 0))};
  EXPECT_EQ(cohesion(kP, v, behind, n, 0.3), Vector3d::Zero());
  EXPECT_EQ(alignment(kP, v, behind, n, 1.0), Vector3d::Zero());
  EXPECT_GT(separation(kP, behind, 4.0, 1.0).x(), 0.0);
}

// --- combination ------------------------------------------------------------

TEST(ReynoldsAllocation, SpendsTheBudgetInPrecedenceOrder) {
  const std::vector<Vector3d> pressed{{2, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  EXPECT_NEAR((allocate_by_priority(pressed, 1.5) - Vector3d(1.5, 0, 0)).norm(), 0, 1e-12);
  const std::vector<Vector3d> partial{{0.5, 0, 0}, {0, 0.7, 0}, {0, 0, 1}};
  EXPECT_NEAR((allocate_by_priority(partial, 1.5) - Vector3d(0.5, 0.7, 0.3)).norm(), 0, 1e-12);
  const std::vector<Vector3d> light{{0.2, 0, 0}, {0, 0.2, 0}, {0, 0, 0.2}};
  EXPECT_NEAR((allocate_by_priority(light, 1.5) - Vector3d(0.2, 0.2, 0.2)).norm(), 0, 1e-12);
}

law::Observation observe(const std::vector<law::Peer>& peers) {
  law::Observation o;
  o.p_world = kP;
  o.peers = peers;
  o.inter_distance_m = 4.0;
  o.max_speed_mps = 3.0;
  return o;
}

TEST(ReynoldsLaw, AloneItFliesTheMissionAndRespectsTheSpeedLimit) {
  law::Observation o = observe({});
  o.mission_velocity = Vector3d(0.8, 0, 0);
  o.v_world = Vector3d(0, 2, 0);
  EXPECT_EQ(reynolds_terms(o, ReynoldsConfig{}).velocity, Vector3d(0.8, 0, 0));
  o.mission_velocity = Vector3d(5, 0, 0);
  EXPECT_NEAR(reynolds_terms(o, ReynoldsConfig{}).velocity.norm(), 3.0, 1e-12);
}

TEST(ReynoldsLaw, PriorityLetsAClosePeerOverrideCentering) {
  // A peer 1 m to the south, the rest of the neighbourhood 9 m and more to
  // the south: separation pushes north, cohesion pulls south.
  const std::vector<law::Peer> q{peer(kP + Vector3d(0, -1, 0)), peer(kP + Vector3d(0, -9, 0)),
                                 peer(kP + Vector3d(0, -9.5, 0))};
  const law::Observation o = observe(q);
  ReynoldsConfig c;
  const ReynoldsTerms t = reynolds_terms(o, c);
  ASSERT_NEAR(t.separation.y(), 12.0, 1e-12);      // 4 m * (4/1 - 1), uncapped
  ASSERT_NEAR(t.cohesion.y(), 0.3 * -6.5, 1e-12);  // toward the centroid
  // Prioritised: collision avoidance takes the whole budget, away from the peer.
  EXPECT_NEAR((t.velocity - Vector3d(0, c.max_term_mps, 0)).norm(), 0.0, 1e-12);
  // A capped sum instead lets centering cancel it: the drone stays 1 m from its peer.
  c.priority = false;
  EXPECT_NEAR(reynolds_terms(o, c).velocity.norm(), 0.0, 1e-12);
}

TEST(ReynoldsLaw, CruiseSpeedKeepsTheDroneFlyingItsWay) {
  law::Observation o = observe({});
  o.v_world = Vector3d(0.3, 0.4, 0);
  ReynoldsConfig c;
  EXPECT_EQ(reynolds_terms(o, c).velocity, Vector3d::Zero());  // no cruise: it stops
  c.cruise_speed_mps = 1.0;
  EXPECT_NEAR((reynolds_terms(o, c).velocity - Vector3d(0.6, 0.8, 0)).norm(), 0.0, 1e-12);
  o.mission_velocity = Vector3d(0.3, 0.4, 0);  // no motion relative to the mission
  EXPECT_EQ(reynolds_terms(o, c).velocity, Vector3d(0.3, 0.4, 0));
}

// --- parameters ---------------------------------------------------------------

law::LawContext context() {
  law::LawContext ctx;
  ctx.drone_id = 0;
  ctx.num_drones = 4;
  ctx.inter_distance_m = 4.0;
  return ctx;
}

std::string refused_field(std::map<std::string, std::string> kv) {
  law::Params p("agent.law.params", std::move(kv));
  try {
    make_reynolds(p, law::Rng(1), context());
  } catch (const law::ParamError& e) {
    return e.field();
  }
  return "";
}

TEST(ReynoldsParams, RefusesUnknownKeysAndOutOfRangeValuesNamingTheField) {
  EXPECT_EQ(refused_field({{"radius", "10"}}), "agent.law.params.radius");
  EXPECT_EQ(refused_field({{"separation_gain", "-1"}}), "agent.law.params.separation_gain");
  EXPECT_EQ(refused_field({{"alignment_gain", "fast"}}), "agent.law.params.alignment_gain");
  EXPECT_EQ(refused_field({{"cohesion_gain", "11"}}), "agent.law.params.cohesion_gain");
  EXPECT_EQ(refused_field({{"fov_deg", "400"}}), "agent.law.params.fov_deg");
  EXPECT_EQ(refused_field({{"fov_deg", "0"}}), "agent.law.params.fov_deg");
  EXPECT_EQ(refused_field({{"max_term_mps", "0"}}), "agent.law.params.max_term_mps");
  EXPECT_EQ(refused_field({{"radius_m", "-2"}}), "agent.law.params.radius_m");
  EXPECT_EQ(refused_field({{"cruise_speed_mps", "25"}}), "agent.law.params.cruise_speed_mps");
  EXPECT_EQ(refused_field({{"combine", "average"}}), "agent.law.params.combine");
  // The refusal of a typo lists what the law takes.
  law::Params p("agent.law.params", {{"radius", "10"}});
  try {
    make_reynolds(p, law::Rng(1), context());
    ADD_FAILURE() << "a typo was accepted";
  } catch (const law::ParamError& e) {
    for (const char* key : {"radius_m", "max_term_mps", "combine"})
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << key;
  }
}

TEST(ReynoldsParams, SeparationMustBeInsideTheRadius) {
  EXPECT_EQ(refused_field({{"separation_m", "6"}, {"radius_m", "5"}}),
            "agent.law.params.separation_m");
  EXPECT_EQ(refused_field({{"separation_m", "10"}}),  // default radius 2.5 * 4 m
            "agent.law.params.separation_m");
  EXPECT_EQ(refused_field({{"radius_m", "4"}}),  // default separation D_int = 4 m
            "agent.law.params.radius_m");
  EXPECT_EQ(refused_field({{"separation_m", "10"}, {"radius_m", "0"}}), "");  // every peer
  EXPECT_EQ(refused_field({{"separation_m", "9.9"}}), "");
}

TEST(ReynoldsParams, AValidSetBuildsALawThatUsesIt) {
  law::Params p("agent.law.params", {{"radius_m", "6"},
                                     {"separation_m", "2"},
                                     {"separation_gain", "0.5"},
                                     {"alignment_gain", "0"},
                                     {"cohesion_gain", "0"},
                                     {"fov_deg", "270"},
                                     {"max_term_mps", "2"},
                                     {"cruise_speed_mps", "0"},
                                     {"combine", "sum"}});
  const auto law = make_reynolds(p, law::Rng(7), context());
  ASSERT_NE(law, nullptr);
  EXPECT_TRUE(law->uses_obstacle_term());
  // separation_m = 2: a peer at 1.5 m pushes (0.5 * 2 * (2/1.5 - 1) = 1/3 m/s), one at 2.5 m not.
  std::vector<law::Peer> q{peer(kP + Vector3d(1.5, 0, 0))};
  EXPECT_NEAR(law->step(observe(q)).velocity_world.x(), -1.0 / 3.0, 1e-12);
  q = {peer(kP + Vector3d(2.5, 0, 0))};
  EXPECT_EQ(law->step(observe(q)).velocity_world, Vector3d::Zero());
}

// --- the aggregate (Reynolds 1987, section 4) --------------------------------

constexpr int kFlockSize = 16;
constexpr double kDInt = 4.0;  // m, FlockSim's default D_int

struct FlockRun {
  double order_at_10s = 0;           // FlockSim::order() at t = 10 s
  double min_order_20_30s = 1;       // its minimum over 20..30 s
  double min_distance_m = HUGE_VAL;  // over the whole run, the start included
  double min_distance_after_5s_m = HUGE_VAL;
  double max_diameter_after_20s_m = 0;  // the widest pair
  bool always_connected = true;         // the default-radius neighbourhood graph, every tick
  double max_mean_velocity_error_after_10s = 0;  // |mean velocity - V_mission|, m/s
  std::vector<Vector3d> final_positions;
};

bool connected(const FlockSim& s, double radius_m) {
  std::vector<bool> seen(s.drones.size(), false);
  std::vector<std::size_t> todo{0};
  seen[0] = true;
  std::size_t count = 1;
  while (!todo.empty()) {
    const std::size_t i = todo.back();
    todo.pop_back();
    for (std::size_t j = 0; j < s.drones.size(); ++j)
      if (!seen[j] && (s.drones[i].p - s.drones[j].p).norm() <= radius_m) {
        seen[j] = true;
        ++count;
        todo.push_back(j);
      }
  }
  return count == s.drones.size();
}

double diameter(const FlockSim& s) {
  double m = 0;
  for (const auto& a : s.drones)
    for (const auto& b : s.drones) m = std::max(m, (a.p - b.p).norm());
  return m;
}

/// 16 drones at seeded random positions in a 10 m x 10 m square (no two
/// closer than 1 m) with seeded random headings at 1.5 m/s, flown for 30 s.
FlockRun fly(std::uint64_t seed, const std::map<std::string, std::string>& params,
             const Vector3d& mission = Vector3d::Zero()) {
  FlockSim s;
  s.mission_velocity = mission;
  s.inter_distance_m = kDInt;
  law::Rng rng(seed);
  std::vector<Eigen::Vector2d> at;
  while (at.size() < kFlockSize) {
    const Eigen::Vector2d q(rng.uniform(0, 10), rng.uniform(0, 10));
    if (std::all_of(at.begin(), at.end(), [&](const auto& a) { return (a - q).norm() >= 1.0; }))
      at.push_back(q);
  }
  law::LawContext ctx = context();
  ctx.num_drones = kFlockSize;
  for (int i = 0; i < kFlockSize; ++i) {
    law::Params p("agent.law.params", params);
    ctx.drone_id = i;
    const double heading = rng.uniform(0, 2 * std::numbers::pi);
    s.add(make_reynolds(p, law::Rng(seed + i), ctx), at[i].x(), at[i].y(), 1.5 * std::cos(heading),
          1.5 * std::sin(heading));
  }
  FlockRun r;
  const long ticks = std::lround(30.0 / s.dt_s);
  for (long k = 1; k <= ticks; ++k) {
    s.step();
    const double t = static_cast<double>(k) * s.dt_s;
    if (k == std::lround(10.0 / s.dt_s)) r.order_at_10s = s.order();
    if (t >= 20.0 - 1e-9) {
      r.min_order_20_30s = std::min(r.min_order_20_30s, s.order());
      r.max_diameter_after_20s_m = std::max(r.max_diameter_after_20s_m, diameter(s));
    }
    if (t > 5.0)
      r.min_distance_after_5s_m = std::min(r.min_distance_after_5s_m, s.min_distance_m());
    if (t >= 10.0 - 1e-9)
      r.max_mean_velocity_error_after_10s =
          std::max(r.max_mean_velocity_error_after_10s, (s.mean_velocity() - mission).norm());
    r.always_connected = r.always_connected && connected(s, 2.5 * kDInt);
  }
  r.min_distance_m = s.min_distance_seen_m;
  for (const auto& d : s.drones) r.final_positions.push_back(d.p);
  return r;
}

// Free flock (cruise 1 m/s, no mission), seeds 1-3. Over seeds 1-30 the
// figures are: order > 0.95 after 3.4-5.2 s, order(10 s) >= 0.994; closest
// pair after 5 s >= 2.87 m (0.72 D_int), over the whole run >= 0.77 m;
// widest pair after 20 s <= 15.0 m; the 10 m neighbourhood graph never splits.
TEST(ReynoldsFlock, RandomHeadingsBecomeOnePolarisedSeparatedFlock) {
  for (std::uint64_t seed : {1, 2, 3}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const FlockRun r = fly(seed, {{"cruise_speed_mps", "1"}});
    EXPECT_GT(r.order_at_10s, 0.99);
    EXPECT_GT(r.min_order_20_30s, 0.99);
    EXPECT_TRUE(r.always_connected);
    EXPECT_LT(r.max_diameter_after_20s_m, 4.0 * kDInt);
    EXPECT_GT(r.min_distance_after_5s_m, 0.7 * kDInt);
    EXPECT_GT(r.min_distance_m, 0.5);
  }
}

// The control: velocity matching is what polarises. Without it the same
// flocks are still disordered at 10 s (seeds 1-30: median 0.07, max 0.73).
TEST(ReynoldsFlock, WithoutVelocityMatchingTheFlockStaysDisordered) {
  double sum = 0;
  for (std::uint64_t seed : {1, 2, 3}) {
    const FlockRun r = fly(seed, {{"cruise_speed_mps", "1"}, {"alignment_gain", "0"}});
    EXPECT_LT(r.order_at_10s, 0.5) << "seed " << seed;
    sum += r.order_at_10s;
  }
  EXPECT_LT(sum / 3, 0.3);
}

// The thesis task: defaults, V_mission = (0.8, 0, 0). Seeds 1-30: the mean
// velocity is within 0.05 m/s of V_mission from 1.2-4.9 s on.
TEST(ReynoldsFlock, FlockFliesTheMissionVelocity) {
  const Vector3d mission(0.8, 0, 0);
  for (std::uint64_t seed : {1, 2, 3}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const FlockRun r = fly(seed, {}, mission);
    EXPECT_LT(r.max_mean_velocity_error_after_10s, 0.05);
    EXPECT_GT(r.min_order_20_30s, 0.99);
    EXPECT_TRUE(r.always_connected);
    EXPECT_LT(r.max_diameter_after_20s_m, 4.0 * kDInt);
    EXPECT_GT(r.min_distance_after_5s_m, 0.7 * kDInt);
    EXPECT_GT(r.min_distance_m, 0.5);
  }
}

TEST(ReynoldsFlock, SameSeedSamePositionsBitForBit) {
  const std::map<std::string, std::string> params{{"cruise_speed_mps", "1"}, {"fov_deg", "300"}};
  const FlockRun a = fly(11, params), b = fly(11, params), c = fly(12, params);
  ASSERT_EQ(a.final_positions.size(), b.final_positions.size());
  for (std::size_t i = 0; i < a.final_positions.size(); ++i)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(a.final_positions[i][k], b.final_positions[i][k]);
  EXPECT_NE(a.final_positions[0], c.final_positions[0]);  // the seed matters
}

}  // namespace
}  // namespace ddswarm::agent::laws
