#include "sim_server/mixer.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

namespace ddswarm::sim {

Mixer::Mixer(const QuadrotorParams& p)
    : k_f_(p.k_f()), omega_min_(p.omega_min_rad_s), omega_max_(p.omega_max_rad_s()) {
  const double kappa = p.k_m() / p.k_f();  // yaw torque per newton of rotor thrust
  for (int i = 0; i < 4; ++i) {
    const Eigen::Vector3d r = p.rotor_position_body(i);
    allocation_.col(i) << 1.0, r.y(), -r.x(), -QuadrotorParams::rotor_spin(i) * kappa;
  }
  mixing_ = allocation_.inverse();
  t_lo_ = k_f_ * omega_min_ * omega_min_;
  t_hi_ = k_f_ * omega_max_ * omega_max_;
  // Quotients mix() needs at every call: computed here once, by the same
  // operations on the same operands, so the results do not change by a bit.
  t_floor_ = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < 4; ++i) {
    lo_over_c_[i] = t_lo_ / mixing_(i, 0);
    hi_over_c_[i] = t_hi_ / mixing_(i, 0);
    t_floor_ = std::max(t_floor_, lo_over_c_[i]);
  }
}

MixerResult Mixer::mix(const Wrench& demand) const {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  constexpr double kEps = 1e-9;
  MixerResult out;
  out.demanded = demand;

  // Per-rotor thrust = c_t*T + s*a + k*y; c_t > 0 for a quad-x.
  const Eigen::Vector4d c_t = mixing_.col(0);
  const Eigen::Vector4d a =
      mixing_.col(1) * demand.torque_body_nm.x() + mixing_.col(2) * demand.torque_body_nm.y();
  const Eigen::Vector4d y = mixing_.col(3) * demand.torque_body_nm.z();
  const double lo = t_lo_, hi = t_hi_;

  // Largest roll/pitch share s* for which some collective fits every rotor:
  // for all i, j: (lo - s a_i)/c_i <= (hi - s a_j)/c_j.
  double a_over_c[4];
  for (int i = 0; i < 4; ++i) a_over_c[i] = a[i] / c_t[i];
  double s_max = 1.0;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      const double coef = a_over_c[j] - a_over_c[i];
      if (coef > 0) s_max = std::min(s_max, (hi_over_c_[j] - lo_over_c_[i]) / coef);
    }
  s_max = std::clamp(s_max, 0.0, 1.0);

  double t_top = kInf;  // highest collective that fits at s*
  for (int i = 0; i < 4; ++i) t_top = std::min(t_top, (hi - s_max * a[i]) / c_t[i]);

  double s = s_max;
  double thrust = demand.thrust_n;
  if (thrust >= t_top) {
    thrust = t_top;  // lower the collective to keep roll/pitch
  } else {
    // Airmode off: never raise the collective; shrink roll/pitch until every
    // rotor stays above its minimum.
    thrust = std::max(thrust, t_floor_);
    for (int i = 0; i < 4; ++i) {
      const double base = c_t[i] * thrust;
      if (a[i] > 0) s = std::min(s, (hi - base) / a[i]);
      if (a[i] < 0) s = std::min(s, (lo - base) / a[i]);
    }
    s = std::clamp(s, 0.0, s_max);
  }
  Eigen::Vector4d u = c_t * thrust + s * a;

  // Yaw gets what headroom is left.
  double k = 1.0;
  for (int i = 0; i < 4; ++i) {
    if (y[i] > 0) k = std::min(k, (hi - u[i]) / y[i]);
    if (y[i] < 0) k = std::min(k, (lo - u[i]) / y[i]);
  }
  k = std::clamp(k, 0.0, 1.0);
  u += k * y;

  for (int i = 0; i < 4; ++i) {
    const double t = std::clamp(u[i], lo, hi);
    out.omega_rad_s[i] = std::clamp(std::sqrt(t / k_f_), omega_min_, omega_max_);
    u[i] = t;
    out.thrust_n[i] = t;
  }
  const Eigen::Vector4d w = allocation_ * u;
  out.produced.thrust_n = w[0];
  out.produced.torque_body_nm = w.tail<3>();
  out.roll_pitch_scale = s;
  out.yaw_scale = k;
  out.thrust_limited =
      std::abs(thrust - demand.thrust_n) > kEps * std::max(1.0, std::abs(demand.thrust_n));
  return out;
}

}  // namespace ddswarm::sim
