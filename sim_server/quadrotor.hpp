#pragma once
// The simulated vehicle: a quadrotor in X configuration and its distance
// sensors, described by plain config structs.
//
// Body frame FLU (x forward, y left, z up); world frame ENU; SI units.
// Rotor numbering follows PX4's quad-x, seen from above (x up the page,
// y to the left):
//
//      2 (CW)     0 (CCW)      front
//      1 (CCW)    3 (CW)       rear
//
//   rotor 0 front-right CCW, 1 rear-left CCW, 2 front-left CW, 3 rear-right CW.
// A CCW rotor (spin vector +z) pushes the body with reaction torque -k_m w^2
// about body z; a CW rotor with +k_m w^2.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <string>

#include "common/config_fields.hpp"
#include "common/yaml_section.hpp"

namespace ddswarm::sim {

/// Standard gravity (m/s^2), used by the physics world and the controller.
inline constexpr double kGravityMps2 = 9.80665;

/// Rigid-body state of one drone.
struct RigidState {
  Eigen::Vector3d p_world{0, 0, 0};  ///< m, body centre (centre of mass), ENU
  Eigen::Vector3d v_world{0, 0, 0};  ///< m/s, ENU
  Eigen::Quaterniond q_world_body = Eigen::Quaterniond::Identity();  ///< body FLU -> world ENU
  Eigen::Vector3d w_body{0, 0, 0};  ///< rad/s, angular velocity in body axes
};

/// rad, heading of the body x axis (yaw about world z), in (-pi, pi].
double yaw_of(const Eigen::Quaterniond& q_world_body);

/// Collective thrust along body +z and torque about the body axes.
struct Wrench {
  double thrust_n = 0.0;                    ///< N, along body +z
  Eigen::Vector3d torque_body_nm{0, 0, 0};  ///< N m, body FLU axes
};

/// The airframes a drone can fly: each names a full set of QuadrotorParams
/// (QuadrotorParams::preset) and its flight-controller gains
/// (ControllerConfig::preset). docs/airframes.md gives their sources.
enum class Airframe : std::uint8_t {
  kGeneric,    ///< AirSim's generic quadrotor (1 kg), the thesis's vehicle
  kCrazyflie,  ///< Bitcraze Crazyflie 2.x (27 g, 92 mm motor to motor)
};

/// The airframes' names in YAML, in the order the reference lists them.
const Choices<Airframe>& airframe_names();
/// "generic", "crazyflie".
std::string airframe_name(Airframe a);

/// Physical description of the quadrotor.
///
/// Defaults are AirSim's "generic quadrotor" (AirSim MultiRotorParams::
/// setupFrameGenericQuad and RotorParams), the simulator the thesis used:
/// 1 kg, 0.2275 m arms, a 0.18 x 0.11 x 0.04 m body box plus four 0.055 kg
/// motor assemblies for the inertia, propellers with C_T = 0.109919,
/// C_P = 0.040164, D = 0.2286 m at 6396.667 RPM in air of 1.225 kg/m^3, a
/// 5 ms motor filter, and AirSim's face-area drag model reduced to one
/// quadratic coefficient per body axis. Its rotor-drag coefficient is PX4's
/// Gazebo Iris (rotorDragCoefficient 8.06428e-5 in the multicopter motor
/// model plugin), the one published value for a quadrotor of that size.
struct QuadrotorParams {
  Airframe airframe = Airframe::kGeneric;  ///< the preset these values start from

  double mass_kg = 1.0;                          ///< kg, total mass, > 0
  double arm_length_m = 0.2275;                  ///< m, centre to rotor axis, > 0
  Eigen::Vector3d body_box_m{0.18, 0.11, 0.04};  ///< m, central box x, y, z, each > 0
  double motor_mass_kg = 0.055;  ///< kg per motor assembly (point mass at the arm tip), >= 0
  double rotor_z_m = 0.025;      ///< m, rotor plane above the centre (inertia only), >= 0
  /// kg m^2, [Ixx, Iyy, Izz] override; all zero (default) computes the inertia
  /// from body_box_m and the motor point masses (AirSim's formula).
  Eigen::Vector3d inertia_kgm2{0, 0, 0};

