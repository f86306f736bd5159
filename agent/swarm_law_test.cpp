#include "agent/swarm_law.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <numbers>
#include <optional>
#include <random>
#include <vector>

using namespace ddswarm::agent;
using Eigen::Vector3d;

namespace {

constexpr double kPi = std::numbers::pi;

Eigen::Quaterniond yaw(double rad) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(rad, Vector3d::UnitZ()));
}

/// Eight rays evenly spaced, the first along the body's heading (thesis Fig. 6).
std::vector<float> eight_rays() {
  std::vector<float> y;
  for (int k = 0; k < 8; ++k) y.push_back(static_cast<float>(k * kPi / 4));
  return y;
}

/// Distance along a horizontal ray from p to the nearest vertical cylinder wall.
std::optional<double> cast(const Vector3d& p, const Vector3d& dir,
                           const std::vector<std::pair<Eigen::Vector2d, double>>& pillars) {
  std::optional<double> best;
  for (const auto& [c, r] : pillars) {
    const Eigen::Vector2d o = p.head<2>() - c;
    const Eigen::Vector2d d = dir.head<2>();
    const double b = o.dot(d), q = o.squaredNorm() - r * r, disc = b * b - q;
    if (disc < 0) continue;
    const double t = -b - std::sqrt(disc);
    if (t >= 0 && (!best || t < *best)) best = t;
  }
  return best;
}

struct Scan {
  std::vector<float> range, yaw;
  std::vector<std::uint8_t> hit;
};

/// What a drone at p with attitude q sees with rays of max_m.
Scan scan(const Vector3d& p, const Eigen::Quaterniond& q,
          const std::vector<std::pair<Eigen::Vector2d, double>>& pillars, double max_m = 10) {
  Scan s;
  s.yaw = eight_rays();
  for (float y : s.yaw) {
    auto t = cast(p, ray_direction_world(y, q), pillars);
    const bool h = t && *t < max_m;
    s.hit.push_back(h);
    s.range.push_back(static_cast<float>(h ? *t : max_m));
  }
  return s;
}

}  // namespace

// ---- drone-to-drone activation ---------------------------------------------------------------

TEST(Activation, ZeroAtDintRepulsiveBelowAttractiveAboveRepulsionSteeper) {
  ActivationConfig a;
  EXPECT_EQ(f_rel(0.0, a), 0.0);
  EXPECT_DOUBLE_EQ(f_rel(-1.0, a), -1.0);  // repulsion_gain 1/s
  EXPECT_DOUBLE_EQ(f_rel(2.0, a), 0.5);    // attraction_gain 0.25/s
  for (double x : {0.1, 0.5, 1.0, 1.4}) EXPECT_GT(std::abs(f_rel(-x, a)), f_rel(x, a)) << x;
}

TEST(Activation, SaturatesAtMax) {
  ActivationConfig a;
  EXPECT_DOUBLE_EQ(f_rel(-1.5, a), -1.5);
  EXPECT_DOUBLE_EQ(f_rel(-3.9, a), -1.5);
  EXPECT_DOUBLE_EQ(f_rel(6.0, a), 1.5);
  EXPECT_DOUBLE_EQ(f_rel(100.0, a), 1.5);
}

TEST(Activation, CustomCurveMatchesItsBreakpointsAndHoldsBeyond) {
  ActivationConfig a;
  a.type = ActivationType::kCustom;
  a.points = {{-2, -1.2}, {-1, -1.0}, {0, 0}, {3, 0.6}};
  a.validate();
  EXPECT_DOUBLE_EQ(f_rel(-2, a), -1.2);
  EXPECT_DOUBLE_EQ(f_rel(-1, a), -1.0);
  EXPECT_DOUBLE_EQ(f_rel(0, a), 0.0);
  EXPECT_DOUBLE_EQ(f_rel(3, a), 0.6);
  EXPECT_DOUBLE_EQ(f_rel(1.5, a), 0.3);    // interpolated
  EXPECT_DOUBLE_EQ(f_rel(-3.5, a), -1.2);  // held beyond the ends
  EXPECT_DOUBLE_EQ(f_rel(50, a), 0.6);
  a.max_mps = 1.1;  // the saturation applies to custom curves too
  EXPECT_DOUBLE_EQ(f_rel(-2, a), -1.1);
}

