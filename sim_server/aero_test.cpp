#include "sim_server/aero.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace ddswarm::sim;
using Eigen::Vector3d;

TEST(GroundEffect, TheThrustRatioIsCheesemanAndBennetts) {
  const double r = 0.1143;  // AirSim's generic quadrotor: 9-inch propellers
  // T_IGE / T_OGE = 1 / (1 - (R / 4z)^2): one radius up, 16/15; two radii, 64/63.
  EXPECT_NEAR(ground_effect_ratio(r, r), 16.0 / 15.0, 1e-12);
  EXPECT_NEAR(ground_effect_ratio(2 * r, r), 64.0 / 63.0, 1e-12);
  // Above two diameters, none.
  EXPECT_EQ(ground_effect_ratio(4 * r, r), 1.0);
  EXPECT_EQ(ground_effect_ratio(10.0, r), 1.0);
  // It grows toward the ground, and is held at R / 2 (4/3) below.
  EXPECT_GT(ground_effect_ratio(0.8 * r, r), ground_effect_ratio(r, r));
  EXPECT_NEAR(ground_effect_ratio(0.1 * r, r), 4.0 / 3.0, 1e-12);
  EXPECT_NEAR(ground_effect_ratio(0.0, r), 4.0 / 3.0, 1e-12);
}

TEST(Downwash, HalfAMetreBelowAnotherDroneTheForceIsTheModels) {
  const AeroConfig c;
  const double r = 0.023135;  // the Crazyflie's, as gym-pybullet-drones fits the model to
  const Vector3d above(0, 0, 1.5), below(0, 0, 1.0);
  // Straight below: alpha = C1 (R / (4 dz))^2.
  const double alpha = 2267.18 * std::pow(r / (4 * 0.5), 2);
  EXPECT_NEAR(downwash_force(c, above, below, r), alpha, 1e-12);
  // 5 cm aside: alpha exp(-(dxy / beta)^2 / 2), beta = 0.16 dz - 0.11 = -0.03 (|beta| used).
  EXPECT_NEAR(downwash_force(c, above, below + Vector3d(0.05, 0, 0), r),
              alpha * std::exp(-0.5 * std::pow(0.05 / 0.03, 2)), 1e-12);
  // Weaker farther down, nothing level or above, nothing 10 m aside.
  EXPECT_LT(downwash_force(c, above, below - Vector3d(0, 0, 1), r), alpha);
  EXPECT_EQ(downwash_force(c, below, above, r), 0.0);
  EXPECT_EQ(downwash_force(c, above, Vector3d(0, 0, 1.5), r), 0.0);
  EXPECT_EQ(downwash_force(c, above, Vector3d(10, 0, 1.0), r), 0.0);
  // Where the model's beta passes through 0 (dz = 0.6875 m) the force stays finite.
  EXPECT_TRUE(std::isfinite(downwash_force(c, above, Vector3d(0.01, 0, 1.5 - 0.6875), r)));
}

TEST(RotorDrag, TheForceIsLinearInAirspeedAndRotorSpeedAgainstTheAirspeed) {
  // F = -c (.) v sum |omega|: the Crazyflie's coefficients (Förster) at 2 m/s
  // forward, 1 m/s left and 0.5 m/s up, rotors at 1500 rad/s.
  const Vector3d c(9.1785e-7, 9.1785e-7, 10.311e-7), v(2, 1, 0.5);
  const std::array<double, 4> w{1500, 1500, 1500, 1500};
  const Vector3d f = rotor_drag_force(c, v, w);
  EXPECT_NEAR(f.x(), -9.1785e-7 * 2 * 6000, 1e-15);
  EXPECT_NEAR(f.y(), -9.1785e-7 * 1 * 6000, 1e-15);
  EXPECT_NEAR(f.z(), -10.311e-7 * 0.5 * 6000, 1e-15);
  // Linear: twice the airspeed or the rotor speeds, twice the force; a
  // rotor's direction of spin does not matter.
  EXPECT_TRUE(rotor_drag_force(c, 2 * v, w).isApprox(2 * f, 1e-12));
  EXPECT_TRUE(rotor_drag_force(c, v, {3000, 3000, -3000, -3000}).isApprox(2 * f, 1e-12));
  EXPECT_EQ(rotor_drag_force(c, v, {0, 0, 0, 0}), Vector3d::Zero());
}
