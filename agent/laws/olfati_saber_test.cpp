#include "olfati_saber.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "flock_sim.hpp"

namespace ddswarm::agent::laws {
namespace {

constexpr double kEps = 0.1;

std::unique_ptr<law::SwarmLaw> make_law(std::map<std::string, std::string> values = {}) {
  law::Params p("agent.law.params", std::move(values));
  return make_olfati_saber(p, law::Rng(0), law::LawContext{});
}

OlfatiSaberConfig config(std::map<std::string, std::string> values = {}) {
  law::Params p("agent.law.params", std::move(values));
  return olfati_saber_config(p);
}

/// The field a ParamError names when building with values; "" when it builds.
std::string refused_field(std::map<std::string, std::string> values) {
  try {
    make_law(std::move(values));
  } catch (const law::ParamError& e) {
    return e.field();
  }
  return "";
}

// ---- The paper's functions ----

TEST(OlfatiSaberFunctions, SigmaNormGradientIsSigmaEpsilon) {
  for (const double eps : {0.1, 0.5, 2.0}) {
    for (const Eigen::Vector3d& z :
         {Eigen::Vector3d(0.3, -0.2, 0.1), Eigen::Vector3d(4, 1, 0), Eigen::Vector3d(-12, 7, 2)}) {
      // ‖z‖_σ as the paper writes it, against the cancellation-free form.
      EXPECT_NEAR(sigma_norm(z.norm(), eps), (std::sqrt(1 + eps * z.squaredNorm()) - 1) / eps,
                  1e-12 * (1 + z.squaredNorm()));
      Eigen::Vector3d numeric;
      const double step = 1e-6;
      for (int k = 0; k < 3; ++k) {
        Eigen::Vector3d dz = Eigen::Vector3d::Zero();
        dz[k] = step;
        numeric[k] =
            (sigma_norm((z + dz).norm(), eps) - sigma_norm((z - dz).norm(), eps)) / (2 * step);
      }
      EXPECT_LT((sigma_gradient(z, eps) - numeric).norm(), 1e-6) << "eps " << eps;
      EXPECT_LT(sigma_gradient(z, eps).norm(), 1 / std::sqrt(eps));
    }
  }
  EXPECT_EQ(sigma_gradient(Eigen::Vector3d::Zero(), kEps), Eigen::Vector3d::Zero());
}

TEST(OlfatiSaberFunctions, BumpIsOneOnZeroHThenSmoothlyZeroAtOne) {
  for (const double h : {0.2, 0.9}) {
    for (double z = 0; z < h; z += h / 10) EXPECT_EQ(bump(z, h), 1.0) << z;
    EXPECT_EQ(bump(1.0, h), 0.0);
    for (const double z : {1.0001, 1.5, 10.0}) EXPECT_EQ(bump(z, h), 0.0) << z;
    // Continuous at h and 1, strictly decreasing between, flat at both joins (C¹).
    EXPECT_NEAR(bump(h, h), 1.0, 1e-15);
    const double step = 1e-7;
    EXPECT_NEAR((bump(h + step, h) - bump(h, h)) / step, 0.0, 1e-4);
    EXPECT_NEAR((bump(1.0, h) - bump(1.0 - step, h)) / step, 0.0, 1e-4);
    double last = 1.0;
    for (double z = h + 0.01; z < 1.0; z += 0.01) {
      const double v = bump(z, h);
      EXPECT_LT(v, last) << z;
      EXPECT_GT(v, 0.0) << z;
      last = v;
    }
  }
}

TEST(OlfatiSaberFunctions, PhiAlphaRepelsBelowDAttractsUpToRAndIsZeroFromR) {
  const double d = 4, r = 1.2 * d;
  const double d_a = sigma_norm(d, kEps), r_a = sigma_norm(r, kEps);
  for (const auto& [a, b] : {std::pair{5.0, 5.0}, std::pair{2.0, 5.0}}) {
    EXPECT_NEAR(phi(0, a, b), 0.0, 1e-12);
    EXPECT_NEAR(phi_alpha(d_a, r_a, d_a, 0.2, a, b), 0.0, 1e-12);
    for (double z = 0.01; z < d_a; z += 0.05) EXPECT_LT(phi_alpha(z, r_a, d_a, 0.2, a, b), 0) << z;
    for (double z = d_a + 0.01; z < r_a - 1e-3; z += 0.05)
      EXPECT_GT(phi_alpha(z, r_a, d_a, 0.2, a, b), 0) << z;
    for (const double z : {r_a, r_a + 0.1, 3 * r_a})
      EXPECT_EQ(phi_alpha(z, r_a, d_a, 0.2, a, b), 0);
    // φ is bounded by −b and a.
    EXPECT_GT(phi(-1e6, a, b), -b - 1e-9);
    EXPECT_LT(phi(1e6, a, b), a + 1e-9);
    EXPECT_NEAR(phi(-1e6, a, b), -b, 1e-6);
  }
}

TEST(OlfatiSaberFunctions, PhiBetaOnlyRepelsAndOnlyCloserThanDBeta) {
  const double d_b = sigma_norm(0.6 * 4, kEps);
  for (double z = 0; z < d_b; z += 0.05) EXPECT_LT(phi_beta(z, d_b, 0.9), 0) << z;
  for (const double z : {d_b, d_b + 0.5, 10 * d_b}) EXPECT_EQ(phi_beta(z, d_b, 0.9), 0);
}

// ---- One drone's acceleration ----

law::Observation lone(const Eigen::Vector3d& mission_velocity = Eigen::Vector3d::Zero()) {
  law::Observation o;
  o.p_world = Eigen::Vector3d(0, 0, 2);
  o.mission_velocity = mission_velocity;
  o.inter_distance_m = 4.0;
  return o;
}

TEST(OlfatiSaberLaw, PairAtDMovingTogetherIsAtRestRepelsCloserAttractsFarther) {
  const OlfatiSaberConfig c = config();
  const Eigen::Vector3d v(0.5, 0, 0);
  auto u_with_peer_at = [&](double x) {
    law::Observation o = lone(v);
    const law::Peer peer{1, o.p_world + Eigen::Vector3d(x, 0, 0), v, 0.0};
    o.peers = std::span<const law::Peer>(&peer, 1);
    return olfati_saber_acceleration(o, v, c);
  };
  EXPECT_LT(u_with_peer_at(4.0).norm(), 1e-12);
  EXPECT_LT(u_with_peer_at(3.6).x(), -0.1);  // pushed away from the peer in +x
  EXPECT_GT(u_with_peer_at(4.4).x(), 0.01);  // pulled toward it
  EXPECT_EQ(u_with_peer_at(4.8).norm(), 0);  // at r: no longer a neighbour
  // d_m overrides D_int: at d_m = 4.4 m the peer at 4.4 m is at rest.
  law::Observation o = lone(v);
  const law::Peer peer{1, o.p_world + Eigen::Vector3d(4.4, 0, 0), v, 0.0};
  o.peers = std::span<const law::Peer>(&peer, 1);
  EXPECT_LT(olfati_saber_acceleration(o, v, config({{"d_m", "4.4"}})).norm(), 1e-12);
}

TEST(OlfatiSaberLaw, PeerWithoutVelocityStillRepelsButIsNotMatched) {
  const OlfatiSaberConfig c = config();
  law::Observation o = lone();
  const law::Peer blind{1, o.p_world + Eigen::Vector3d(0, 4, 0), Eigen::Vector3d::Constant(NAN), 0};
  const law::Peer moving{1, o.p_world + Eigen::Vector3d(0, 4, 0), Eigen::Vector3d(1, 0, 0), 0};
  o.peers = std::span<const law::Peer>(&blind, 1);
  const Eigen::Vector3d u_blind = olfati_saber_acceleration(o, Eigen::Vector3d::Zero(), c);
  EXPECT_TRUE(u_blind.allFinite());
  EXPECT_LT(u_blind.norm(), 1e-12);  // at d, no velocity: nothing to do
  o.peers = std::span<const law::Peer>(&moving, 1);
  EXPECT_GT(olfati_saber_acceleration(o, Eigen::Vector3d::Zero(), c).x(), 0.05);  // matches it
}

TEST(OlfatiSaberLaw, RayHitRepelsAndBrakesOnlyTowardTheWall) {
  OlfatiSaberConfig c = config();
  c.c2_gamma = 0;  // the β terms alone
  law::Observation o = lone();
  law::Ray ray;
  ray.hit = true;
  ray.range_m = 1.0;
  ray.yaw_body_rad = std::numbers::pi / 2;  // body +y
  // Yawed by 90°: body +y is world −x.
  o.q_world_body =
      Eigen::Quaterniond(Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitZ()));
  o.rays = std::span<const law::Ray>(&ray, 1);
  const Eigen::Vector3d p(-0.5, 0.7, 0);  // toward the wall, and along it
  const Eigen::Vector3d u = olfati_saber_acceleration(o, p, c);
  EXPECT_GT(u.x(), 1.0);           // away from the wall at world −x
  EXPECT_NEAR(u.y(), 0.0, 1e-12);  // the part along the wall is left alone
  // The braking: c2_β b_ik (u·p) = 2√5 · 1 · 0.5 more push than when gliding along it.
  const Eigen::Vector3d u_glide = olfati_saber_acceleration(o, Eigen::Vector3d(0, 0.7, 0), c);
  EXPECT_NEAR(u.x() - u_glide.x(), 2 * std::sqrt(5.0) * 0.5, 1e-9);
  ray.range_m = 0.6 * 4 + 0.01;  // beyond d' = 2.4 m
  EXPECT_EQ(olfati_saber_acceleration(o, p, c).norm(), 0);
  ray.hit = false;
  ray.range_m = 1.0;
  EXPECT_EQ(olfati_saber_acceleration(o, p, c).norm(), 0);
}

/// A ring of n rays (body = world) from q against pillars and, when given, the
/// wall {x : a·x = a·w} (a its unit normal), as FlockSim casts it.
std::vector<law::Ray> ring(const Eigen::Vector2d& q, int n, const std::vector<Pillar>& pillars,
                           const Eigen::Vector2d& wall_a = Eigen::Vector2d::Zero(),
                           const Eigen::Vector2d& wall_w = Eigen::Vector2d::Zero(),
                           double range_m = 6.0) {
  std::vector<law::Ray> rays;
  for (int k = 0; k < n; ++k) {
    const double yaw = 2.0 * std::numbers::pi * k / n;
    const Eigen::Vector2d d(std::cos(yaw), std::sin(yaw));
    double best = HUGE_VAL;
    for (const auto& pl : pillars) {
      const Eigen::Vector2d f = q - pl.c;
      const double b = f.dot(d), c = f.squaredNorm() - pl.radius_m * pl.radius_m;
      if (b * b - c >= 0 && -b - std::sqrt(b * b - c) >= 0)
        best = std::min(best, -b - std::sqrt(b * b - c));
    }
    if (wall_a.norm() > 0 && wall_a.dot(d) < 0)
      best = std::min(best, wall_a.dot(wall_w - q) / wall_a.dot(d));
    law::Ray r;
    r.yaw_body_rad = yaw;
    r.hit = best <= range_m;
    r.range_m = r.hit ? best : range_m;
    rays.push_back(r);
  }
  return rays;
}

// Three rays on a pillar: the circle through their hits is the pillar, and
// its β-agent is the paper's sphere projection (Sec. VII).
TEST(OlfatiSaberObstacles, ThreeHitsOnAPillarGiveThePapersSphereBetaAgent) {
  const Pillar pillar{Eigen::Vector2d(1.6, 0.5), 1.0};
  law::Observation o = lone();
  const std::vector<law::Ray> rays = ring(o.p_world.head<2>(), 16, {pillar});
  ASSERT_EQ(std::count_if(rays.begin(), rays.end(), [](const law::Ray& r) { return r.hit; }), 3);
  o.rays = rays;
  const std::vector<Obstacle> obs = obstacles_from_rays(o);
  ASSERT_EQ(obs.size(), 1u);  // one β-agent per obstacle, not per ray
  EXPECT_TRUE(obs[0].sphere);
  EXPECT_LT((obs[0].y - pillar.c).norm(), 1e-9);
  EXPECT_NEAR(obs[0].radius_m, pillar.radius_m, 1e-9);

  const Eigen::Vector2d q = o.p_world.head<2>(), p(0.4, 0.3);
  const BetaAgent b = beta_agent(obs[0], q, p);
  const double mu = pillar.radius_m / (q - pillar.c).norm();
  const Eigen::Vector2d a = (q - pillar.c).normalized();
  EXPECT_LT((b.q - (mu * q + (1 - mu) * pillar.c)).norm(), 1e-9);
  EXPECT_LT((b.p - mu * (Eigen::Matrix2d::Identity() - a * a.transpose()) * p).norm(), 1e-9);
  EXPECT_NEAR((b.q - pillar.c).norm(), pillar.radius_m, 1e-9);  // on the surface
  // At rest with no mission: pushed straight away from the centre.
  const Eigen::Vector3d u = olfati_saber_acceleration(o, Eigen::Vector3d::Zero(), config());
  EXPECT_GT(u.norm(), 0.1);
  EXPECT_LT(std::abs(u.x() * a.y() - u.y() * a.x()), 1e-9 * u.norm());
  EXPECT_GT(u.head<2>().dot(a), 0);
}

// A wall seen by several rays is one wall, with its own normal (not a ray's).
TEST(OlfatiSaberObstacles, AWallIsOneBetaAgentWithTheWallsNormal) {
  law::Observation o = lone();
  const Eigen::Vector2d q = o.p_world.head<2>();
  const Eigen::Vector2d a(-std::cos(0.3), -std::sin(0.3));  // faces the drone, 17° off any ray
  const std::vector<law::Ray> rays = ring(q, 16, {}, a, q - 2.0 * a);
  ASSERT_GE(std::count_if(rays.begin(), rays.end(), [](const law::Ray& r) { return r.hit; }), 5);
  o.rays = rays;
  const std::vector<Obstacle> obs = obstacles_from_rays(o);
  ASSERT_EQ(obs.size(), 1u);
  EXPECT_FALSE(obs[0].sphere);
  EXPECT_LT((obs[0].a - a).norm(), 1e-9);
  const BetaAgent b = beta_agent(obs[0], q, Eigen::Vector2d(1, 0));
  EXPECT_LT((b.q - (q - 2.0 * a)).norm(), 1e-9);  // the foot of the perpendicular
  EXPECT_NEAR(b.p.dot(a), 0, 1e-12);              // moves along the wall
  // Two pillars either side: two β-agents, one each.
  const std::vector<law::Ray> two =
      ring(q, 16, {{q + Eigen::Vector2d(0, 2.0), 0.5}, {q + Eigen::Vector2d(0, -2.2), 0.5}});
  o.rays = two;
  EXPECT_EQ(obstacles_from_rays(o).size(), 2u);
}

// One hit ahead, the mission straight into it: the paper's β-agent (slide 0)
// only pushes back; the slide pushes round, to the side the drone already
// moves, else a_k turned +90°.
TEST(OlfatiSaberObstacles, HeadOnHitSlidesRoundOnlyWithTheSlide) {
  law::Observation o = lone(Eigen::Vector3d(0.8, 0, 0));
  law::Ray ray;
  ray.hit = true;
  ray.range_m = 2.0;
  o.rays = std::span<const law::Ray>(&ray, 1);
  const std::vector<Obstacle> obs = obstacles_from_rays(o);
  ASSERT_EQ(obs.size(), 1u);
  EXPECT_FALSE(obs[0].sphere);
  EXPECT_LT((obs[0].a - Eigen::Vector2d(-1, 0)).norm(), 1e-12);  // faces the ray
  const Eigen::Vector3d p(0.3, 0, 0);
  const Eigen::Vector3d paper = olfati_saber_acceleration(o, p, config({{"beta_slide", "0"}}));
  EXPECT_LT(paper.x(), 0);
  EXPECT_EQ(paper.y(), 0);
  // a = −x turned +90° is −y: a drone flying east passes on the south.
  const Eigen::Vector3d slide = olfati_saber_acceleration(o, p, config());
  EXPECT_LT(slide.y(), -0.5);
  EXPECT_DOUBLE_EQ(slide.x(), paper.x());
  // Already moving north along the surface: it keeps that side.
  EXPECT_GT(olfati_saber_acceleration(o, Eigen::Vector3d(0.3, 0.1, 0), config()).y(), 0.3);
  // The slide stops at the blocked speed, and without a mission into it there is none.
  const Eigen::Vector3d p_fast(0.3, -0.8, 0);
  EXPECT_EQ(olfati_saber_acceleration(o, p_fast, config()),
            olfati_saber_acceleration(o, p_fast, config({{"beta_slide", "0"}})));
  o.mission_velocity = Eigen::Vector3d(-0.8, 0.2, 0);
  EXPECT_EQ(olfati_saber_acceleration(o, p, config()).y(),
            olfati_saber_acceleration(o, p, config({{"beta_slide", "0"}})).y());
}

TEST(OlfatiSaberLaw, GoalPullIsBoundedBySigma1OrLinearWhenAsked) {
  law::Observation o = lone();
  o.goal_world = o.p_world + Eigen::Vector3d(50, 0, 0);
  const double c1 = config().c1_gamma;
  const Eigen::Vector3d u = olfati_saber_acceleration(o, Eigen::Vector3d::Zero(), config());
  EXPECT_GT(u.x(), 0.99 * c1);
  EXPECT_LE(u.x(), c1);
  const Eigen::Vector3d u_lin =
      olfati_saber_acceleration(o, Eigen::Vector3d::Zero(), config({{"gamma_position", "linear"}}));
  EXPECT_NEAR(u_lin.x(), c1 * 50, 1e-9);
}

TEST(OlfatiSaberLaw, IntegratesTheAccelerationIntoTheVelocityCommand) {
  auto law = make_law();
  EXPECT_FALSE(law->uses_obstacle_term());
  law::Observation o = lone(Eigen::Vector3d(1, 0, -0.3));
  o.tick = 10;
  o.dt_s = 0.02;
  o.v_world = Eigen::Vector3d(0.2, 0.1, 0.4);
  const double c2 = 2 * std::sqrt(config().c1_gamma);  // c2_gamma follows c1_gamma
  // First call: from the measured horizontal velocity, one step of u.
  Eigen::Vector3d v = law->step(o).velocity_world;
  Eigen::Vector3d expect(0.2 + c2 * (1 - 0.2) * 0.02, 0.1 - c2 * 0.1 * 0.02, -0.3);
  EXPECT_LT((v - expect).norm(), 1e-12);
  // Next tick: from its own v_c, whatever the drone measures.
  o.tick = 11;
  o.v_world = Eigen::Vector3d(-2, 2, 0);
  const Eigen::Vector3d v2 = law->step(o).velocity_world;
  expect = Eigen::Vector3d(v.x() + c2 * (1 - v.x()) * 0.02, v.y() - c2 * v.y() * 0.02, -0.3);
  EXPECT_LT((v2 - expect).norm(), 1e-12);
  // A gap in ticks starts again from the measured velocity.
  o.tick = 20;
  o.v_world = Eigen::Vector3d(0, 0, 0);
  EXPECT_NEAR(law->step(o).velocity_world.x(), c2 * 0.02, 1e-12);
  // The command never exceeds the framework's limit.
  o.tick = 21;
  o.mission_velocity = Eigen::Vector3d(50, 0, 0);
  o.max_speed_mps = 1.0;
  for (int k = 0; k < 500; ++k, ++o.tick) {
    v = law->step(o).velocity_world;
    ASSERT_LE(v.head<2>().norm(), 1.0 + 1e-12);
  }
  EXPECT_NEAR(v.x(), 1.0, 1e-9);
}

// ---- Flocks in FlockSim ----

struct Lattice {
  double mean_error = 0;      ///< mean |dist − d| / d over neighbour pairs (dist < r)
  double within_5pct = 0;     ///< fraction of neighbour pairs with |dist − d| < 0.05 d
  double closest = HUGE_VAL;  ///< smallest pair distance / d
  bool connected = true;      ///< the neighbour graph is one flock
  double energy = 0;          ///< deviation energy / d² (the paper's E(q))
};

Lattice lattice(const FlockSim& s, double d, double r) {
  Lattice l;
  const std::size_t n = s.drones.size();
  std::vector<std::size_t> group(n);
  for (std::size_t i = 0; i < n; ++i) group[i] = i;
  auto root = [&](std::size_t i) {
    while (group[i] != i) i = group[i];
    return i;
  };
  int pairs = 0, within = 0;
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) {
      const double dist = (s.drones[i].p - s.drones[j].p).norm();
      l.closest = std::min(l.closest, dist / d);
      if (dist >= r) continue;
      ++pairs;
      const double e = std::abs(dist - d) / d;
      l.mean_error += e;
      l.energy += e * e;
      within += e < 0.05;
      group[root(i)] = root(j);
    }
  l.mean_error /= std::max(pairs, 1);
  l.within_5pct = pairs ? static_cast<double>(within) / pairs : 0;
  l.energy /= pairs + 1;
  for (std::size_t i = 0; i < n; ++i) l.connected = l.connected && root(i) == root(0);
  return l;
}