TEST(RepulsionAttraction, PairForceIsEqualAndOppositeAndZeroAtDint) {
  ActivationConfig a;
  const double d_int = 4;
  const Vector3d p1(1, 2, 3);
  for (double dist : {1.0, 2.5, 3.9, 4.0, 4.1, 7.0, 20.0}) {
    const Vector3d dir = Vector3d(1, -2, 0.5).normalized();
    const Vector3d p2 = p1 + dist * dir;
    const Vector3d f12 = repulsion_attraction(p1, std::span(&p2, 1), d_int, a);
    const Vector3d f21 = repulsion_attraction(p2, std::span(&p1, 1), d_int, a);
    EXPECT_NEAR((f12 + f21).norm(), 0.0, 1e-12) << dist;
    EXPECT_NEAR(f12.cross(dir).norm(), 0.0, 1e-12) << dist;  // along the line joining them
    const double toward = f12.dot(dir);
    if (dist < d_int) {
      EXPECT_LT(toward, 0) << "too close pushes apart at " << dist;
    } else if (dist > d_int) {
      EXPECT_GT(toward, 0) << "too far pulls together at " << dist;
    } else {
      EXPECT_EQ(f12.norm(), 0.0);
    }
  }
}

TEST(RepulsionAttraction, SumsPeersSkipsCoincidentAndCutoff) {
  ActivationConfig a;
  const Vector3d self(0, 0, 2);
  std::vector<Vector3d> peers = {{2, 0, 2}, {-2, 0, 2}};  // symmetric: cancel
  EXPECT_NEAR(repulsion_attraction(self, peers, 4, a).norm(), 0.0, 1e-12);
  peers = {self, {6, 0, 2}};  // coincident peer: no NaN, no direction
  const Vector3d c = repulsion_attraction(self, peers, 4, a);
  EXPECT_TRUE(c.allFinite());
  EXPECT_NEAR(c.x(), 0.5, 1e-12);
  a.cutoff_m = 5;  // the peer 6 m away is out of range
  EXPECT_EQ(repulsion_attraction(self, peers, 4, a), Vector3d::Zero());
}

TEST(RepulsionAttraction, NeighboursTakesOnlyTheKNearestPeers) {
  ActivationConfig a;
  const Vector3d self(0, 0, 2);
  // Two close peers push, two far ones pull harder than they push.
  const std::vector<Vector3d> peers = {{9, 0, 2}, {0, 3, 2}, {-3, 0, 2}, {0, -10, 2}};
  const Vector3d all = repulsion_attraction(self, peers, 4, a);
  a.neighbours = 2;
  const Vector3d near2 = repulsion_attraction(self, peers, 4, a);
  // Only (0, 3) and (-3, 0) act: each pushes 1 m/s away from it.
  EXPECT_NEAR(near2.x(), 1.0, 1e-12);
  EXPECT_NEAR(near2.y(), -1.0, 1e-12);
  EXPECT_GT((all - near2).norm(), 1.0) << "the far peers did act in the full sum";
  a.neighbours = 4;  // as many as there are: the thesis's sum
  EXPECT_EQ(repulsion_attraction(self, peers, 4, a), all);
  // The cutoff applies first: of the peers within 5 m, k = 3 leaves both.
  a.neighbours = 3;
  a.cutoff_m = 5;
  EXPECT_EQ(repulsion_attraction(self, peers, 4, a), near2);
  // Equal distances: the earlier peer in the span wins, whatever the order of the rest.
  a = ActivationConfig{};
  a.neighbours = 1;
  const std::vector<Vector3d> tie = {{20, 0, 2}, {0, 2, 2}, {2, 0, 2}};
  EXPECT_NEAR(repulsion_attraction(self, tie, 4, a).y(), -1.5, 1e-12);
}

