#pragma once
// Aerodynamics between and under drones, each switchable (YAML `aero`):
//
// Ground effect (Cheeseman and Bennett 1955, "The effect of the ground on a
// helicopter rotor in forward flight", ARC R&M 3021): a rotor of radius R
// with its hub z above the ground gives
//   T_IGE / T_OGE = 1 / (1 - (R / (4 z))^2)
// times its thrust out of ground effect. It is applied below two rotor
// diameters (z < 4 R, where it is under 0.4 %), with z held at R / 2 or more
// (ratio at most 4/3): the formula grows without bound as z -> R / 4, which
// no rotor shows.
//
// Downwash (the model gym-pybullet-drones documents, Panerati et al. 2021,
// "Learning to Fly", fitted to Crazyflie 2.x data): a drone dz below another
// and dxy beside it is pushed down by
//   F = alpha exp(-(dxy / beta)^2 / 2),  alpha = C1 (R / (4 dz))^2,  beta = C2 dz + C3,
// C1 = 2267.18 N, C2 = 0.16, C3 = -0.11 m, R the upper drone's rotor radius.
// Its beta passes through 0 at dz = 0.6875 m (C3 < 0); ddswarm uses |beta|
// held at 0.02 m or more there, so the force stays finite and keeps the
// model's shape either side. Drones more than 10 m apart sideways, or level
// or below, are not affected (as there).
//
// Rotor drag: a rotor moving edgewise through the air tilts its disc
// (blade flapping) and its advancing blade meets more drag than the
// retreating one; together they push the vehicle against its airspeed with
// a force linear in the airspeed (M. Faessler, A. Franchi, D. Scaramuzza,
// "Differential flatness of quadrotor dynamics subject to rotor drag for
// accurate tracking of high-speed trajectories", IEEE RA-L 3(2), 2018,
// doi:10.1109/LRA.2017.2776353: F = -R D R^T v, D diagonal and constant).
// ddswarm scales D with the rotor speeds, as PX4's Gazebo multicopter motor
// model (per rotor -|omega_i| c v across its axis) and Förster's Crazyflie
// identification (K_aero sum_i omega_i v) both do:
//   F_body = -c (.) v_air_body * sum_i |omega_i|,
// c the airframe's quadrotor.rotor_drag_body per body axis; at hover that is
// Faessler's D = c sum_i omega_i. It acts on the airspeed (the velocity
// relative to the wind), at the centre of mass.
//
// Pure: no state.
#include <Eigen/Core>
#include <array>

#include "common/config_fields.hpp"
#include "common/yaml_section.hpp"

namespace ddswarm::sim {

struct AeroConfig {
  bool ground_effect = false;
  bool downwash = false;
  bool rotor_drag = false;
  double downwash_c1_n = 2267.18;
  double downwash_c2 = 0.16;
  double downwash_c3_m = -0.11;

  template <class Self, class V>
  static void fields(Self& c, V& v) {
    v.field("ground_effect", c.ground_effect,
            {"", any(), "Cheeseman-Bennett thrust ratio below two rotor diameters"});
    v.field("downwash", c.downwash,
            {"", any(), "a drone's downwash on those beneath it (gym-pybullet-drones' model)"});
    v.field("rotor_drag", c.rotor_drag,
            {"", any(), "rotor drag on the airspeed, linear in it and in the rotor speeds"});
    v.field("downwash_c1_n", c.downwash_c1_n, {"N", non_negative(), "the model's C1"});
    v.field("downwash_c2", c.downwash_c2, {"", any(), "the model's C2"});
    v.field("downwash_c3_m", c.downwash_c3_m, {"m", any(), "the model's C3"});
  }
  bool enabled() const { return ground_effect || downwash || rotor_drag; }
};

/// T_IGE / T_OGE for a rotor of radius r_m with its hub z_m above the ground.
double ground_effect_ratio(double z_m, double r_m);

/// m: a drone this far or farther sideways from another feels none of its downwash.
inline constexpr double kDownwashReachM = 10.0;

/// The downward force (N, >= 0) on a drone at `below` from one at `above`
/// whose rotors have radius r_m.
double downwash_force(const AeroConfig& c, const Eigen::Vector3d& above,
                      const Eigen::Vector3d& below, double r_m);

/// N, body axes: the rotors' drag -c (.) v_air_body * sum_i |omega_i|.
/// c: N/(m/s) per rad/s, per body axis; v_air_body: airspeed in body axes.
Eigen::Vector3d rotor_drag_force(const Eigen::Vector3d& c, const Eigen::Vector3d& v_air_body,
                                 const std::array<double, 4>& omega_rad_s);

/// Reads section `aero`; unknown keys throw ConfigError with file and line.
void load(YamlSection s, AeroConfig& c);

}  // namespace ddswarm::sim