/// n drones at uniform random positions in [0, box]², no two closer than
/// min_spacing_m and their neighbour graph (pairs closer than 1.2 D_int)
/// connected, velocities uniform in [−v, v]², all flying the default law.
/// Draws again from the same generator until the graph is connected.
FlockSim random_flock(unsigned seed, int n, double box_m, double min_spacing_m, double v) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> pos(0, box_m), vel(-v, v);
  for (;;) {
    FlockSim s;
    std::vector<Eigen::Vector2d> placed;
    while (static_cast<int>(placed.size()) < n) {
      const Eigen::Vector2d c(pos(gen), pos(gen));
      if (std::all_of(placed.begin(), placed.end(),
                      [&](const Eigen::Vector2d& q) { return (q - c).norm() >= min_spacing_m; }))
        placed.push_back(c);
    }
    for (const auto& c : placed) {
      const double vx = vel(gen), vy = vel(gen);
      s.add(make_law(), c.x(), c.y(), vx, vy);
    }
    if (lattice(s, s.inter_distance_m, 1.2 * s.inter_distance_m).connected) return s;
  }
}

// 15 drones, random connected start in a 12 m box (no two closer than
// 1.5 m, speeds up to 0.5 m/s per axis), mission velocity (0.5, 0, 0),
// D_int = 4 m, the law's defaults. Measured over seeds 1-20 at 20 s: mean
// |dist − d| ≤ 0.016 d (half the seeds ≤ 0.003 d), ≥ 92 % of neighbour
// pairs within 5 % of d (all of them in 11 seeds), closest pair ≥ 0.985 d,
// order ≥ 0.999, deviation energy ≤ 0.022 of the start's, closest approach
// over the flight 1.43 m; every criterion below holds from 11 s on. The
// pairs off by more than 5 % sit just inside r, where ρ_h has nearly
// switched φ_α off: the quasi α-lattice. (|dist − d| < 0.2 d for every pair
// closer than r = 1.2 d only bounds the compressed side; the test bounds
// that at 0.95 d.)
TEST(OlfatiSaberFlock, FreeFlockFormsAQuasiAlphaLatticeWithinTwentySeconds) {
  const double d = 4.0, r = 1.2 * d;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    FlockSim s = random_flock(seed, 15, 12.0, 1.5, 0.5);
    s.mission_velocity = Eigen::Vector3d(0.5, 0, 0);
    s.inter_distance_m = d;
    const Lattice start = lattice(s, d, r);
    ASSERT_TRUE(start.connected);
    s.run(20.0);
    const Lattice end = lattice(s, d, r);
    EXPECT_TRUE(end.connected);
    EXPECT_LT(end.mean_error, 0.03);
    EXPECT_GE(end.within_5pct, 0.85);
    EXPECT_GT(end.closest, 0.95);  // no pair squeezed below d
    EXPECT_LT(end.energy, 0.1 * start.energy);
    EXPECT_GT(s.order(), 0.99);
    EXPECT_LT((s.mean_velocity() - s.mission_velocity).norm(), 0.02);
    EXPECT_GT(s.min_distance_seen_m, 1.0);
  }
}