// The k nearest, found in one pass, are the peers a full sort by (distance,
// index) puts first, summed in that order: checked bit for bit on clouds of
// a swarm's size with duplicates, a coincident peer, NaN and a cutoff.
TEST(RepulsionAttraction, NeighboursMatchTheFullSortBitForBit) {
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(-30.0, 30.0);
  for (int round = 0; round < 40; ++round) {
    ActivationConfig a;
    a.neighbours = 1 + round % 12;
    a.cutoff_m = round % 3 == 0 ? 12.0 : 0.0;
    const Vector3d self(u(rng), u(rng), 5.0);
    std::vector<Vector3d> peers;
    for (int j = 0; j < 511; ++j) peers.emplace_back(u(rng), u(rng), 5.0 + u(rng) / 10);
    peers[7] = self;                             // coincident: acts not at all
    peers[30] = self + Vector3d(1.5, 0.5, 0.0);  // among the nearest, and tied:
    peers[40] = peers[30];                       // the earlier one first
    peers[20] = self + Vector3d(-1.5, -0.5, 0.0);
    peers[100] = Vector3d(std::nan(""), 0, 0);
    std::vector<std::pair<double, std::size_t>> ref;
    for (std::size_t j = 0; j < peers.size(); ++j) {
      const double d = (peers[j] - self).norm();
      if (d > 1e-9 && !(a.cutoff_m > 0 && d > a.cutoff_m)) ref.emplace_back(d, j);
    }
    std::sort(ref.begin(), ref.end());
    Vector3d want = Vector3d::Zero();
    for (std::size_t i = 0; i < std::min<std::size_t>(ref.size(), a.neighbours); ++i)
      want += f_rel(ref[i].first - 4.0, a) * ((peers[ref[i].second] - self) / ref[i].first);
    EXPECT_EQ(repulsion_attraction(self, peers, 4.0, a), want) << "round " << round;
  }
}

namespace {

struct Packing {
  double closest = 1e9;    ///< m, closest pair
  double widest_gap = 0;   ///< m, the farthest any drone is from its nearest peer
  bool connected = false;  ///< every drone within 1.5 D_int of the rest, transitively
};

/// One kinematic step of every drone on the law alone: x += v dt.
void step_swarm(std::vector<Vector3d>& p, const AgentConfig& c, double dt) {
  std::vector<Vector3d> peers, v(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) {
    peers.clear();
    for (std::size_t j = 0; j < p.size(); ++j)
      if (j != i) peers.push_back(p[j]);
    LawInput in;
    in.p_world = p[i];
    in.peers_world = peers;
    v[i] = control_velocity(in, c);
  }
  for (std::size_t i = 0; i < p.size(); ++i) p[i] += dt * v[i];
}

/// Flies n drones from a square start grid (spacing m apart, one altitude) on
/// the swarm term alone, kinematically (20 Hz), for t_s seconds.
Packing settle(int n, double spacing, const AgentConfig& c, double t_s) {
  std::vector<Vector3d> p;
  const int side = static_cast<int>(std::ceil(std::sqrt(n)));
  for (int i = 0; i < n; ++i) p.emplace_back(spacing * (i % side), spacing * (i / side), 2.0);
  const double dt = 0.05;
  for (int step = 0; step < static_cast<int>(t_s / dt); ++step) step_swarm(p, c, dt);
  Packing k;
  std::vector<int> comp(p.size());
  for (std::size_t i = 0; i < p.size(); ++i) comp[i] = static_cast<int>(i);
  std::function<int(int)> root = [&](int i) { return comp[i] == i ? i : comp[i] = root(comp[i]); };
  for (std::size_t i = 0; i < p.size(); ++i) {
    double nearest = 1e9;
    for (std::size_t j = 0; j < p.size(); ++j) {
      if (i == j) continue;
      const double d = (p[i] - p[j]).norm();
      nearest = std::min(nearest, d);
      if (d < 1.5 * c.inter_distance_m) comp[root(static_cast<int>(i))] = root(static_cast<int>(j));
    }
    k.closest = std::min(k.closest, nearest);
    k.widest_gap = std::max(k.widest_gap, nearest);
  }
  k.connected = true;
  for (std::size_t i = 0; i < p.size(); ++i)
    k.connected = k.connected && root(static_cast<int>(i)) == root(0);
  return k;
}

}  // namespace

TEST(DenseSwarm, EveryPeerPacksThirtyTwoDronesTightKNearestKeepsThemApart) {
  // 32 drones from the thesis course's 2 m start grid, 60 s on the swarm law.
  AgentConfig thesis;
  const Packing sum = settle(32, 2.0, thesis, 60);
  // The thesis's sum: 31 peers pull, one pushes at most max_mps. Drones
  // about 0.5 m across touch well before this.
  EXPECT_LT(sum.closest, 1.0);
  AgentConfig topo;
  topo.activation.neighbours = 6;
  const Packing k6 = settle(32, 2.0, topo, 60);
  std::printf(
      "32 drones after 60 s: every peer: closest pair %.2f m; 6 nearest: closest %.2f m, "
      "widest nearest-neighbour gap %.2f m\n",
      sum.closest, k6.closest, k6.widest_gap);
  EXPECT_GT(k6.closest, 0.6 * topo.inter_distance_m) << "k nearest keep clear of each other";
  EXPECT_LT(k6.widest_gap, 1.25 * topo.inter_distance_m) << "and near their neighbours";
  EXPECT_TRUE(k6.connected) << "one swarm, not islands";
}