  double thrust_coeff = 0.109919;   ///< C_T, thrust = C_T rho n^2 D^4 (n in rev/s), > 0
  double power_coeff = 0.040164;    ///< C_P, torque = C_P rho n^2 D^5 / (2 pi), > 0
  double prop_diameter_m = 0.2286;  ///< m, > 0
  double air_density_kgm3 = 1.225;  ///< kg/m^3, > 0
  /// N/rpm^2, thrust = k_F rpm^2 as identified on a thrust stand; > 0
  /// replaces thrust_coeff (0: from C_T, rho and D).
  double k_f_n_per_rpm2 = 0.0;
  /// N m/rpm^2, reaction torque = k_M rpm^2; > 0 replaces power_coeff.
  double k_m_nm_per_rpm2 = 0.0;
  double max_rpm = 6396.667;     ///< rev/min at full command (omega_max ~ 669.9 rad/s), > 0
  double omega_min_rad_s = 0.0;  ///< rad/s, lowest rotor speed, in [0, omega_max)
  double motor_tau_s = 0.005;    ///< s, first-order rotor speed lag, >= 0 (0 = instant)
  /// s, the lag while a rotor slows down, >= 0; 0 = motor_tau_s (one lag both ways).
  double motor_tau_down_s = 0.0;

  /// N/(m/s)^2 per body axis: F = -c v|v| (AirSim: 0.325/2 * rho * exposed
  /// area of the box faces plus propellers, per axis).
  Eigen::Vector3d drag_quadratic_body{0.0066, 0.0072, 0.1347};
  double drag_linear_n_per_mps = 0.0;       ///< N/(m/s), extra linear drag on each axis, >= 0
  double angular_drag_nm_per_rad_s = 5e-4;  ///< N m/(rad/s), body rate damping, >= 0
  /// N/(m/s) per rad/s of rotor speed, per body axis, each >= 0: with
  /// aero.rotor_drag on, the rotors add F = -c v_air sum_i |omega_i| (body
  /// axes). z = 0: PX4's model acts across the rotor axis only.
  Eigen::Vector3d rotor_drag_body{8.06428e-5, 8.06428e-5, 0.0};

  double collision_radius_m = 0.3;        ///< m, collision cylinder radius (covers props), > 0
  double collision_half_height_m = 0.05;  ///< m, collision cylinder half height, > 0

  /// The airframe's published parameters (generic: the defaults above).
  static QuadrotorParams preset(Airframe a);

  template <class Self, class V>
  static void fields(Self& c, V& v) {
    v.choice("airframe", c.airframe, airframe_names(),
             {"", any(), "the preset the other keys override (docs/airframes.md)"});
    v.field("mass_kg", c.mass_kg, {"kg", positive(), "total mass"});
    v.field("arm_length_m", c.arm_length_m, {"m", positive(), "centre to rotor axis"});
    v.field("body_box_m", c.body_box_m, {"m", any(), "central box, for the inertia"});
    v.field("motor_mass_kg", c.motor_mass_kg,
            {"kg", non_negative(), "point mass at each arm tip, for the inertia"});
    v.field("rotor_z_m", c.rotor_z_m,
            {"m", non_negative(), "rotor plane above the centre (inertia only)"});
    v.field(
        "inertia_kgm2", c.inertia_kgm2,
        {"kg m^2", any(), "[Ixx, Iyy, Izz] override; all zero computes it from box and motors"});
    v.field("thrust_coeff", c.thrust_coeff,
            {"-", positive(), "C_T: thrust = C_T rho n^2 D^4 (n in rev/s)"});
    v.field("power_coeff", c.power_coeff,
            {"-", positive(), "C_P: torque = C_P rho n^2 D^5 / (2 pi)"});
    v.field("prop_diameter_m", c.prop_diameter_m, {"m", positive(), "D"});
    v.field("air_density_kgm3", c.air_density_kgm3, {"kg/m^3", positive(), "rho"});
    v.field("k_f_n_per_rpm2", c.k_f_n_per_rpm2,
            {"N/rpm^2", non_negative(), "k_F: thrust = k_F rpm^2; > 0 replaces thrust_coeff"});
    v.field("k_m_nm_per_rpm2", c.k_m_nm_per_rpm2,
            {"N m/rpm^2", non_negative(), "k_M: torque = k_M rpm^2; > 0 replaces power_coeff"});
    v.field("max_rpm", c.max_rpm, {"rev/min", positive(), "rotor speed at full command"});
    v.field("omega_min_rad_s", c.omega_min_rad_s, {"rad/s", non_negative(), "lowest rotor speed"});
    v.field("motor_tau_s", c.motor_tau_s,
            {"s", non_negative(), "first-order rotor speed lag (0 = instant)"});
    v.field("motor_tau_down_s", c.motor_tau_down_s,
            {"s", non_negative(), "the lag while a rotor slows; 0 = motor_tau_s"});
    v.field("drag_quadratic_body", c.drag_quadratic_body,
            {"N/(m/s)^2", any(), "F = -c v|v| per body axis"});
    v.field("drag_linear_n_per_mps", c.drag_linear_n_per_mps,
            {"N/(m/s)", non_negative(), "extra linear drag on each axis"});
    v.field("angular_drag_nm_per_rad_s", c.angular_drag_nm_per_rad_s,
            {"N m/(rad/s)", non_negative(), "body-rate damping"});
    v.field("rotor_drag_body", c.rotor_drag_body,
            {"N/(m/s)/(rad/s)", any(), "rotor drag with aero.rotor_drag"});
    v.field("collision_radius_m", c.collision_radius_m,
            {"m", positive(), "collision cylinder radius (covers the propellers)"});
    v.field("collision_half_height_m", c.collision_half_height_m,
            {"m", positive(), "collision cylinder half height"});
  }