// The goal 24 m from the start, no mission velocity. Measured: the flock
// stops with its centroid 0.04 m from the goal, closest pair 0.89 d (0.95 d
// with c1_gamma = 0.5, which gathers the thesis course's six drones too
// loosely: see the header); with gamma_position = linear the same flock ends
// with pairs 0.00 m apart.
TEST(OlfatiSaberFlock, GathersAtTheGoalWithoutCollapsing) {
  const double d = 4.0;
  FlockSim s = random_flock(1, 15, 12.0, 1.5, 0.5);
  s.goal = Eigen::Vector3d(30, 6, s.z_m);
  s.run(150.0);
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& dr : s.drones) centroid += dr.p / static_cast<double>(s.drones.size());
  EXPECT_LT((centroid - s.goal).head<2>().norm(), 1.0);
  EXPECT_LT(s.mean_velocity().norm(), 0.05);
  EXPECT_GT(s.min_distance_m(), 0.85 * d);
  EXPECT_GT(s.min_distance_seen_m, 1.0);
}

/// Seven drones in a hexagon of side d (one at the centre) at x = −20 m,
/// flying +x at speed v toward a 0.5 m pillar at (0, pillar_y).
FlockSim hexagon_toward_pillar(double v, double pillar_y) {
  const double d = 4.0;
  FlockSim s;
  s.inter_distance_m = d;
  s.mission_velocity = Eigen::Vector3d(v, 0, 0);
  s.rays = 16;
  s.ray_range_m = 6.0;
  s.pillars.push_back({Eigen::Vector2d(0, pillar_y), 0.5});
  s.add(make_law(), -20, 0, v, 0);
  for (int k = 0; k < 6; ++k) {
    const double a = std::numbers::pi / 3 * k;
    s.add(make_law(), -20 + d * std::cos(a), d * std::sin(a), v, 0);
  }
  return s;
}