// ---- sensor functions ------------------------------------------------------------------------

TEST(SensorFunction, Fs1MatchesItsDefinition) {
  SensorFunctionConfig s;  // fs1, max 2 m/s
  EXPECT_DOUBLE_EQ(sensor_activation(0.0, true, s), 2.0);
  EXPECT_DOUBLE_EQ(sensor_activation(1.0, true, s), 2.0);
  EXPECT_DOUBLE_EQ(sensor_activation(2.5, true, s), 1.0);
  EXPECT_DOUBLE_EQ(sensor_activation(4.0, true, s), 0.0);
  EXPECT_NEAR(sensor_activation(3.999, true, s), 2.0 * 0.001 / 3, 1e-12);
  EXPECT_EQ(sensor_range_m(s), 4.0);
}

TEST(SensorFunction, Fs2HasTheLargerDomain) {
  SensorFunctionConfig s;
  s.type = SensorFunctionType::kFs2;
  EXPECT_DOUBLE_EQ(sensor_activation(1.0, true, s), 2.0);
  EXPECT_DOUBLE_EQ(sensor_activation(3.5, true, s), 1.0);
  EXPECT_DOUBLE_EQ(sensor_activation(5.0, true, s), 0.4);
  EXPECT_DOUBLE_EQ(sensor_activation(6.0, true, s), 0.0);
  SensorFunctionConfig fs1;
  for (double r : {1.5, 2.0, 3.0, 4.5})
    EXPECT_GT(sensor_activation(r, true, s), sensor_activation(r, true, fs1));
}

TEST(SensorFunction, LogRisesSteeplyNearTheObstacleAndIsClamped) {
  SensorFunctionConfig s;
  s.type = SensorFunctionType::kLog;
  EXPECT_NEAR(sensor_activation(6.0 / std::exp(1.0), true, s), 1.0, 1e-12);
  EXPECT_NEAR(sensor_activation(4.0, true, s), std::log(1.5), 1e-12);
  EXPECT_DOUBLE_EQ(sensor_activation(6.0, true, s), 0.0);
  EXPECT_DOUBLE_EQ(sensor_activation(0.5, true, s), 2.0);  // clamp from 6/e^2 = 0.81 m
  EXPECT_DOUBLE_EQ(sensor_activation(0.0, true, s), 2.0);
  // Weaker than fs2 far away, stronger close in.
  SensorFunctionConfig fs2;
  fs2.type = SensorFunctionType::kFs2;
  EXPECT_LT(sensor_activation(3.0, true, s), sensor_activation(3.0, true, fs2));
  EXPECT_GT(sensor_activation(5.9, true, s), 0.0);
}

TEST(SensorFunction, CustomMatchesBreakpoints) {
  SensorFunctionConfig s;
  s.type = SensorFunctionType::kCustom;
  s.points = {{0.5, 3.0}, {2.0, 1.0}, {5.0, 0.0}};
  s.validate();
  EXPECT_DOUBLE_EQ(sensor_activation(0.2, true, s), 3.0);
  EXPECT_DOUBLE_EQ(sensor_activation(0.5, true, s), 3.0);
  EXPECT_DOUBLE_EQ(sensor_activation(2.0, true, s), 1.0);
  EXPECT_DOUBLE_EQ(sensor_activation(3.5, true, s), 0.5);
  EXPECT_DOUBLE_EQ(sensor_activation(5.0, true, s), 0.0);
  EXPECT_DOUBLE_EQ(sensor_activation(9.0, true, s), 0.0);
  EXPECT_EQ(sensor_range_m(s), 5.0);
}

