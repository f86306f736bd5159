// The swarm stepped as the server steps it: a mixed swarm of two airframes
// hovers, each drone with its own mass, rotors and gains, and each airframe
// holds its place in a steady 5 m/s wind.
#include "sim_server/swarm_physics.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace ddswarm::sim {
namespace {

constexpr int kSubsteps = 20;  // 1 kHz physics, 50 Hz control: the server's defaults
constexpr double kDt = 0.001;

/// Generic quads (even ids) and Crazyflies (odd ids), 4 m apart.
Fleet mixed(int n) {
  Fleet f;
  f.quadrotors = {QuadrotorParams::preset(Airframe::kGeneric),
                  QuadrotorParams::preset(Airframe::kCrazyflie)};
  f.controllers = {ControllerConfig::preset(Airframe::kGeneric),
                   ControllerConfig::preset(Airframe::kCrazyflie)};
  for (int i = 0; i < n; ++i) f.airframe_of.push_back(i % 2);
  return f;
}

std::vector<Eigen::Vector3d> row(int n) {
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i < n; ++i) p.emplace_back(4.0 * i, 0, 0);
  return p;
}

void fly(SwarmPhysics& s, std::vector<VelocitySetpoint>& sp, double seconds) {
  const int ticks = static_cast<int>(std::lround(seconds / (kSubsteps * kDt)));
  for (int k = 0; k < ticks; ++k) s.step(sp, kSubsteps, kDt);
}

/// Motors on, climbs at 1 m/s for 2 s, then holds (zero velocity) for 4 s.
std::vector<VelocitySetpoint> take_off(SwarmPhysics& s, int n) {
  std::vector<VelocitySetpoint> sp(n);
  for (auto& v : sp) {
    v.motors_on = true;
    v.v_world = {0, 0, 1};
  }
  fly(s, sp, 2.0);
  for (auto& v : sp) v.v_world.setZero();
  fly(s, sp, 4.0);
  return sp;
}

TEST(SwarmPhysics, AMixedSwarmHoversEachDroneOnItsOwnRotors) {
  const int n = 6;
  SwarmPhysics s(SceneConfig{}, mixed(n), row(n), 1);
  auto sp = take_off(s, n);
  std::vector<double> z0(n);
  for (int i = 0; i < n; ++i) z0[i] = s.state(i).p_world.z();
  fly(s, sp, 5.0);
  for (int i = 0; i < n; ++i) {
    const QuadrotorParams& q = s.airframe(i);
    EXPECT_EQ(q.airframe, i % 2 ? Airframe::kCrazyflie : Airframe::kGeneric) << "drone " << i;
    const RigidState st = s.state(i);
    EXPECT_NEAR(st.p_world.z(), 2.0, 0.1) << "drone " << i << " climbed 2 s at 1 m/s";
    EXPECT_LT(std::abs(st.p_world.z() - z0[i]), 0.02) << "drone " << i << " holds its altitude";
    EXPECT_LT(st.v_world.norm(), 0.01) << "drone " << i;
    // Its rotors turn at its own hover speed: k_f w^2 = m g / 4.
    for (double w : s.rotor_speeds(i)) EXPECT_NEAR(w, q.hover_omega(), 0.01 * q.hover_omega());
  }
}

/// A drone of airframe a takes off in a steady 5 m/s wind and is then held
/// at the place it reached by a proportional position loop on top of its
/// velocity command (0.5 m/s per m, as an agent's law would close it).
/// Returns the largest distance from that place over 20 s, after 10 s of
/// settling; *settled: the distance at the end of the settling.
double wind_hold_error(Airframe a, double* settled) {
  Fleet f{{QuadrotorParams::preset(a)}, {ControllerConfig::preset(a)}, {0}};
  WindConfig wind;
  wind.steady_mps = {5, 0, 0};
  SwarmPhysics s(SceneConfig{}, f, {{0, 0, 0}}, 1, wind);
  auto sp = take_off(s, 1);
  const Eigen::Vector3d place = s.state(0).p_world;
  auto hold = [&](double seconds, double* worst) {
    const int ticks = static_cast<int>(std::lround(seconds / (kSubsteps * kDt)));
    for (int k = 0; k < ticks; ++k) {
      sp[0].v_world = 0.5 * (place - s.state(0).p_world);
      s.step(sp, kSubsteps, kDt);
      if (worst) *worst = std::max(*worst, (s.state(0).p_world - place).norm());
    }
  };
  hold(10.0, nullptr);
  *settled = (s.state(0).p_world - place).norm();
  double worst = 0;
  hold(20.0, &worst);
  return worst;
}

TEST(SwarmPhysics, EachAirframeHoldsItsPlaceInA5MpsWind) {
  for (Airframe a : {Airframe::kGeneric, Airframe::kCrazyflie}) {
    double settled = 0;
    const double worst = wind_hold_error(a, &settled);
    EXPECT_LT(settled, 0.05) << airframe_name(a) << ": back within 5 cm after 10 s";
    EXPECT_LT(worst, 0.05) << airframe_name(a) << ": within 5 cm of its place over 20 s";
  }
}

TEST(RotorDrag, PushesAHoveringDroneAsTheFormulaSaysOnlyWhenOn) {
  // Rotors at hover speed in 3 m/s of wind along x, body drag removed: the
  // drone accelerates downwind at c_x * 3 * 4 w_hover / m with rotor drag on,
  // and not at all with it off.
  for (Airframe a : {Airframe::kGeneric, Airframe::kCrazyflie}) {
    QuadrotorParams q = QuadrotorParams::preset(a);
    q.drag_quadratic_body.setZero();
    for (bool on : {true, false}) {
      PhysicsWorld w(SceneConfig{}, q, {{0, 0, 0}}, 0.0);
      AeroConfig aero;
      aero.rotor_drag = on;
      w.set_aero(aero);
      w.reset_drone(0, {0, 0, 50}, 0.0);
      const double h = q.hover_omega();
      w.set_rotor_commands(0, {h, h, h, h});
      for (int k = 0; k < 500; ++k) w.step(kDt);  // the rotors spin up
      w.set_air_velocity(0, {3, 0, 0});
      const double v0 = w.state(0).v_world.x();
      for (int k = 0; k < 20; ++k) w.step(kDt);
      const double accel = (w.state(0).v_world.x() - v0) / 0.02;
      const double expected = on ? q.rotor_drag_body.x() * 3 * 4 * h / q.mass_kg : 0.0;
      EXPECT_NEAR(accel, expected, 0.02 * expected + 1e-9)
          << airframe_name(a) << (on ? " on" : " off");
    }
  }
}

}  // namespace
}  // namespace ddswarm::sim
