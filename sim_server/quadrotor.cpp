#include "sim_server/quadrotor.hpp"

#include <cmath>
#include <numbers>

namespace ddswarm::sim {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

void check_vector_positive(const std::string& field, const Eigen::Vector3d& v) {
  for (int k = 0; k < 3; ++k)
    if (!(v[k] > 0) || !std::isfinite(v[k]))
      throw FieldError(field, to_text(v.transpose()), "every component must be > 0");
}

void check_vector_non_negative(const std::string& field, const Eigen::Vector3d& v) {
  for (int k = 0; k < 3; ++k)
    if (!(v[k] >= 0) || !std::isfinite(v[k]))
      throw FieldError(field, to_text(v.transpose()), "every component must be >= 0");
}

}  // namespace

double yaw_of(const Eigen::Quaterniond& q_world_body) {
  const Eigen::Vector3d x = q_world_body * Eigen::Vector3d::UnitX();
  return std::atan2(x.y(), x.x());
}

void load(YamlSection s, QuadrotorParams& c) {
  s.get("mass_kg", c.mass_kg);
  s.get("arm_length_m", c.arm_length_m);
  s.get("body_box_m", c.body_box_m);
  s.get("motor_mass_kg", c.motor_mass_kg);
  s.get("rotor_z_m", c.rotor_z_m);
  s.get("inertia_kgm2", c.inertia_kgm2);
  s.get("thrust_coeff", c.thrust_coeff);
  s.get("power_coeff", c.power_coeff);
  s.get("prop_diameter_m", c.prop_diameter_m);
  s.get("air_density_kgm3", c.air_density_kgm3);
  s.get("max_rpm", c.max_rpm);
  s.get("omega_min_rad_s", c.omega_min_rad_s);
  s.get("motor_tau_s", c.motor_tau_s);
  s.get("drag_quadratic_body", c.drag_quadratic_body);
  s.get("drag_linear_n_per_mps", c.drag_linear_n_per_mps);
  s.get("angular_drag_nm_per_rad_s", c.angular_drag_nm_per_rad_s);
  s.get("collision_radius_m", c.collision_radius_m);
  s.get("collision_half_height_m", c.collision_half_height_m);
  s.finish();
}

void QuadrotorParams::validate() const {
  check_positive("quadrotor.mass_kg", mass_kg);
  check_positive("quadrotor.arm_length_m", arm_length_m);
  check_vector_positive("quadrotor.body_box_m", body_box_m);
  check_non_negative("quadrotor.motor_mass_kg", motor_mass_kg);
  if (!(4 * motor_mass_kg < mass_kg))
    throw FieldError("quadrotor.motor_mass_kg", to_text(motor_mass_kg),
                     "four motors must weigh less than mass_kg");
  check_non_negative("quadrotor.rotor_z_m", rotor_z_m);
  check_vector_non_negative("quadrotor.inertia_kgm2", inertia_kgm2);
  if (!inertia_kgm2.isZero(0.0)) check_vector_positive("quadrotor.inertia_kgm2", inertia_kgm2);
  check_positive("quadrotor.thrust_coeff", thrust_coeff);
  check_positive("quadrotor.power_coeff", power_coeff);
  check_positive("quadrotor.prop_diameter_m", prop_diameter_m);
  check_positive("quadrotor.air_density_kgm3", air_density_kgm3);
  check_positive("quadrotor.max_rpm", max_rpm);
  check_non_negative("quadrotor.omega_min_rad_s", omega_min_rad_s);
  if (!(omega_min_rad_s < omega_max_rad_s()))
    throw FieldError(
        "quadrotor.omega_min_rad_s", to_text(omega_min_rad_s),
        "must be below omega_max (" + to_text(omega_max_rad_s()) + " rad/s from max_rpm)");
  check_non_negative("quadrotor.motor_tau_s", motor_tau_s);
  check_vector_non_negative("quadrotor.drag_quadratic_body", drag_quadratic_body);
  check_non_negative("quadrotor.drag_linear_n_per_mps", drag_linear_n_per_mps);
  check_non_negative("quadrotor.angular_drag_nm_per_rad_s", angular_drag_nm_per_rad_s);
  check_positive("quadrotor.collision_radius_m", collision_radius_m);
  check_positive("quadrotor.collision_half_height_m", collision_half_height_m);
  // Hovering must leave headroom for attitude control.
  if (!(4 * max_rotor_thrust_n() > 1.1 * mass_kg * kGravityMps2))
    throw FieldError("quadrotor.mass_kg", to_text(mass_kg),
                     "needs more than 91 % of the rotors' total thrust (" +
                         to_text(4 * max_rotor_thrust_n()) + " N) to hover");
}