// Measured: closest approach to the pillar's surface 2.01 m at 0.5 m/s and
// 1.96 m at 1 m/s; closest pair 0.81 d and 0.75 d; the flock splits round the pillar
// and both halves fly on at the mission velocity (no goal to rejoin).
TEST(OlfatiSaberFlock, FlockPassesAPillarWithoutTouchingIt) {
  for (const double v : {0.5, 1.0}) {
    SCOPED_TRACE("v " + std::to_string(v));
    FlockSim s = hexagon_toward_pillar(v, 1.0);
    s.run(30.0 + 40.0 / v);
    EXPECT_GT(s.min_clearance_seen_m, 1.5);
    EXPECT_GT(s.min_distance_seen_m, 0.5 * s.inter_distance_m);
    for (const auto& dr : s.drones) EXPECT_GT(dr.p.x(), 10.0);  // all past it
    EXPECT_GT(s.order(), 0.99);
    EXPECT_LT((s.mean_velocity() - s.mission_velocity).norm(), 0.02);
  }
}

/// One drone at (−20, offset) flying +x at speed v toward a pillar at the
/// origin, seen by a ring of rays of 6 m.
FlockSim lone_toward_pillar(int rays, double radius_m, double v, double offset_m,
                            std::map<std::string, std::string> params = {}) {
  FlockSim s;
  s.mission_velocity = Eigen::Vector3d(v, 0, 0);
  s.rays = rays;
  s.ray_range_m = 6.0;
  s.pillars.push_back({Eigen::Vector2d(0, 0), radius_m});
  s.add(make_law(std::move(params)), -20, offset_m, v, 0);
  return s;
}

