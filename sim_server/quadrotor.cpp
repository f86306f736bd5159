#include "sim_server/quadrotor.hpp"

#include <cmath>
#include <map>
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

const Choices<Airframe>& airframe_names() {
  static const Choices<Airframe> names = {{"generic", Airframe::kGeneric},
                                          {"crazyflie", Airframe::kCrazyflie}};
  return names;
}

std::string airframe_name(Airframe a) {
  for (const auto& [name, value] : airframe_names())
    if (value == a) return name;
  return "?";
}

QuadrotorParams QuadrotorParams::preset(Airframe a) {
  QuadrotorParams q;
  if (a == Airframe::kGeneric) return q;
  // Bitcraze Crazyflie 2.x. Mass, thrust and torque coefficients and the
  // rotor-drag coefficients are J. Förster, "System Identification of the
  // Crazyflie 2.0 Nano Quadrocopter", BSc thesis, ETH Zürich IDSC 2015 (the
  // values gym-pybullet-drones' cf2x.urdf and BaseAviary use, rounded there
  // to kf 3.16e-10, km 7.94e-12; DRAG_COEFF_XY/Z 9.1785e-7/10.311e-7 kg/rad);
  // the inertia is the diagonal of Förster's identified tensor
  // ([16.57, 16.66, 29.26] 1e-6 kg m^2, as CrazyS's crazyflie2.xacro and
  // the Crazyflie firmware's physical_constants quote it). Arm: half the
  // 92 mm motor-to-motor diagonal (Bitcraze; CrazyS arm_length 0.046).
  // Propeller radius 23.13 mm (gym-pybullet-drones PROP_RADIUS). Full speed
  // gives a thrust-to-weight ratio of 2.25 (cf2x.urdf thrust2weight).
  // Motor time constants 12.5 ms up, 25 ms down: CrazyS (G. Silano et al.,
  // "CrazyS: a software-in-the-loop platform for the Crazyflie 2.0
  // nano-quadcopter", ECC 2018), crazyflie2.xacro time_constant_up/down.
  q.airframe = a;
  q.mass_kg = 0.027;
  q.arm_length_m = 0.046;
  q.body_box_m = {0.092, 0.092, 0.03};  // inertia is given: not used for it
  q.motor_mass_kg = 0.0;
  q.rotor_z_m = 0.0;
  q.inertia_kgm2 = {1.6572e-5, 1.6656e-5, 2.9262e-5};
  q.prop_diameter_m = 0.0462696;
  q.k_f_n_per_rpm2 = 3.1582e-10;
  q.k_m_nm_per_rpm2 = 7.9379e-12;
  q.max_rpm = 21716.0;  // sqrt(2.25 m g / (4 k_F))
  q.omega_min_rad_s = 0.0;
  q.motor_tau_s = 0.0125;
  q.motor_tau_down_s = 0.025;
  // Body drag by AirSim's face-area formula (0.325/2 rho A per axis), with
  // A = 92 mm x 30 mm from the side and four propeller discs plus the body
  // from above; the rotors' own drag (below) is what Förster measured.
  q.drag_quadratic_body = {5.5e-4, 5.5e-4, 1.9e-3};
  q.drag_linear_n_per_mps = 0.0;
  // The generic quad's rate damping per unit inertia (5e-4 / 6.7e-3 1/s).
  q.angular_drag_nm_per_rad_s = 1.2e-6;
  q.rotor_drag_body = {9.1785e-7, 9.1785e-7, 10.311e-7};
  // Arm plus propeller radius (69 mm); the frame is 29 mm tall with its battery.
  q.collision_radius_m = 0.07;
  q.collision_half_height_m = 0.015;
  return q;
}

void load(YamlSection s, QuadrotorParams& c) {
  // The preset first: every other key overrides it.
  Airframe a = c.airframe;
  s.get_enum("airframe", a,
             std::map<std::string, Airframe>(airframe_names().begin(), airframe_names().end()));
  if (a != c.airframe) c = QuadrotorParams::preset(a);
  FieldLoader load(s);
  QuadrotorParams::fields(c, load);
  s.finish();
}