  void validate() const;  ///< throws FieldError("quadrotor.…")

  /// rad/s, rotor speed at full command.
  double omega_max_rad_s() const;
  /// N/(rad/s)^2: thrust = k_f omega^2.
  double k_f() const;
  /// N m/(rad/s)^2: reaction torque = k_m omega^2.
  double k_m() const;
  /// N, thrust of one rotor at omega_max.
  double max_rotor_thrust_n() const;
  /// rad/s, rotor speed at which the four rotors carry the weight.
  double hover_omega() const;
  /// kg m^2, diagonal inertia [Ixx, Iyy, Izz] (override or computed).
  Eigen::Vector3d inertia() const;
  /// m, rotor i's hub in the body frame (z = 0: the thrust line passes the
  /// centre plane; rotor_z_m only enters the inertia).
  Eigen::Vector3d rotor_position_body(int i) const;
  /// +1 for a CCW rotor (0, 1), -1 for a CW rotor (2, 3).
  static int rotor_spin(int i) { return i < 2 ? 1 : -1; }
  /// Forward rotor model: the wrench produced by rotor speeds (rad/s).
  Wrench rotor_wrench(const std::array<double, 4>& omega_rad_s) const;
};

/// Reads section `quadrotor`: `airframe` first (the preset, default generic),
/// then every other key overrides it. Unknown keys throw ConfigError.
void load(YamlSection s, QuadrotorParams& c);

/// The distance sensors on every drone: by default the thesis's ring of 8
/// rangefinders in the body x-y plane; with rows > 1, a lidar-like pattern of
/// rows x count rays spread in elevation over vertical_fov_deg.
///
/// Ray k is row k / count, column k % count: body yaw yaw_offset_rad + 2 pi
/// column / count, elevation (up from the body x-y plane) -fov/2 + fov row /
/// (rows - 1), 0 with one row.
struct SensorConfig {
  /// At most this many rays per scan (DistanceScan's sequences): every
  /// SwarmState carries every drone's scan, 9 bytes a ray.
  static constexpr int kMaxRays = 256;

  int count = 8;                ///< rays per row, evenly spaced in yaw, in [1, 256]
  int rows = 1;                 ///< rows of rays, in [1, 32]; rows x count <= kMaxRays
  double vertical_fov_deg = 0;  ///< deg, elevation from the lowest row to the highest, in [0, 180]
  double max_range_m = 4.0;     ///< m, > min_range_m
  double min_range_m = 0.05;    ///< m, > 0; measured ranges are clamped to it
  double noise_sigma_m = 0.02;  ///< m, Gaussian range noise standard deviation, >= 0
  double yaw_offset_rad = 0.0;  ///< rad, body yaw of column 0, in [-2pi, 2pi]

  template <class Self, class V>
  static void fields(Self& c, V& v) {
    v.field("count", c.count, {"", in(1, kMaxRays), "rays per row, evenly spaced in body yaw"});
    v.field("rows", c.rows,
            {"", in(1, 32), "rows of rays, evenly spread in elevation over vertical_fov_deg"});
    v.field("vertical_fov_deg", c.vertical_fov_deg,
            {"deg", in(0, 180), "elevation from the lowest row to the highest"});
    v.field("max_range_m", c.max_range_m, {"m", positive(), "sensor range"});
    v.field("min_range_m", c.min_range_m, {"m", positive(), "readings are clamped up to this"});
    v.field("noise_sigma_m", c.noise_sigma_m,
            {"m", non_negative(), "Gaussian range noise, standard deviation"});
    v.field("yaw_offset_rad", c.yaw_offset_rad,
            {"rad", in(-2 * 3.14159265358979323846, 2 * 3.14159265358979323846),
             "body yaw of column 0"});
  }

  /// Rays per scan: rows x count.
  int rays() const { return rows * count; }
  /// rad, body yaw of ray k (its column's).
  double ray_yaw_rad(int k) const;
  /// rad, elevation of ray k (its row's) up from the body x-y plane; 0 with one row.
  double ray_elevation_rad(int k) const;
  /// Unit direction of ray k in the body frame (FLU).
  Eigen::Vector3d ray_direction_body(int k) const;

  void validate() const;  ///< throws FieldError("sensors.…")
};

void load(YamlSection s, SensorConfig& c);

}  // namespace ddswarm::sim