TEST(SensorFunction, ZeroWithoutHitBeyondRangeOrOnNaN) {
  for (auto t : {SensorFunctionType::kFs1, SensorFunctionType::kFs2, SensorFunctionType::kLog}) {
    SensorFunctionConfig s;
    s.type = t;
    EXPECT_EQ(sensor_activation(0.5, false, s), 0.0);
    EXPECT_EQ(sensor_activation(sensor_range_m(s) + 0.01, true, s), 0.0);
    EXPECT_EQ(sensor_activation(std::nan(""), true, s), 0.0);
    EXPECT_EQ(sensor_activation(-0.2, true, s), s.max_mps);  // inside reads as touching
  }
}

// ---- obstacle avoidance ----------------------------------------------------------------------

TEST(ObstacleAvoidance, CentredBetweenEqualPillarsGetsNoSidewaysPush) {
  SensorFunctionConfig s;
  s.type = SensorFunctionType::kFs2;
  // Pillars of radius 1 at x = +-3.5: a 5 m gap, the drone heading north (+y) in it.
  const std::vector<std::pair<Eigen::Vector2d, double>> pillars = {{{-3.5, 0}, 1.0},
                                                                   {{3.5, 0}, 1.0}};
  const auto q = yaw(kPi / 2);
  const Vector3d centre(0, 0, 2);
  Scan sc = scan(centre, q, pillars);
  ASSERT_GE(std::count(sc.hit.begin(), sc.hit.end(), 1), 2);
  const Vector3d c = obstacle_avoidance(sc.range, sc.hit, sc.yaw, {}, q, s);
  EXPECT_NEAR(c.x(), 0.0, 1e-6);
  EXPECT_NEAR(c.z(), 0.0, 1e-12);

  for (double off : {0.5, 1.0, 1.5}) {
    const Vector3d p(off, -0.3, 2);  // closer to the east pillar
    Scan so = scan(p, q, pillars);
    const Vector3d push = obstacle_avoidance(so.range, so.hit, so.yaw, {}, q, s);
    EXPECT_LT(push.x(), -0.1) << "pushed back toward the middle at offset " << off;
  }
}

TEST(ObstacleAvoidance, PushesAwayAlongTheWorldRayAndIgnoresFarOrMissedRays) {
  SensorFunctionConfig s;  // fs1
  const std::vector<float> yaw_body = {0.0f, static_cast<float>(kPi / 2)};
  const auto q = yaw(kPi / 2);  // body x = world north
  // Ray 0 (ahead = north) hits at 2.5 m: push south at 1 m/s. Ray 1 missed.
  std::vector<float> range = {2.5f, 1.0f};
  std::vector<std::uint8_t> hit = {1, 0};
  Vector3d c = obstacle_avoidance(range, hit, yaw_body, {}, q, s);
  EXPECT_NEAR((c - Vector3d(0, -1, 0)).norm(), 0.0, 1e-6);
  range = {4.5f, 1.0f};  // beyond fs1's 4 m
  EXPECT_EQ(obstacle_avoidance(range, hit, yaw_body, {}, q, s), Vector3d::Zero());
  // Pitched attitude: the reaction stays horizontal.
  const Eigen::Quaterniond pitched =
      q * Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Vector3d::UnitY()));
  range = {2.5f, 1.0f};
  c = obstacle_avoidance(range, hit, yaw_body, {}, pitched, s);
  EXPECT_EQ(c.z(), 0.0);
  EXPECT_NEAR(c.norm(), 1.0, 1e-6);
  hit.push_back(1);
  EXPECT_THROW(obstacle_avoidance(range, hit, yaw_body, {}, q, s), std::invalid_argument);
}