double QuadrotorParams::omega_max_rad_s() const { return max_rpm / 60.0 * kTwoPi; }

double QuadrotorParams::k_f() const {
  // thrust = C_T rho n^2 D^4 with n = omega / 2pi.
  return thrust_coeff * air_density_kgm3 * std::pow(prop_diameter_m, 4) / (kTwoPi * kTwoPi);
}

double QuadrotorParams::k_m() const {
  // torque = C_P rho n^2 D^5 / 2pi with n = omega / 2pi.
  return power_coeff * air_density_kgm3 * std::pow(prop_diameter_m, 5) / (kTwoPi * kTwoPi * kTwoPi);
}

double QuadrotorParams::max_rotor_thrust_n() const {
  double w = omega_max_rad_s();
  return k_f() * w * w;
}

double QuadrotorParams::hover_omega() const {
  return std::sqrt(mass_kg * kGravityMps2 / (4.0 * k_f()));
}

Eigen::Vector3d QuadrotorParams::inertia() const {
  if (!inertia_kgm2.isZero(0.0)) return inertia_kgm2;
  // AirSim MultiRotorParams::computeInertiaMatrix: a solid box plus point masses.
  const double box_mass = mass_kg - 4 * motor_mass_kg;
  const Eigen::Vector3d& b = body_box_m;
  Eigen::Vector3d j(box_mass / 12.0 * (b.y() * b.y() + b.z() * b.z()),
                    box_mass / 12.0 * (b.x() * b.x() + b.z() * b.z()),
                    box_mass / 12.0 * (b.x() * b.x() + b.y() * b.y()));
  for (int i = 0; i < 4; ++i) {
    Eigen::Vector3d r = rotor_position_body(i);
    r.z() = rotor_z_m;
    j.x() += motor_mass_kg * (r.y() * r.y() + r.z() * r.z());
    j.y() += motor_mass_kg * (r.x() * r.x() + r.z() * r.z());
    j.z() += motor_mass_kg * (r.x() * r.x() + r.y() * r.y());
  }
  return j;
}

Eigen::Vector3d QuadrotorParams::rotor_position_body(int i) const {
  // Arms at -45 (0, front-right), 135 (1, rear-left), 45 (2, front-left), -135 deg (3).
  static constexpr double kAngleDeg[4] = {-45.0, 135.0, 45.0, -135.0};
  const double a = kAngleDeg[i] * std::numbers::pi / 180.0;
  return {arm_length_m * std::cos(a), arm_length_m * std::sin(a), 0.0};
}

Wrench QuadrotorParams::rotor_wrench(const std::array<double, 4>& omega_rad_s) const {
  Wrench w;
  const double kf = k_f(), km = k_m();
  for (int i = 0; i < 4; ++i) {
    const double w2 = omega_rad_s[i] * omega_rad_s[i];
    const double t = kf * w2;
    const Eigen::Vector3d r = rotor_position_body(i);
    w.thrust_n += t;
    w.torque_body_nm += Eigen::Vector3d(r.y() * t, -r.x() * t, -rotor_spin(i) * km * w2);
  }
  return w;
}

void load(YamlSection s, SensorConfig& c) {
  s.get("count", c.count);
  s.get("max_range_m", c.max_range_m);
  s.get("min_range_m", c.min_range_m);
  s.get("noise_sigma_m", c.noise_sigma_m);
  s.get("yaw_offset_rad", c.yaw_offset_rad);
  s.finish();
}

void SensorConfig::validate() const {
  check_range("sensors.count", count, 1, 64);
  check_positive("sensors.min_range_m", min_range_m);
  check_positive("sensors.max_range_m", max_range_m);
  if (!(max_range_m > min_range_m))
    throw FieldError("sensors.max_range_m", to_text(max_range_m),
                     "must exceed min_range_m (" + to_text(min_range_m) + ")");
  check_non_negative("sensors.noise_sigma_m", noise_sigma_m);
  check_range("sensors.yaw_offset_rad", yaw_offset_rad, -kTwoPi, kTwoPi);
}

}  // namespace ddswarm::sim
