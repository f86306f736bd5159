#pragma once
// Control allocation for the quad-x: wrench demand -> rotor speeds.
#include <Eigen/Core>
#include <array>

#include "sim_server/quadrotor.hpp"

namespace ddswarm::sim {

/// What the mixer decided for one demand.
struct MixerResult {
  std::array<double, 4> omega_rad_s{};  ///< rad/s, commanded rotor speeds
  std::array<double, 4> thrust_n{};     ///< N, per-rotor thrust those speeds produce
  Wrench demanded;                      ///< the input
  Wrench produced;                      ///< what the rotors produce at omega_rad_s (steady state)
  double roll_pitch_scale = 1.0;        ///< [0, 1], share of the roll/pitch torque kept
  double yaw_scale = 1.0;               ///< [0, 1], share of the yaw torque kept
  bool thrust_limited = false;          ///< collective thrust differs from the demand
};

/// Maps [collective thrust, body torque] to rotor speeds with PX4's
/// airmode-off priorities: roll/pitch first (the collective is lowered when
/// a rotor would exceed its maximum; it is never raised to make room, so at
/// very low thrust roll/pitch is scaled down instead), then the collective,
/// then yaw, which only gets the headroom left. Roll and pitch are scaled
/// together, so the torque keeps its direction.
class Mixer {
 public:
  explicit Mixer(const QuadrotorParams& params);

  MixerResult mix(const Wrench& demand) const;

  /// [T, tau_x, tau_y, tau_z] = allocation() * [T_0 .. T_3] (rotor thrusts, N).
  const Eigen::Matrix4d& allocation() const { return allocation_; }
  /// allocation().inverse().
  const Eigen::Matrix4d& mixing() const { return mixing_; }
  /// N, per-rotor thrust at omega_min and omega_max.
  double rotor_thrust_min_n() const { return t_lo_; }
  double rotor_thrust_max_n() const { return t_hi_; }

 private:
  Eigen::Matrix4d allocation_;
  Eigen::Matrix4d mixing_;
  double k_f_;
  double t_lo_, t_hi_;
  double lo_over_c_[4], hi_over_c_[4];  ///< t_lo_, t_hi_ / mixing_(i, 0)
  double t_floor_;                      ///< max_i lo_over_c_[i]
  double omega_min_, omega_max_;
};

}  // namespace ddswarm::sim