TEST(ObstacleAvoidance, SeveralRowsAreAveragedSoAWallSeenByAllPushesAsTheRing) {
  SensorFunctionConfig s;  // fs1: 1 m/s at 2.5 m
  const auto q = yaw(0);
  // Three rows (-20, 0, +20 deg) of one column, looking east at a wall the
  // drone's level ray meets at 2.5 m; each row reads the wall along its slant.
  const float e = static_cast<float>(20 * kPi / 180);
  const std::vector<float> yaw_body(3, 0.0f), elevation = {-e, 0.0f, e};
  const std::vector<std::uint8_t> hit = {1, 1, 1};
  const std::vector<float> range(3, 2.5f);  // as if every row read 2.5 m
  const Vector3d c = obstacle_avoidance(range, hit, yaw_body, elevation, q, s);
  // The mean over rows: f = 1 m/s for each, directions (cos e, 0, -+sin e) and
  // (1, 0, 0); the vertical parts cancel.
  EXPECT_NEAR(c.x(), -(1 + 2 * std::cos(20 * kPi / 180)) / 3, 1e-6);
  EXPECT_NEAR(c.z(), 0.0, 1e-9);
  // The ring's one ray at 2.5 m pushes 1 m/s: the rows push no harder than it.
  const std::vector<float> one_yaw = {0.0f}, one_range = {2.5f};
  const std::vector<std::uint8_t> one_hit = {1};
  EXPECT_NEAR(obstacle_avoidance(one_range, one_hit, one_yaw, {}, q, s).x(), -1.0, 1e-6);
  EXPECT_GT(-c.x(), 0.9);

  // Only the top row sees something (an overhang): pushed back and down, by a
  // third of its activation.
  const std::vector<std::uint8_t> top = {0, 0, 1};
  const Vector3d d = obstacle_avoidance(range, top, yaw_body, elevation, q, s);
  EXPECT_NEAR(d.x(), -std::cos(20 * kPi / 180) / 3, 1e-6);
  EXPECT_NEAR(d.z(), -std::sin(20 * kPi / 180) / 3, 1e-6);
}

TEST(ObstacleAvoidance, ARowPatternWeighsEachRayByOneOverItsRows) {
  // 5 rows x 8 columns, row by row as the server casts them.
  std::vector<float> elevation;
  for (int r = 0; r < 5; ++r)
    for (int c = 0; c < 8; ++c) elevation.push_back(static_cast<float>(0.1 * (r - 2)));
  EXPECT_DOUBLE_EQ(ray_weight(elevation), 1.0 / 5);
  EXPECT_EQ(ray_weight(std::vector<float>(8, 0.0f)), 1.0);  // the ring
  EXPECT_EQ(ray_weight({}), 1.0);
  // The ring's direction is unchanged by an elevation argument of 0, tilted or not.
  const Eigen::Quaterniond tilted =
      yaw(0.7) * Eigen::Quaterniond(Eigen::AngleAxisd(0.2, Vector3d::UnitX()));
  EXPECT_EQ(ray_direction_world(1.1, tilted, 0.0), ray_direction_world(1.1, tilted));
  const Vector3d up = ray_direction_world(0.0, yaw(kPi / 2), 0.5);
  EXPECT_NEAR((up - Vector3d(0, std::cos(0.5), std::sin(0.5))).norm(), 0.0, 1e-12);
}

TEST(ObstacleAvoidance, TheVerticalPushReachesTheCommandWithoutAltitudeHold) {
  AgentConfig c;
  LawInput in;
  in.p_world = {0, 0, 2};
  in.swarm_enabled = false;
  in.altitude_hold = false;
  const float e = static_cast<float>(20 * kPi / 180);
  const std::vector<float> yaw_body(3, 0.0f), elevation = {-e, 0.0f, e}, range(3, 1.5f);
  const std::vector<std::uint8_t> hit = {0, 0, 1};  // something ahead and above
  in.ray_range_m = range;
  in.ray_hit = hit;
  in.ray_yaw_body_rad = yaw_body;
  in.ray_elevation_body_rad = elevation;
  const Vector3d v = control_velocity(in, c);
  EXPECT_LT(v.x(), -0.05);
  EXPECT_LT(v.z(), -0.05);  // pushed down, away from the overhang
  in.altitude_hold = true;  // the altitude loop owns the vertical
  EXPECT_NEAR(control_velocity(in, c).z(), 0.0, 1e-9);
}

// ---- the combined law ------------------------------------------------------------------------

TEST(ControlVelocity, SumsTermsAndLimitsSpeedKeepingDirection) {
  AgentConfig c;
  LawInput in;
  in.altitude_hold = false;
  in.p_world = {0, 0, 2};
  std::vector<Vector3d> peers = {{20, 0, 2}, {0, 20, 2}};  // both pull at the full 1.5 m/s
  in.peers_world = peers;
  in.mission_velocity = {1.0, 1.0, 0};
  const Vector3d v = control_velocity(in, c);
  EXPECT_NEAR(v.norm(), c.max_speed_mps, 1e-9);
  EXPECT_NEAR(v.normalized().dot(Vector3d(1, 1, 0).normalized()), 1.0, 1e-12);

  in.peers_world = {};
  in.mission_velocity = {0.3, 0, 0.2};  // below every limit: passes through unchanged
  EXPECT_NEAR((control_velocity(in, c) - in.mission_velocity).norm(), 0.0, 1e-12);

  in.mission_velocity = {2.9, 0, 2.0};  // horizontal OK, total too fast
  const Vector3d w = control_velocity(in, c);
  EXPECT_NEAR(w.norm(), 3.0, 1e-9);
  EXPECT_NEAR(w.normalized().dot(in.mission_velocity.normalized()), 1.0, 1e-12);
}