// The head-on trap (see the header): flown at a pillar's centre, or anywhere
// one ray alone sees it, the paper's β-agent (beta_slide = 0) only pushes
// back, and the drone stops about d' short and stays. Measured: 2.28 m from
// the surface at the closest, with 16 rays and a 0.5 m pillar and with 8
// rays and a 1 m pillar (the thesis course's).
TEST(OlfatiSaberFlock, WithoutTheSlideADroneFlownAtAPillarStopsShort) {
  for (const auto& [rays, radius] : {std::pair{16, 0.5}, std::pair{8, 1.0}}) {
    SCOPED_TRACE("rays " + std::to_string(rays));
    FlockSim s = lone_toward_pillar(rays, radius, 0.5, 0.0, {{"beta_slide", "0"}});
    s.run(120.0);
    EXPECT_GT(s.min_clearance_seen_m, 1.5);
    EXPECT_LT(s.drones[0].p.x(), -2.0);  // never got past
  }
}

// The case that trapped the drones on the thesis course: a lone drone flying
// its mission straight at a pillar's centre, or 0.5 or 0.9 of its radius
// off it (one ray sees it), gets past with the slide: round the side it
// drifts to, else the south (a_k turned +90°), then on at the mission
// velocity. Measured over these cases: closest to the surface 1.58 m, at
// most 27 s later than unobstructed (8 rays, 0.5 m/s, 0.9 R north of centre:
// it crosses the whole pillar to the default side).
TEST(OlfatiSaberFlock, DroneFlownAtAPillarsCentreGetsPast) {
  for (const auto& [rays, radius] : {std::pair{16, 0.5}, std::pair{8, 1.0}})
    for (const double v : {0.5, 0.8})
      for (const double offset : {0.0, 0.5, -0.9}) {
        SCOPED_TRACE("rays " + std::to_string(rays) + ", v " + std::to_string(v) + ", offset " +
                     std::to_string(offset));
        FlockSim s = lone_toward_pillar(rays, radius, v, offset * radius);
        s.run(20.0 / v + 40.0);
        EXPECT_GT(s.min_clearance_seen_m, 1.4);
        EXPECT_GT(s.drones[0].p.x(), 5.0);  // past it
        EXPECT_LT((s.drones[0].v - s.mission_velocity).norm(), 0.02);
      }
}

