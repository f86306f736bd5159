#pragma once
// The drone's autopilot: velocity setpoint in, rotor speeds out.
//
// A PX4 / AirSim SimpleFlight style cascade run at the physics rate:
// velocity PI -> acceleration -> thrust vector (tilt limited) + yaw setpoint
// -> attitude P (roll/pitch before yaw) -> body-rate P(+D) -> torques ->
// mixer. Pure: no I/O, no Bullet.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <limits>

#include "common/yaml_section.hpp"
#include "sim_server/mixer.hpp"
#include "sim_server/quadrotor.hpp"

namespace ddswarm::sim {

/// Limits and gains of the flight controller. Rate-loop gains are angular
/// accelerations per error (the vehicle's inertia is applied by the
/// controller), so they do not depend on the airframe.
struct ControllerConfig {
  double max_speed_mps = 5.0;           ///< m/s, horizontal speed command limit, > 0
  double max_vertical_speed_mps = 2.0;  ///< m/s, vertical speed command limit, > 0
  double max_yaw_rate_rad_s = 1.5;      ///< rad/s, yaw rate command limit, > 0
  /// rad/s^2, > 0: the yaw rate command is slewed at this rate, which the
  /// airframe can follow (the generic quad manages ~6 at hover), so the yaw
  /// setpoint never runs ahead of the vehicle.
  double max_yaw_accel_rad_s2 = 4.0;
  double max_tilt_rad = 0.6;    ///< rad, tilt of the thrust vector, in (0, 1.2]
  double max_accel_mps2 = 4.0;  ///< m/s^2, horizontal and vertical acceleration limit, > 0
                                ///< (downward additionally limited to 0.8 g)

  double vel_p_xy = 3.0;        ///< 1/s, horizontal velocity P gain, > 0
  double vel_p_z = 4.0;         ///< 1/s, vertical velocity P gain, > 0
  double vel_i_xy = 1.0;        ///< 1/s^2, horizontal velocity I gain, >= 0
  double vel_i_z = 2.0;         ///< 1/s^2, vertical velocity I gain, >= 0
  double vel_i_max_mps2 = 2.0;  ///< m/s^2, integrator clamp per axis group, >= 0
  /// m/s, > 0: the integrators integrate the velocity error clamped to this
  /// magnitude, so a step transient leaves little in them to unwind later.
  double vel_i_band_mps = 0.1;
  /// Cancel the airframe's modelled body drag at the measured velocity, so the
  /// integrators only absorb model errors.
  bool drag_feedforward = true;

  double att_p_rp = 8.0;  ///< 1/s, roll/pitch attitude P gain, > 0
  /// 1/s, yaw attitude P gain, > 0. As in PX4 it acts as a weight
  /// att_p_yaw/att_p_rp (capped at 1) on the yaw error, so yaw gives way to
  /// roll/pitch on large errors.
  double att_p_yaw = 3.0;
  double max_body_rate_rad_s = 4.0;  ///< rad/s, body-rate setpoint limit on every axis, > 0

  double rate_p_rp = 25.0;   ///< 1/s, roll/pitch rate P gain (rad/s^2 per rad/s), > 0
  double rate_p_yaw = 15.0;  ///< 1/s, yaw rate P gain, > 0
  double rate_d_rp = 0.0;    ///< -, roll/pitch rate D gain on measured angular acceleration, >= 0
  double rate_d_lpf_hz = 50.0;  ///< Hz, low-pass cutoff of the D term's derivative, > 0

  /// The gains and limits tuned for an airframe (generic: the defaults above).
  static ControllerConfig preset(Airframe a);

