#include "sim_server/flight_controller.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace ddswarm::sim {
namespace {

double wrap_pi(double a) {
  constexpr double kPi = std::numbers::pi;
  a = std::fmod(a + kPi, 2 * kPi);
  if (a < 0) a += 2 * kPi;
  return a - kPi;
}

Eigen::Quaterniond canonical(const Eigen::Quaterniond& q) {
  return q.w() < 0 ? Eigen::Quaterniond(-q.w(), -q.x(), -q.y(), -q.z()) : q;
}

/// Attitude with body z along z_world_des and heading yaw (PX4 bodyzToAttitude).
/// cos_yaw, sin_yaw: of the heading yaw.
Eigen::Quaterniond attitude_from_thrust(const Eigen::Vector3d& z_des, double cos_yaw,
                                        double sin_yaw) {
  const Eigen::Vector3d x_course(cos_yaw, sin_yaw, 0.0);
  Eigen::Vector3d y_des = z_des.cross(x_course);
  if (y_des.squaredNorm() < 1e-12) y_des = Eigen::Vector3d(-sin_yaw, cos_yaw, 0.0);
  y_des.normalize();
  const Eigen::Vector3d x_des = y_des.cross(z_des);
  Eigen::Matrix3d r;
  r.col(0) = x_des;
  r.col(1) = y_des;
  r.col(2) = z_des;
  return Eigen::Quaterniond(r).normalized();
}

}  // namespace

void load(YamlSection s, ControllerConfig& c) {
  FieldLoader load(s);
  ControllerConfig::fields(c, load);
  s.finish();
}

void ControllerConfig::validate() const {
  FieldChecker check("controller");
  ControllerConfig::fields(*this, check);
}

ControllerConfig ControllerConfig::preset(Airframe a) {
  ControllerConfig c;
  if (a == Airframe::kGeneric) return c;
  // The generic gains fly the Crazyflie too (they are angular accelerations
  // per error, the inertia applied), with a rate loop stable to 100 1/s and
  // more; its smaller size and lighter weight (wind moves it three times as
  // much per unit mass) call for tighter loops: a quarter faster in
  // velocity, half again in attitude and rate, measured with the step tests
  // (flight_controller_test.cpp) to stay below 3 % overshoot.
  c.vel_p_xy = 4.0;
  c.vel_i_xy = 1.5;
  c.vel_p_z = 5.0;
  c.att_p_rp = 12.0;
  c.rate_p_rp = 40.0;
  c.max_body_rate_rad_s = 6.0;
  return c;
}

FlightController::FlightController(const QuadrotorParams& params, const ControllerConfig& config)
    : params_(params),
      cfg_(config),
      mixer_(params),
      inertia_(params.inertia()),
      tan_max_tilt_(std::tan(config.max_tilt_rad)) {}

void FlightController::reset(double yaw_rad) {
  yaw_sp_ = wrap_pi(yaw_rad);
  yaw_rate_sp_ = 0.0;
  vel_int_.setZero();
  w_prev_.setZero();
  w_dot_filt_.setZero();
  have_prev_ = false;
}

