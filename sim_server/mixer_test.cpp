// The mixer delivers the demanded wrench when it can, and when it cannot it
// gives up yaw first, then collective thrust, and keeps roll/pitch.
#include "sim_server/mixer.hpp"

#include <gtest/gtest.h>

namespace ddswarm::sim {
namespace {

Wrench demand(double thrust, double tx, double ty, double tz) {
  Wrench w;
  w.thrust_n = thrust;
  w.torque_body_nm = {tx, ty, tz};
  return w;
}

void expect_rotors_within_limits(const QuadrotorParams& q, const MixerResult& r) {
  for (double w : r.omega_rad_s) {
    EXPECT_GE(w, q.omega_min_rad_s);
    EXPECT_LE(w, q.omega_max_rad_s() + 1e-9);
  }
}

class MixerTest : public ::testing::Test {
 protected:
  QuadrotorParams q;
  Mixer mixer{q};
  double weight = q.mass_kg * kGravityMps2;
};

TEST_F(MixerTest, AllocationInvertsAndMatchesTheRotorModel) {
  EXPECT_TRUE((mixer.allocation() * mixer.mixing()).isIdentity(1e-12));
  const MixerResult r = mixer.mix(demand(weight, 0.05, -0.03, 0.01));
  const Wrench model = q.rotor_wrench(r.omega_rad_s);  // what the physics will apply
  EXPECT_NEAR(model.thrust_n, r.produced.thrust_n, 1e-9);
  EXPECT_TRUE(model.torque_body_nm.isApprox(r.produced.torque_body_nm, 1e-9));
}

TEST_F(MixerTest, UnsaturatedDemandIsProducedExactly) {
  const Wrench d = demand(weight, 0.1, -0.2, 0.02);
  const MixerResult r = mixer.mix(d);
  EXPECT_NEAR(r.produced.thrust_n, d.thrust_n, 1e-9);
  EXPECT_TRUE(r.produced.torque_body_nm.isApprox(d.torque_body_nm, 1e-9));
  EXPECT_EQ(r.roll_pitch_scale, 1.0);
  EXPECT_EQ(r.yaw_scale, 1.0);
  EXPECT_FALSE(r.thrust_limited);
}

TEST_F(MixerTest, ExcessCollectiveIsCutToKeepRollPitch) {
  // 20 N exceeds the 16.7 N the four rotors can give at all.
  const Wrench d = demand(20.0, 0.3, -0.2, 0.0);
  const MixerResult r = mixer.mix(d);
  expect_rotors_within_limits(q, r);
  EXPECT_TRUE(r.thrust_limited);
  EXPECT_LT(r.produced.thrust_n, d.thrust_n);
  EXPECT_EQ(r.roll_pitch_scale, 1.0);
  EXPECT_NEAR(r.produced.torque_body_nm.x(), 0.3, 1e-9);
  EXPECT_NEAR(r.produced.torque_body_nm.y(), -0.2, 1e-9);
  // The collective is only cut as far as needed: the top rotor is at its limit.
  const double top = *std::max_element(r.thrust_n.begin(), r.thrust_n.end());
  EXPECT_NEAR(top, mixer.rotor_thrust_max_n(), 1e-9);
}

TEST_F(MixerTest, YawIsSacrificedFirst) {
  // Hover plus a sizeable roll torque plus far more yaw than the rotors can give.
  const Wrench d = demand(weight, 0.4, 0.0, 0.5);
  const MixerResult r = mixer.mix(d);
  expect_rotors_within_limits(q, r);
  EXPECT_NEAR(r.produced.thrust_n, d.thrust_n, 1e-9);
  EXPECT_NEAR(r.produced.torque_body_nm.x(), 0.4, 1e-9);
  EXPECT_NEAR(r.produced.torque_body_nm.y(), 0.0, 1e-9);
  EXPECT_LT(r.yaw_scale, 1.0);
  EXPECT_GT(r.produced.torque_body_nm.z(), 0.0);  // what yaw there is, is in the right direction
  EXPECT_LT(r.produced.torque_body_nm.z(), 0.5);
  EXPECT_FALSE(r.thrust_limited);
}

TEST_F(MixerTest, ExcessCollectiveAlsoStarvesYaw) {
  const Wrench d = demand(20.0, 0.2, 0.0, -0.3);
  const MixerResult r = mixer.mix(d);
  expect_rotors_within_limits(q, r);
  EXPECT_NEAR(r.produced.torque_body_nm.x(), 0.2, 1e-9);
  EXPECT_TRUE(r.thrust_limited);
  EXPECT_LT(r.yaw_scale, 1.0);
}

TEST_F(MixerTest, ImpossibleRollPitchKeepsItsDirection) {
  const Wrench d = demand(weight, 3.0, 2.0, 0.0);  // far beyond what 4 N rotors on 0.23 m arms give
  const MixerResult r = mixer.mix(d);
  expect_rotors_within_limits(q, r);
  EXPECT_LT(r.roll_pitch_scale, 1.0);
  EXPECT_GT(r.roll_pitch_scale, 0.0);
  const Eigen::Vector2d want = d.torque_body_nm.head<2>().normalized();
  const Eigen::Vector2d got = r.produced.torque_body_nm.head<2>().normalized();
  EXPECT_NEAR(want.dot(got), 1.0, 1e-9);
}

TEST_F(MixerTest, LowCollectiveIsNotBoostedAirmodeOff) {
  const Wrench d = demand(0.4, 0.2, 0.0, 0.0);
  const MixerResult r = mixer.mix(d);
  expect_rotors_within_limits(q, r);
  EXPECT_NEAR(r.produced.thrust_n, 0.4, 1e-9);
  EXPECT_LT(r.roll_pitch_scale, 1.0);
  EXPECT_NEAR(*std::min_element(r.thrust_n.begin(), r.thrust_n.end()), 0.0, 1e-9);
}

TEST_F(MixerTest, ZeroDemandStopsRotors) {
  const MixerResult r = mixer.mix(demand(0, 0, 0, 0));
  for (double w : r.omega_rad_s) EXPECT_EQ(w, 0.0);
}

}  // namespace
}  // namespace ddswarm::sim