TEST(OlfatiSaberFlock, SameSeedGivesBitIdenticalFlights) {
  auto fly = [](unsigned seed) {
    FlockSim s = random_flock(seed, 12, 12.0, 1.5, 0.5);
    s.mission_velocity = Eigen::Vector3d(0.7, 0.1, 0);
    s.rays = 16;
    s.ray_range_m = 6.0;
    s.pillars.push_back({Eigen::Vector2d(20, 7), 0.5});
    s.run(40.0);
    std::vector<double> xy;
    for (const auto& dr : s.drones) xy.insert(xy.end(), {dr.p.x(), dr.p.y()});
    return xy;
  };
  const std::vector<double> a = fly(7), b = fly(7);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) EXPECT_EQ(a[k], b[k]) << k;
  EXPECT_NE(fly(8), a);
}

// ---- Parameters ----

TEST(OlfatiSaberParams, RefusesUnknownKeysAndOutOfRangeValues) {
  EXPECT_EQ(refused_field({{"c1_alpah", "0.3"}}), "agent.law.params.c1_alpah");
  try {
    make_law({{"hbeta", "0.5"}});
    FAIL() << "unknown key accepted";
  } catch (const law::ParamError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown parameter"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("h_beta"), std::string::npos);  // lists the real names
  }
  EXPECT_EQ(refused_field({{"h_alpha", "1"}}), "agent.law.params.h_alpha");
  EXPECT_EQ(refused_field({{"h_beta", "-0.1"}}), "agent.law.params.h_beta");
  EXPECT_EQ(refused_field({{"epsilon", "0"}}), "agent.law.params.epsilon");
  EXPECT_EQ(refused_field({{"r_ratio", "1"}}), "agent.law.params.r_ratio");
  EXPECT_EQ(refused_field({{"d_m", "0.05"}}), "agent.law.params.d_m");
  EXPECT_EQ(refused_field({{"d_m", "-4"}}), "agent.law.params.d_m");
  EXPECT_EQ(refused_field({{"c1_beta", "-1"}}), "agent.law.params.c1_beta");
  EXPECT_EQ(refused_field({{"c2_gamma", "fast"}}), "agent.law.params.c2_gamma");
  EXPECT_EQ(refused_field({{"obstacle_ratio", "0"}}), "agent.law.params.obstacle_ratio");
  EXPECT_EQ(refused_field({{"gamma_position", "quadratic"}}), "agent.law.params.gamma_position");
  EXPECT_EQ(refused_field({{"beta_slide", "-0.5"}}), "agent.law.params.beta_slide");
  EXPECT_EQ(refused_field({{"beta_slide", "11"}}), "agent.law.params.beta_slide");
  // Cross-field: 0 < a <= b.
  EXPECT_EQ(refused_field({{"a", "6"}}), "agent.law.params.a");
  EXPECT_EQ(refused_field({{"a", "0"}, {"b", "5"}}), "agent.law.params.a");
}