TEST(ControlVelocity, AltitudeHoldReplacesVerticalTermsAndIsRateLimited) {
  AgentConfig c;
  LawInput in;
  in.p_world = {0, 0, 2};
  std::vector<Vector3d> peers = {{0, 0, 10}};  // straight above: R&A pulls up
  in.peers_world = peers;
  in.altitude_target_m = 2;
  EXPECT_NEAR(control_velocity(in, c).z(), 0.0, 1e-12);
  in.peers_world = {};
  in.altitude_target_m = 10;  // far below: climb no faster than takeoff speed
  EXPECT_DOUBLE_EQ(control_velocity(in, c).z(), c.takeoff_speed_mps);
  in.altitude_target_m = -5;  // far above: sink no faster than landing speed
  EXPECT_DOUBLE_EQ(control_velocity(in, c).z(), -c.landing_speed_mps);
  in.altitude_target_m = 2.2;  // close: proportional
  EXPECT_NEAR(control_velocity(in, c).z(), c.altitude_gain * 0.2, 1e-12);
  in.mission_velocity = {0, 0, 0.3};  // a climbing move adds its feed-forward
  EXPECT_NEAR(control_velocity(in, c).z(), 0.3 + c.altitude_gain * 0.2, 1e-12);
}

TEST(ControlVelocity, SafetyDistanceMakesObstacleRepulsionDominate) {
  AgentConfig c;
  const std::vector<float> yaw_body = eight_rays();
  std::vector<float> range(8, 10.0f);
  std::vector<std::uint8_t> hit(8, 0);
  range[0] = 0.5f;  // obstacle 0.5 m straight ahead (east, identity attitude)
  hit[0] = 1;
  std::vector<Vector3d> peers = {{15, 0, 2}};  // a peer beyond the obstacle pulls east too
  LawInput in;
  in.p_world = {0, 0, 2};
  in.altitude_target_m = 2;
  in.peers_world = peers;
  in.ray_range_m = range;
  in.ray_hit = hit;
  in.ray_yaw_body_rad = yaw_body;
  in.mission_velocity = {2.5, 0.5, 0};  // the task flies into it

  // Without the safety distance the mission and the pull overpower f_s: the
  // drone keeps closing in (the thesis's collisions at higher speed).
  LawTerms plain = evaluate_law(in, c);
  EXPECT_FALSE(plain.safety_active);
  EXPECT_GT(plain.velocity.x(), 0.0);

  c.sensor_function.safety_distance_m = 1.0;
  LawTerms safe = evaluate_law(in, c);
  EXPECT_TRUE(safe.safety_active);
  EXPECT_LT(safe.velocity.x(), -0.5) << "moves away from the obstacle";
  EXPECT_GT(safe.velocity.y(), 0.0) << "keeps sliding sideways";
  EXPECT_LE(safe.velocity.norm(), c.max_speed_mps + 1e-9);

  range[0] = 1.5f;  // outside the safety distance: the graded reaction only
  EXPECT_FALSE(evaluate_law(in, c).safety_active);
}

// ---- swarm condition and the gathering it measures -------------------------------------------

TEST(SwarmCondition, AllPairsWithinEpsilon) {
  std::vector<Vector3d> p = {{0, 0, 2}, {4, 0, 2}, {2, 3, 2}};
  EXPECT_TRUE(swarm_condition(p, 4.1));
  EXPECT_FALSE(swarm_condition(p, 4.0));  // strict: distance < epsilon
  EXPECT_TRUE(swarm_condition(std::span(p).first(1), 0.1));
  EXPECT_EQ(default_epsilon(4.0), 9.0);
}

