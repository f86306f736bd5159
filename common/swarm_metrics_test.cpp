#include "common/swarm_metrics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

namespace ddswarm {
namespace {

using Vecs = std::vector<Eigen::Vector3d>;

Vecs line(int n, double spacing_m) {
  Vecs p;
  for (int i = 0; i < n; ++i) p.emplace_back(i * spacing_m, 0, 2);
  return p;
}

Vecs same(int n, const Eigen::Vector3d& v) { return Vecs(n, v); }

/// φ_corr by its definition, pair by pair: what velocity_order's O(N) sum must equal.
double order_by_pairs(const Vecs& v, double still) {
  double sum = 0;
  for (std::size_t i = 0; i < v.size(); ++i)
    for (std::size_t j = 0; j < v.size(); ++j) {
      if (i == j) continue;
      const double a = v[i].norm(), b = v[j].norm();
      if (a >= still && b >= still) sum += v[i].dot(v[j]) / (a * b);
    }
  return sum / (static_cast<double>(v.size()) * static_cast<double>(v.size() - 1));
}

TEST(SwarmOrder, AlignedIsOneOppositeHalvesAreMinusOneOverNMinusOne) {
  EXPECT_DOUBLE_EQ(velocity_order(same(6, {0.3, 0.8, 0.1}), 0.05), 1.0);
  // Speeds differ, directions agree: still 1 (order is about headings).
  EXPECT_NEAR(velocity_order(Vecs{{1, 0, 0}, {5, 0, 0}, {0.2, 0, 0}}, 0.05), 1.0, 1e-12);
  EXPECT_DOUBLE_EQ(velocity_order(Vecs{{1, 0, 0}, {-1, 0, 0}}, 0.05), -1.0);
  for (int n : {4, 6, 10}) {
    Vecs v;
    for (int i = 0; i < n; ++i) v.emplace_back(i % 2 ? -0.8 : 0.8, 0, 0);
    EXPECT_NEAR(velocity_order(v, 0.05), -1.0 / (n - 1), 1e-12) << n << " drones";
  }
  // Perpendicular pairs count 0: two east, one north -> (2·1 + 4·0) / 6.
  EXPECT_NEAR(velocity_order(Vecs{{1, 0, 0}, {1, 0, 0}, {0, 1, 0}}, 0.05), 1.0 / 3.0, 1e-12);
}

TEST(SwarmOrder, AStillDroneHasNoHeadingAndItsPairsCountZero) {
  // Three aligned, one hovering: 6 of the 12 ordered pairs are aligned.
  EXPECT_NEAR(velocity_order(Vecs{{1, 0, 0}, {1, 0, 0}, {1, 0, 0}, {0.01, 0.02, 0}}, 0.05), 0.5,
              1e-12);
  EXPECT_EQ(velocity_order(same(5, Eigen::Vector3d::Zero()), 0.05), 0.0);
  EXPECT_TRUE(std::isnan(velocity_order(Vecs{{1, 0, 0}}, 0.05)));
  EXPECT_TRUE(std::isnan(velocity_order(Vecs{}, 0.05)));
}

TEST(SwarmOrder, TheLinearSumEqualsThePairByPairDefinition) {
  std::mt19937 rng(7);
  std::normal_distribution<double> g(0.0, 1.0);
  for (int n : {2, 3, 17, 64}) {
    Vecs v;
    for (int i = 0; i < n; ++i) v.emplace_back(g(rng), g(rng), 0.2 * g(rng));
    v[0] *= 0.01;  // one below still_speed_mps
    EXPECT_NEAR(velocity_order(v, 0.05), order_by_pairs(v, 0.05), 1e-12) << n << " drones";
  }
}

TEST(SwarmConnectivity, PathGraphLambda2IsTwoOneMinusCosPiOverN) {
  for (int n : {2, 3, 5, 10, 30}) {
    // 1 m apart with a 1.5 m range: each drone hears only its neighbours, P_n.
    const double expected = 2 * (1 - std::cos(std::numbers::pi / n));
    EXPECT_NEAR(algebraic_connectivity(line(n, 1.0), 1.5), expected, 1e-9) << "P_" << n;
    SwarmMetricsOptions o;
    o.range_m = 1.5;
    const auto m = swarm_tick_metrics(line(n, 1.0), same(n, {1, 0, 0}), o);
    EXPECT_EQ(m.components, 1);
    EXPECT_NEAR(m.lambda2, expected, 1e-9) << "P_" << n;
  }
}

TEST(SwarmConnectivity, CompleteGraphLambda2IsN) {
  for (int n : {2, 4, 6, 12}) {
    // Everyone within range of everyone: K_n.
    EXPECT_NEAR(algebraic_connectivity(line(n, 0.5), 100.0), n, 1e-9) << "K_" << n;
  }
}

TEST(SwarmConnectivity, TwoFarClustersAreTwoComponentsWithLambda2Zero) {
  Vecs p = {{0, 0, 2}, {2, 0, 2}, {0, 2, 2}, {50, 0, 2}, {52, 0, 2}};
  SwarmMetricsOptions o;
  o.range_m = 10;
  const auto m = swarm_tick_metrics(p, same(5, {0, 1, 0}), o);
  EXPECT_EQ(m.components, 2);
  EXPECT_EQ(m.lambda2, 0.0);
  EXPECT_EQ(algebraic_connectivity(p, 10), 0.0);  // the decomposition agrees
  // The link is inclusive: exactly range_m apart is still heard.
  o.range_m = 48;
  const auto joined = swarm_tick_metrics(p, same(5, {0, 1, 0}), o);
  EXPECT_EQ(joined.components, 1);
  EXPECT_GT(joined.lambda2, 0.0);
  // Everyone out of range: every drone its own component.
  o.range_m = 1;
  EXPECT_EQ(swarm_tick_metrics(p, same(5, {0, 1, 0}), o).components, 5);
}

TEST(SwarmConnectivity, Lambda2IsLeftOutAboveTheSizeLimitUnlessDisconnected) {
  SwarmMetricsOptions o;
  o.range_m = 1.5;
  o.lambda2_max_drones = 4;
  EXPECT_GT(swarm_tick_metrics(line(4, 1.0), same(4, {1, 0, 0}), o).lambda2, 0.0);
  EXPECT_TRUE(std::isnan(swarm_tick_metrics(line(5, 1.0), same(5, {1, 0, 0}), o).lambda2));
  EXPECT_EQ(swarm_tick_metrics(line(5, 2.0), same(5, {1, 0, 0}), o).lambda2, 0.0);
  o.lambda2_max_drones = 0;
  EXPECT_TRUE(std::isnan(swarm_tick_metrics(line(2, 1.0), same(2, {1, 0, 0}), o).lambda2));
}

TEST(SwarmTick, DistancesSpeedAndNearPairs) {
  Vecs p = {{0, 0, 2}, {0.6, 0, 2}, {0, 0.9, 2}, {5, 5, 2}};
  Vecs v = {{3, 4, 0}, {0, 1, 0}, {0, 0, 0}, {0, 2, 0}};
  const auto m = swarm_tick_metrics(p, v, {});
  EXPECT_EQ(m.drones, 4);
  EXPECT_DOUBLE_EQ(m.mean_speed_mps, (5.0 + 1 + 0 + 2) / 4);
  EXPECT_DOUBLE_EQ(m.min_distance_m, 0.6);
  EXPECT_DOUBLE_EQ(m.max_distance_m, std::hypot(5.0, 5.0));
  EXPECT_EQ(m.near_pairs, 2);  // 0-1 0.6 m, 0-2 0.9 m; 1-2 1.08 m is not
  ASSERT_EQ(m.close.size(), 3u);
  EXPECT_TRUE(m.close[0].near);
  EXPECT_EQ(m.close[2].k, 1);
  EXPECT_EQ(m.close[2].l, 2);
  EXPECT_FALSE(m.close[2].near);  // 1.08 m: inside the release band only
  EXPECT_EQ(m.components, 1);     // default range 10 m
}

TEST(SwarmTick, NoDroneOrOneDrone) {
  const auto none = swarm_tick_metrics(Vecs{}, Vecs{}, {});
  EXPECT_EQ(none.components, 0);
  EXPECT_TRUE(std::isnan(none.mean_speed_mps));
  EXPECT_TRUE(std::isnan(none.order));
  const Vecs p = {{1, 2, 3}}, v = {{0, 2, 0}};
  const auto one = swarm_tick_metrics(p, v, {});
  EXPECT_EQ(one.components, 1);
  EXPECT_EQ(one.mean_speed_mps, 2.0);
  EXPECT_TRUE(std::isnan(one.order));
  EXPECT_TRUE(std::isnan(one.lambda2));
  EXPECT_TRUE(std::isinf(one.min_distance_m));
}

/// Drone 0 at x = 0 and drone 1 at x = d; drone 2 far away.
SwarmTickMetrics pair_at(double d, const SwarmMetricsOptions& o) {
  const Vecs p = {{0, 0, 2}, {d, 0, 2}, {0, 40, 2}};
  return swarm_tick_metrics(p, same(3, {0, 1, 0}), o);
}

TEST(SwarmTask, ANearMissIsCountedOncePerApproach) {
  SwarmMetricsOptions o;  // near miss below 1.0 m, released at 1.1 m
  SwarmMetricsAccumulator acc(o);
  const std::vector<int> ids = {0, 1, 2};
  // Closing in, then jitter around the threshold: one approach.
  for (double d : {3.0, 2.0, 1.2, 0.9, 0.95, 1.02, 0.97, 1.05, 0.99}) acc.add(pair_at(d, o), ids);
  EXPECT_EQ(acc.summary().near_misses, 1u);
  // Apart (past 1.1 m), and in again: a second approach.
  for (double d : {1.5, 2.5, 0.8, 0.7}) acc.add(pair_at(d, o), ids);
  EXPECT_EQ(acc.summary().near_misses, 2u);
  // Just past the release distance counts as apart.
  for (double d : {1.11, 0.99}) acc.add(pair_at(d, o), ids);
  EXPECT_EQ(acc.summary().near_misses, 3u);
  EXPECT_EQ(acc.ticks(), 15);
  acc.reset();
  EXPECT_EQ(acc.summary().near_misses, 0u);
  acc.add(pair_at(0.9, o), ids);  // a new task: an approach under way counts anew
  EXPECT_EQ(acc.summary().near_misses, 1u);
}

TEST(SwarmTask, PairsAreFollowedByDroneIdNotByIndex) {
  SwarmMetricsOptions o;
  SwarmMetricsAccumulator acc(o);
  // Drones 3 and 5 stay 0.5 m apart; drone 4 between them in the input drops out.
  acc.add(swarm_tick_metrics(Vecs{{0, 0, 2}, {0, 30, 2}, {0.5, 0, 2}}, same(3, {1, 0, 0}), o),
          std::vector<int>{3, 4, 5});
  acc.add(swarm_tick_metrics(Vecs{{0, 0, 2}, {0.5, 0, 2}}, same(2, {1, 0, 0}), o),
          std::vector<int>{3, 5});
  EXPECT_EQ(acc.summary().near_misses, 1u);
}

TEST(SwarmTask, MeansMinimaAndMaximaOverTheTicks) {
  SwarmMetricsOptions o;
  o.range_m = 1.5;
  SwarmMetricsAccumulator acc(o);
  const std::vector<int> ids = {0, 1, 2};
  // Tick 1: aligned at 1 m/s on a connected line (λ₂ of P_3 = 1).
  acc.add(swarm_tick_metrics(line(3, 1.0), same(3, {1, 0, 0}), o), ids);
  // Tick 2: one reversed, at 2 m/s: order (2 - 4) / 6; the line breaks in two.
  acc.add(swarm_tick_metrics(Vecs{{0, 0, 2}, {1, 0, 2}, {9, 0, 2}},
                             Vecs{{2, 0, 0}, {2, 0, 0}, {-2, 0, 0}}, o),
          ids);
  const SwarmTaskMetrics& s = acc.summary();
  EXPECT_NEAR(s.order_mean, (1.0 - 1.0 / 3.0) / 2, 1e-12);
  EXPECT_NEAR(s.order_min, -1.0 / 3.0, 1e-12);
  EXPECT_DOUBLE_EQ(s.speed_mean_mps, 1.5);
  EXPECT_EQ(s.components_max, 2);
  EXPECT_EQ(s.lambda2_min, 0.0);
  EXPECT_EQ(s.range_m, 1.5);
  EXPECT_EQ(s.near_miss_m, 1.0);
  // Before any tick nothing is measured.
  SwarmMetricsAccumulator fresh(o);
  EXPECT_TRUE(std::isnan(fresh.summary().order_mean));
  EXPECT_TRUE(std::isnan(fresh.summary().lambda2_min));
  EXPECT_EQ(fresh.summary().components_max, 0);
}

}  // namespace
}  // namespace ddswarm