TEST(OlfatiSaberParams, PaperValuesBuildAndC2FollowsC1) {
  EXPECT_EQ(refused_field({{"d_m", "7"},
                           {"r_ratio", "1.2"},
                           {"epsilon", "0.1"},
                           {"a", "5"},
                           {"b", "5"},
                           {"h_alpha", "0.2"},
                           {"h_beta", "0.9"},
                           {"obstacle_ratio", "0.6"},
                           {"c1_alpha", "0.3"},
                           {"c2_alpha", "1.1"},
                           {"c1_beta", "5"},
                           {"c2_beta", "4.5"},
                           {"c1_gamma", "0.5"},
                           {"c2_gamma", "1.4"},
                           {"gamma_position", "linear"},
                           {"beta_slide", "0"}}),
            "");
  EXPECT_EQ(refused_field({{"d_m", "0"}, {"a", "2"}, {"b", "5"}}), "");
  const OlfatiSaberConfig c = config({{"c1_beta", "9"}});
  EXPECT_DOUBLE_EQ(c.c2_beta, 6.0);  // 2√c1 unless given
  EXPECT_DOUBLE_EQ(config({{"c1_beta", "9"}, {"c2_beta", "1"}}).c2_beta, 1.0);
  EXPECT_DOUBLE_EQ(config().c2_alpha, 2 * std::sqrt(0.3));
}

}  // namespace
}  // namespace ddswarm::agent::laws