void QuadrotorParams::validate() const {
  FieldChecker check("quadrotor");
  QuadrotorParams::fields(*this, check);
  check_vector_positive("quadrotor.body_box_m", body_box_m);
  if (!(4 * motor_mass_kg < mass_kg))
    throw FieldError("quadrotor.motor_mass_kg", to_text(motor_mass_kg),
                     "four motors must weigh less than mass_kg");
  check_vector_non_negative("quadrotor.inertia_kgm2", inertia_kgm2);
  if (!inertia_kgm2.isZero(0.0)) check_vector_positive("quadrotor.inertia_kgm2", inertia_kgm2);
  if (!(omega_min_rad_s < omega_max_rad_s()))
    throw FieldError(
        "quadrotor.omega_min_rad_s", to_text(omega_min_rad_s),
        "must be below omega_max (" + to_text(omega_max_rad_s()) + " rad/s from max_rpm)");
  check_vector_non_negative("quadrotor.drag_quadratic_body", drag_quadratic_body);
  check_vector_non_negative("quadrotor.rotor_drag_body", rotor_drag_body);
  // Hovering must leave headroom for attitude control.
  if (!(4 * max_rotor_thrust_n() > 1.1 * mass_kg * kGravityMps2))
    throw FieldError("quadrotor.mass_kg", to_text(mass_kg),
                     "needs more than 91 % of the rotors' total thrust (" +
                         to_text(4 * max_rotor_thrust_n()) + " N) to hover");
}

double QuadrotorParams::omega_max_rad_s() const { return max_rpm / 60.0 * kTwoPi; }

double QuadrotorParams::k_f() const {
  // rpm = omega * 60 / 2pi.
  if (k_f_n_per_rpm2 > 0) return k_f_n_per_rpm2 * (60.0 / kTwoPi) * (60.0 / kTwoPi);
  // thrust = C_T rho n^2 D^4 with n = omega / 2pi.
  return thrust_coeff * air_density_kgm3 * std::pow(prop_diameter_m, 4) / (kTwoPi * kTwoPi);
}

double QuadrotorParams::k_m() const {
  if (k_m_nm_per_rpm2 > 0) return k_m_nm_per_rpm2 * (60.0 / kTwoPi) * (60.0 / kTwoPi);
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
  FieldLoader load(s);
  SensorConfig::fields(c, load);
  s.finish();
}

void SensorConfig::validate() const {
  FieldChecker check("sensors");
  SensorConfig::fields(*this, check);
  if (!(max_range_m > min_range_m))
    throw FieldError("sensors.max_range_m", to_text(max_range_m),
                     "must exceed min_range_m (" + to_text(min_range_m) + ")");
  if (rows * count > kMaxRays)
    throw FieldError("sensors.rows", to_text(rows),
                     "rows x count = " + std::to_string(rows * count) + " rays: must be <= " +
                         std::to_string(kMaxRays) + " (count " + std::to_string(count) + ")");
  if (rows > 1 && !(vertical_fov_deg > 0))
    throw FieldError("sensors.rows", to_text(rows),
                     "needs vertical_fov_deg > 0 (with 0 every row looks the same way)");
}

double SensorConfig::ray_yaw_rad(int k) const {
  return yaw_offset_rad + 2 * std::numbers::pi * (k % count) / count;
}

double SensorConfig::ray_elevation_rad(int k) const {
  if (rows <= 1) return 0.0;
  // Symmetric about 0 and exactly 0 for the middle row of an odd count.
  const int r = k / count;
  return vertical_fov_deg * (std::numbers::pi / 180) * (2 * r - (rows - 1)) / (2.0 * (rows - 1));
}

Eigen::Vector3d SensorConfig::ray_direction_body(int k) const {
  const double a = ray_yaw_rad(k), e = ray_elevation_rad(k);
  const double ce = std::cos(e);
  return {ce * std::cos(a), ce * std::sin(a), std::sin(e)};
}

}  // namespace ddswarm::sim