  template <class Self, class V>
  static void fields(Self& c, V& v) {
    v.field("max_speed_mps", c.max_speed_mps,
            {"m/s", positive(), "horizontal speed command limit"});
    v.field("max_vertical_speed_mps", c.max_vertical_speed_mps,
            {"m/s", positive(), "vertical speed command limit"});
    v.field("max_yaw_rate_rad_s", c.max_yaw_rate_rad_s,
            {"rad/s", positive(), "yaw-rate command limit"});
    v.field("max_yaw_accel_rad_s2", c.max_yaw_accel_rad_s2,
            {"rad/s^2", positive(), "slew rate of the yaw-rate command"});
    v.field("max_tilt_rad", c.max_tilt_rad, {"rad", up_to(1.2), "tilt of the thrust vector"});
    v.field("max_accel_mps2", c.max_accel_mps2,
            {"m/s^2", positive(),
             "horizontal and vertical acceleration limit; downward also limited to 0.8 g"});
    v.field("vel_p_xy", c.vel_p_xy, {"1/s", positive(), "horizontal velocity P gain"});
    v.field("vel_p_z", c.vel_p_z, {"1/s", positive(), "vertical velocity P gain"});
    v.field("vel_i_xy", c.vel_i_xy, {"1/s^2", non_negative(), "horizontal velocity I gain"});
    v.field("vel_i_z", c.vel_i_z, {"1/s^2", non_negative(), "vertical velocity I gain"});
    v.field("vel_i_max_mps2", c.vel_i_max_mps2,
            {"m/s^2", non_negative(), "integrator clamp per axis group"});
    v.field("vel_i_band_mps", c.vel_i_band_mps,
            {"m/s", positive(), "the integrators see the velocity error clamped to this"});
    v.field("drag_feedforward", c.drag_feedforward,
            {"", any(), "cancel the modelled body drag at the measured velocity"});
    v.field("att_p_rp", c.att_p_rp, {"1/s", positive(), "roll/pitch attitude P gain"});
    v.field("att_p_yaw", c.att_p_yaw,
            {"1/s", positive(), "yaw attitude gain, applied as weight att_p_yaw/att_p_rp"});
    v.field("max_body_rate_rad_s", c.max_body_rate_rad_s,
            {"rad/s", positive(), "body-rate setpoint limit, every axis"});
    v.field("rate_p_rp", c.rate_p_rp, {"1/s", positive(), "roll/pitch rate P gain"});
    v.field("rate_p_yaw", c.rate_p_yaw, {"1/s", positive(), "yaw rate P gain"});
    v.field("rate_d_rp", c.rate_d_rp,
            {"-", non_negative(), "roll/pitch rate D gain on measured angular acceleration"});
    v.field("rate_d_lpf_hz", c.rate_d_lpf_hz,
            {"Hz", positive(), "low-pass cutoff of the D term's derivative"});
  }

  void validate() const;  ///< throws FieldError("controller.…")
};

/// Reads section `controller` over c (defaults or an airframe's preset).
void load(YamlSection s, ControllerConfig& c);

/// What the drone is told to do (world frame ENU).
struct VelocitySetpoint {
  Eigen::Vector3d v_world{0, 0, 0};  ///< m/s; clamped to max_speed / max_vertical_speed
  double yaw_rate_rad_s = 0.0;       ///< rad/s, +CCW seen from above; clamped to max_yaw_rate
  bool motors_on = false;            ///< false: rotors stop, integrators reset
};

/// Internals of the last update, for tests and telemetry.
struct ControllerStatus {
  Eigen::Vector3d v_sp_world{0, 0, 0};      ///< m/s, clamped velocity setpoint
  Eigen::Vector3d accel_sp_world{0, 0, 0};  ///< m/s^2, after limits, without gravity
  Eigen::Quaterniond q_sp_world_body = Eigen::Quaterniond::Identity();  ///< attitude setpoint
  Eigen::Vector3d rate_sp_body{0, 0, 0};                                ///< rad/s
  double yaw_sp_rad = 0.0;  ///< rad, integrated yaw setpoint
  MixerResult mix;          ///< allocation of the last demand
};

class FlightController {
 public:
  /// Both configs are expected to be validated.
  FlightController(const QuadrotorParams& params, const ControllerConfig& config);

  /// One control step. dt: s since the previous call, > 0 (the physics step).
  /// Returns the commanded rotor speeds (rad/s), zeros when motors are off.
  std::array<double, 4> update(const RigidState& s, const VelocitySetpoint& sp, double dt);

  /// Clears integrators and filters; the yaw setpoint becomes yaw_rad.
  void reset(double yaw_rad);

  const ControllerStatus& status() const { return status_; }
  const Mixer& mixer() const { return mixer_; }

 private:
  QuadrotorParams params_;
  ControllerConfig cfg_;
  Mixer mixer_;
  Eigen::Vector3d inertia_;
  double tan_max_tilt_;                                         ///< tan(cfg_.max_tilt_rad)
  double trig_yaw_ = std::numeric_limits<double>::quiet_NaN();  ///< the yaw_sp_ of the two below
  double cos_yaw_sp_ = 1.0, sin_yaw_sp_ = 0.0;
  double yaw_sp_ = 0.0;
  double yaw_rate_sp_ = 0.0;  ///< rad/s, slewed yaw rate command
  Eigen::Vector3d vel_int_{0, 0, 0};
  Eigen::Vector3d w_prev_{0, 0, 0};
  Eigen::Vector3d w_dot_filt_{0, 0, 0};
  bool have_prev_ = false;
  ControllerStatus status_;
};

}  // namespace ddswarm::sim