std::array<double, 4> FlightController::update(const RigidState& s, const VelocitySetpoint& sp,
                                               double dt) {
  const Eigen::Quaterniond q = s.q_world_body.normalized();
  if (!sp.motors_on) {
    reset(yaw_of(q));
    status_ = ControllerStatus{};
    status_.q_sp_world_body = q;
    status_.yaw_sp_rad = yaw_sp_;
    return {0.0, 0.0, 0.0, 0.0};
  }

  // Setpoint limits.
  Eigen::Vector3d v_sp = sp.v_world;
  const double v_h = v_sp.head<2>().norm();
  if (v_h > cfg_.max_speed_mps) v_sp.head<2>() *= cfg_.max_speed_mps / v_h;
  v_sp.z() = std::clamp(v_sp.z(), -cfg_.max_vertical_speed_mps, cfg_.max_vertical_speed_mps);
  const double yaw_rate_cmd =
      std::clamp(sp.yaw_rate_rad_s, -cfg_.max_yaw_rate_rad_s, cfg_.max_yaw_rate_rad_s);
  const double dr = std::clamp(yaw_rate_cmd - yaw_rate_sp_, -cfg_.max_yaw_accel_rad_s2 * dt,
                               cfg_.max_yaw_accel_rad_s2 * dt);
  yaw_rate_sp_ += dr;
  const double yaw_accel = dt > 0 ? dr / dt : 0.0;
  const double yaw_rate = yaw_rate_sp_;
  yaw_sp_ = wrap_pi(yaw_sp_ + yaw_rate * dt);

  // Velocity PI -> acceleration.
  const Eigen::Vector3d err = v_sp - s.v_world;
  const Eigen::Vector3d kp(cfg_.vel_p_xy, cfg_.vel_p_xy, cfg_.vel_p_z);
  Eigen::Vector3d accel = kp.cwiseProduct(err) + vel_int_;
  bool sat_xy = false, sat_z = false;
  const double a_h = accel.head<2>().norm();
  if (a_h > cfg_.max_accel_mps2) {
    accel.head<2>() *= cfg_.max_accel_mps2 / a_h;
    sat_xy = true;
  }
  const double a_down = std::min(cfg_.max_accel_mps2, 0.8 * kGravityMps2);
  if (accel.z() > cfg_.max_accel_mps2 || accel.z() < -a_down) {
    accel.z() = std::clamp(accel.z(), -a_down, cfg_.max_accel_mps2);
    sat_z = true;
  }
  // Anti-windup: the integrators see the error clamped to +-vel_i_band_mps,
  // so a transient stores little to unwind while a steady disturbance is
  // still worked off; they hold while the output saturates, and are clamped.
  if (!sat_xy) {
    Eigen::Vector2d e = err.head<2>();
    const double n = e.norm();
    if (n > cfg_.vel_i_band_mps) e *= cfg_.vel_i_band_mps / n;
    vel_int_.head<2>() += cfg_.vel_i_xy * e * dt;
    const double m = vel_int_.head<2>().norm();
    if (m > cfg_.vel_i_max_mps2) vel_int_.head<2>() *= cfg_.vel_i_max_mps2 / m;
  }
  if (!sat_z) {
    const double e = std::clamp(err.z(), -cfg_.vel_i_band_mps, cfg_.vel_i_band_mps);
    vel_int_.z() =
        std::clamp(vel_int_.z() + cfg_.vel_i_z * e * dt, -cfg_.vel_i_max_mps2, cfg_.vel_i_max_mps2);
  }

  // Thrust vector, tilt limited by shrinking the horizontal part (altitude first).
  Eigen::Vector3d f = params_.mass_kg * (accel + Eigen::Vector3d(0, 0, kGravityMps2));
  if (cfg_.drag_feedforward) {
    const Eigen::Vector3d v_b = q.inverse() * s.v_world;
    const Eigen::Vector3d drag_b =
        -params_.drag_quadratic_body.cwiseProduct(v_b.cwiseProduct(v_b.cwiseAbs())) -
        params_.drag_linear_n_per_mps * v_b;
    f -= q * drag_b;
  }
  const double f_h_max = f.z() * tan_max_tilt_;
  const double f_h = f.head<2>().norm();
  if (f_h > f_h_max) f.head<2>() *= f_h_max / f_h;
  const Eigen::Vector3d z_des = f.normalized();
  // The heading setpoint rarely changes (yaw is held): its sine and cosine
  // are computed again only when it does.
  if (!(yaw_sp_ == trig_yaw_)) {
    trig_yaw_ = yaw_sp_;
    cos_yaw_sp_ = std::cos(yaw_sp_);
    sin_yaw_sp_ = std::sin(yaw_sp_);
  }
  const Eigen::Quaterniond q_sp = attitude_from_thrust(z_des, cos_yaw_sp_, sin_yaw_sp_);
  const Eigen::Vector3d z_body = q * Eigen::Vector3d::UnitZ();
  // Project on the current body z so a tilting vehicle does not sink or climb.
  const double thrust = std::max(0.0, f.dot(z_body));

  // Attitude P, roll/pitch before yaw (PX4 AttitudeControl).
  const double yaw_w = std::clamp(cfg_.att_p_yaw / cfg_.att_p_rp, 0.0, 1.0);
  Eigen::Quaterniond qd_red = Eigen::Quaterniond::FromTwoVectors(z_body, z_des);
  if (std::abs(qd_red.x()) > 1 - 1e-5 || std::abs(qd_red.y()) > 1 - 1e-5)
    qd_red = q_sp;  // thrust vector flipped: the reduced attitude is ill-defined
  else
    qd_red = qd_red * q;
  Eigen::Quaterniond q_mix = canonical(qd_red.inverse() * q_sp);
  const double mix_w = std::clamp(q_mix.w(), -1.0, 1.0);
  const double mix_z = std::clamp(q_mix.z(), -1.0, 1.0);
  const Eigen::Quaterniond qd = qd_red * Eigen::Quaterniond(std::cos(yaw_w * std::acos(mix_w)), 0,
                                                            0, std::sin(yaw_w * std::asin(mix_z)));
  const Eigen::Quaterniond qe = canonical(q.inverse() * qd);
  const Eigen::Vector3d att_err = 2.0 * qe.vec();
  // The yaw weight already scales the yaw error to att_p_yaw (as in PX4's
  // setProportionalGain), so every axis uses the roll/pitch gain here.
  const Eigen::Vector3d z_world_in_body = q.inverse() * Eigen::Vector3d::UnitZ();
  Eigen::Vector3d rate_sp = cfg_.att_p_rp * att_err + z_world_in_body * yaw_rate;  // + feed-forward
  for (int k = 0; k < 3; ++k)
    rate_sp[k] = std::clamp(rate_sp[k], -cfg_.max_body_rate_rad_s, cfg_.max_body_rate_rad_s);

  // Body-rate P + D (on the measured angular acceleration) -> torque.
  const Eigen::Vector3d& w = s.w_body;
  Eigen::Vector3d w_dot = Eigen::Vector3d::Zero();
  if (have_prev_ && dt > 0) w_dot = (w - w_prev_) / dt;
  const double lpf = dt / (dt + 1.0 / (2 * std::numbers::pi * cfg_.rate_d_lpf_hz));
  w_dot_filt_ += lpf * (w_dot - w_dot_filt_);
  w_prev_ = w;
  have_prev_ = true;
  const Eigen::Vector3d kp_rate(cfg_.rate_p_rp, cfg_.rate_p_rp, cfg_.rate_p_yaw);
  const Eigen::Vector3d kd_rate(cfg_.rate_d_rp, cfg_.rate_d_rp, 0.0);
  const Eigen::Vector3d ang_accel = kp_rate.cwiseProduct(rate_sp - w) -
                                    kd_rate.cwiseProduct(w_dot_filt_) +
                                    z_world_in_body * yaw_accel;  // slew feed-forward
  Wrench demand;
  demand.thrust_n = thrust;
  demand.torque_body_nm = inertia_.cwiseProduct(ang_accel) + w.cross(inertia_.cwiseProduct(w));

  status_.v_sp_world = v_sp;
  status_.accel_sp_world = accel;
  status_.q_sp_world_body = q_sp;
  status_.rate_sp_body = rate_sp;
  status_.yaw_sp_rad = yaw_sp_;
  status_.mix = mixer_.mix(demand);
  return status_.mix.omega_rad_s;
}

}  // namespace ddswarm::sim
