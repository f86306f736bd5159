#include "sim_server/aero.hpp"

#include <algorithm>
#include <cmath>

namespace ddswarm::sim {

void load(YamlSection s, AeroConfig& c) {
  FieldLoader load(s);
  AeroConfig::fields(c, load);
  s.finish();
}

double ground_effect_ratio(double z_m, double r_m) {
  if (!(z_m < 4 * r_m)) return 1.0;
  const double z = std::max(z_m, 0.5 * r_m);
  const double k = r_m / (4 * z);
  return 1.0 / (1.0 - k * k);
}

double downwash_force(const AeroConfig& c, const Eigen::Vector3d& above,
                      const Eigen::Vector3d& below, double r_m) {
  const double dz = above.z() - below.z();
  const double dxy = (above - below).head<2>().norm();
  if (!(dz > 0) || dxy >= kDownwashReachM) return 0.0;
  const double k = r_m / (4 * dz);
  const double alpha = c.downwash_c1_n * k * k;
  const double beta = std::max(std::abs(c.downwash_c2 * dz + c.downwash_c3_m), 0.02);
  const double q = 0.5 * (dxy / beta) * (dxy / beta);
  // exp(-q) is exactly 0 there: skip its slow underflow path.
  if (q > 746.0) return 0.0;
  return alpha * std::exp(-q);
}

Eigen::Vector3d rotor_drag_force(const Eigen::Vector3d& c, const Eigen::Vector3d& v_air_body,
                                 const std::array<double, 4>& omega_rad_s) {
  const double w = std::abs(omega_rad_s[0]) + std::abs(omega_rad_s[1]) + std::abs(omega_rad_s[2]) +
                   std::abs(omega_rad_s[3]);
  return -w * c.cwiseProduct(v_air_body);
}

}  // namespace ddswarm::sim