TEST(SwarmCondition, SixScatteredDronesGatherWithinDefaultEpsilonWithoutCrowding) {
  AgentConfig c;
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> u(-12, 12);
  std::vector<Vector3d> p(6);
  for (auto& q : p) q = {u(rng), u(rng), 2.0};
  const double eps = default_epsilon(c.inter_distance_m);
  const double dt = 0.05;
  double t_swarmed = -1;
  for (int step = 0; step < 4000 && t_swarmed < 0; ++step) {
    step_swarm(p, c, dt);
    if (swarm_condition(p, eps)) t_swarmed = step * dt;
  }
  ASSERT_GT(t_swarmed, 0) << "never gathered";
  EXPECT_LT(t_swarmed, 60.0);
  // Let it settle, then check the equilibrium the default epsilon was chosen from.
  for (int step = 0; step < 4000; ++step) {
    step_swarm(p, c, dt);
  }
  double dmin = 1e9, dmax = 0;
  for (std::size_t i = 0; i < p.size(); ++i)
    for (std::size_t j = i + 1; j < p.size(); ++j) {
      dmin = std::min(dmin, (p[i] - p[j]).norm());
      dmax = std::max(dmax, (p[i] - p[j]).norm());
    }
  EXPECT_GT(dmin, 0.75 * c.inter_distance_m);
  EXPECT_NEAR(dmax, 1.53 * c.inter_distance_m, 0.1);
  EXPECT_LT(dmax, eps - 1.0);
}

// ---- sliding round an obstacle ------------------------------------------------------------

TEST(ControlVelocity, SlidesRoundAPillarDeadAheadInsteadOfStalling) {
  AgentConfig cfg;
  cfg.altitude_hold = false;
  // One pillar 2.5 m dead ahead of a drone flying north: the thesis's Eq. 3.3
  // pushes straight back, a local minimum where forward push and repulsion cancel.
  const std::vector<std::pair<Eigen::Vector2d, double>> pillars = {{{0, 3.5}, 1.0}};
  const auto q = yaw(kPi / 2);
  const Vector3d p(0, 0, 2);
  Scan sc = scan(p, q, pillars);
  LawInput in;
  in.p_world = p;
  in.q_world_body = q;
  in.ray_range_m = sc.range;
  in.ray_hit = sc.hit;
  in.ray_yaw_body_rad = sc.yaw;
  in.mission_velocity = Vector3d(0, 0.8, 0);
  in.swarm_enabled = false;
  in.altitude_hold = false;

  cfg.sensor_function.slide_gain = 0.0;  // the thesis's law
  LawTerms pure = evaluate_law(in, cfg);
  EXPECT_NEAR(pure.velocity.x(), 0.0, 1e-6) << "no sideways way out: the drone stalls";

  cfg.sensor_function.slide_gain = 1.0;
  LawTerms slid = evaluate_law(in, cfg);
  EXPECT_GT(std::abs(slid.velocity.x()), 0.3) << "the blocked push goes round the pillar";
  EXPECT_LT(slid.velocity.y(), in.mission_velocity.y()) << "and does not drive into it harder";

  // Off-centre to the east, it goes round on the east side (the way it leans).
  in.mission_velocity = Vector3d(0.3, 0.8, 0);
  EXPECT_GT(evaluate_law(in, cfg).slide.x(), 0.0);
  in.mission_velocity = Vector3d(-0.3, 0.8, 0);
  EXPECT_LT(evaluate_law(in, cfg).slide.x(), 0.0);
}

TEST(ControlVelocity, LandingIsNotHeldUpByDronesAlreadyOnTheGround) {
  AgentConfig cfg;
  // Three peers landed 2.5 m below: closer than D_int, so Eq. 3.2 repels upward.
  const std::vector<Vector3d> peers = {{0.5, 0, 0.05}, {-0.5, 0.4, 0.05}, {0, -0.6, 0.05}};
  LawInput in;
  in.p_world = Vector3d(0, 0, 2.5);
  in.peers_world = peers;
  in.obstacle_avoidance_enabled = false;
  in.altitude_hold = false;
  in.mission_velocity = Vector3d(0, 0, -cfg.landing_speed_mps);
  EXPECT_GT(evaluate_law(in, cfg).velocity.z(), -0.1) << "the thesis law alone stalls the descent";
  in.swarm_horizontal_only = true;
  EXPECT_NEAR(evaluate_law(in, cfg).velocity.z(), -cfg.landing_speed_mps, 1e-9);
}
