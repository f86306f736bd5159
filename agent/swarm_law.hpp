#pragma once
// The agent's control laws, pure: positions and ray readings in, velocity out.
// World frame ENU (x east, y north, z up), metres, seconds. Body frame FLU
// (x forward, y left, z up); ray yaw is measured about body +z from body +x.
//
// V = C_s + C + V_mission (thesis Eq. 3.4, plus the mission term), where
//   C   = sum_j f_rel(|d_i - d_j| - D_int) * unit(d_j - d_i)     (Eq. 3.2)
//   C_s = sum_k f_s(S_k) * (-dir_k, horizontal, world)            (Eq. 3.3)
//
// Drone-to-drone activation f_rel(D_r) (m/s; > 0 attracts, < 0 repels):
//   linear (default): f_rel = clamp(attraction_gain * D_r, 0, max_mps)  for D_r >= 0
//                     f_rel = clamp(repulsion_gain  * D_r, -max_mps, 0) for D_r <  0
//   With the defaults (0.25 /s, 1.0 /s, 1.5 m/s) and D_int = 4 m: repulsion
//   saturates at D_r = -1.5 (2.5 m apart), attraction at D_r = +6 (10 m
//   apart). Repulsion four times steeper keeps close pairs apart first (the
//   thesis's safety rule), while the gentle attraction still pulls a
//   straggler 10 m away back at the full 1.5 m/s.
//   custom: linear interpolation through `points`, held flat beyond the ends,
//   then clamped to +-max_mps.
//
// Obstacle reaction f_s(S) (m/s, >= 0; 0 for no hit, for S >= range, NaN S):
//   fs1 (Fig. 7, range 4 m):  max_mps for S <= 1;  max_mps*(4 - S)/3 for 1 < S < 4
//   fs2 (Fig. 8, range 6 m):  max_mps for S <= 1;  max_mps*(6 - S)/5 for 1 < S < 6
//   log (Fig. 19, range 6 m): min(max_mps, log_gain_mps * ln(6 / S)) for 0 < S < 6;
//                             max_mps for S <= 0
//     With k = 1 m/s, max 2 m/s: 0.41 m/s at 4 m, 1 m/s at 2.2 m, 1.8 m/s at
//     1 m, clamped from 0.81 m. Weaker than fs2 far away, steeper near.
//   custom: linear interpolation through `points`; the first f below the first
//     S; 0 from the last S (the range) on.
//   The 1 m plateau: a drone (about 0.5 m across) less than 1 m from a
//   surface gets the full push; fs2 reacts from 6 m, so it acts earlier and
//   more gently per metre than fs1, as the thesis's wider-domain function.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <span>

#include "agent/agent_config.hpp"
#include "common/mission.hpp"

namespace ddswarm::agent {

inline constexpr double kFs1RangeM = 4.0;       ///< m, f_s1 is 0 from here on
inline constexpr double kFs2RangeM = 6.0;       ///< m, f_s2 is 0 from here on
inline constexpr double kLogRangeM = 6.0;       ///< m, S_max of the log function
inline constexpr double kSensorPlateauM = 1.0;  ///< m, fs1/fs2 give max_mps at or below this

/// Drone-to-drone reaction in m/s for D_r = |d_i - d_j| - D_int (m):
/// > 0 attracts, < 0 repels, 0 at D_r = 0, |f| <= max_mps. NaN in, NaN out.
double f_rel(double d_r, const ActivationConfig& a);

/// C_i (m/s, world): sum over peers of f_rel(|d_i - d_j| - d_int) * unit(d_j - d_i).
/// Peers beyond a.cutoff_m (when > 0) are ignored; a peer at self's position
/// (closer than 1e-9 m) has no direction and contributes nothing. With
/// a.neighbours = k > 0 only the k nearest of the remaining peers act (equal
/// distances: the earlier peer in the span), summed nearest first.
///
/// Why k nearest (a topological neighbourhood, as starlings keep about seven
/// neighbours: Ballerini et al., PNAS 2008): in the thesis's sum every peer
/// attracts, so a drone's pull toward the centre grows with n while the
/// push from its closest peer is capped at max_mps. From about 10 drones the
/// swarm packs tighter than 1 m and, at 32 and more, drones touch. With k
/// neighbours the pull is bounded by k terms however large the swarm, and a
/// drone whose k nearest are all closer than D_int is pushed outward.
Eigen::Vector3d repulsion_attraction(const Eigen::Vector3d& self,
                                     std::span<const Eigen::Vector3d> peers, double d_int,
                                     const ActivationConfig& a);

/// f_s(S) in m/s (>= 0) for one ray reading: 0 when !hit, when range_m is
/// NaN or at/beyond the function's range; a negative range reads as 0 m.
double sensor_activation(double range_m, bool hit, const SensorFunctionConfig& s);

/// Distance (m) at and beyond which f_s is 0 (fs1 4, fs2 6, log 6, custom: last S).
double sensor_range_m(const SensorFunctionConfig& s);

/// World direction of a body-frame ray at yaw ray_yaw_body_rad and elevation
/// ray_elevation_body_rad (up from the body x-y plane): its heading h (the
/// yaw turned with the attitude, projected on the horizontal plane and
/// normalised) raised by its elevation, cos(e) h + sin(e) z. The body's tilt
/// turns the heading only, so an elevation-0 ray (the thesis's ring) gives
/// exactly the unit horizontal h. The horizontal part is zero when the
/// heading points straight up or down.
Eigen::Vector3d ray_direction_world(double ray_yaw_body_rad, const Eigen::Quaterniond& q_world_body,
                                    double ray_elevation_body_rad = 0.0);

/// The weight of each ray in C_s: 1 / rows, rows = rays / (the rays at ray
/// 0's elevation), so a scan of rows x columns (row by row, as the server
/// casts it) sums over its columns and averages over its rows. 1 for the
/// ring, or when ray_elevation_body_rad is empty.
double ray_weight(std::span<const float> ray_elevation_body_rad);

/// C_s (m/s, world): sum over rays k of w * f_s(S_k) * (-dir_k), with dir_k
/// = ray_direction_world (yaw, attitude, elevation) and w = ray_weight, the
/// thesis's Eq. 3.3 over the ring (z = 0 there) and a mean over rows for a
/// pattern of several. The spans are per ray; ray_elevation_body_rad may be
/// empty (every ray level). Throws std::invalid_argument if their sizes differ.
Eigen::Vector3d obstacle_avoidance(std::span<const float> range_m,
                                   std::span<const std::uint8_t> hit,
                                   std::span<const float> ray_yaw_body_rad,
                                   std::span<const float> ray_elevation_body_rad,
                                   const Eigen::Quaterniond& q_world_body,
                                   const SensorFunctionConfig& s);

/// Everything control_velocity() needs for one drone at one tick. The spans
/// must outlive the call.
struct LawInput {
  Eigen::Vector3d p_world{0, 0, 0};                                  ///< m, own position
  Eigen::Quaterniond q_world_body = Eigen::Quaterniond::Identity();  ///< own attitude
  std::span<const Eigen::Vector3d> peers_world;  ///< m, the other drones (self excluded)
  std::span<const float> ray_range_m;            ///< m, per ray
  std::span<const std::uint8_t> ray_hit;    ///< per ray, nonzero = obstacle within sensor range
  std::span<const float> ray_yaw_body_rad;  ///< rad, per ray
  /// rad, per ray, up from the body x-y plane; empty: every ray level (the ring)
  std::span<const float> ray_elevation_body_rad;
  Eigen::Vector3d mission_velocity{0, 0, 0};  ///< m/s, world (MissionOutput)
  double inter_distance_m = 4.0;              ///< m, D_int in force now
  bool swarm_enabled = true;                  ///< include C
  bool obstacle_avoidance_enabled = true;     ///< include C_s and the safety distance
  bool altitude_hold = true;                  ///< replace vertical terms by the altitude loop
  bool swarm_horizontal_only = false;         ///< drop C's vertical part (landing: peers already
                                              ///< on the ground must not hold a drone up)
  double altitude_target_m = 2.0;             ///< m, world z held when altitude_hold
};

/// The terms of one evaluation, for logging and tests.
struct LawTerms {
  Eigen::Vector3d swarm{0, 0, 0};     ///< C (m/s), zero when disabled
  Eigen::Vector3d obstacle{0, 0, 0};  ///< C_s (m/s), as used (raised when safety is active)
  Eigen::Vector3d velocity{0, 0, 0};  ///< the command (m/s), limited
  Eigen::Vector3d slide{0, 0, 0};     ///< m/s along the obstacle surface (slide_gain)
  bool safety_active = false;         ///< a ray hit closer than safety_distance_m
};

/// Evaluates V = C_s + C + V_mission for one drone, then:
///  - safety distance (sensor_function.safety_distance_m > 0, a ray hits closer):
///    with u the unit horizontal direction away from those close hits, the
///    other terms (C + V_mission) lose any horizontal component along -u and
///    C_s becomes max_speed_mps * u, so the result always moves away (V.u > 0);
///  - slide (sensor_function.slide_gain > 0): when C_s opposes the other
///    terms horizontally, their blocked part |(C + V_mission).n| is redirected
///    along the surface tangent (the side the other terms lean to; left when
///    dead centre), times slide_gain;
///  - altitude hold: V.z = V_mission.z + clamp(altitude_gain * (target - z),
///    -landing_speed_mps, +takeoff_speed_mps), replacing the vertical parts of C;
///  - limits: horizontal speed, then total speed, to max_speed_mps, keeping direction.
LawTerms evaluate_law(const LawInput& in, const AgentConfig& c);

/// evaluate_law(in, c).velocity: the velocity command (m/s, world).
Eigen::Vector3d control_velocity(const LawInput& in, const AgentConfig& c);

/// The framework around any swarm law (ddswarm/law.hpp): other is the law's
/// velocity, standing for C + V_mission (swarm, the law's own part, is kept
/// for logging). With obstacle_term, C_s and its safety distance and slide
/// act as in evaluate_law; then altitude hold and the limits. evaluate_law
/// is frame_law with the thesis's C.
LawTerms frame_law(const LawInput& in, const Eigen::Vector3d& swarm, Eigen::Vector3d other,
                   bool obstacle_term, const AgentConfig& c);

/// The swarm condition (thesis Eq. 3.1): every pairwise distance < epsilon_m.
/// True for fewer than two drones.
bool swarm_condition(std::span<const Eigen::Vector3d> positions, double epsilon_m);

/// default_epsilon(d_int): the default swarm size epsilon (m) for the task
/// timer, 2 * D_int + 1 m (9 m for D_int = 4). Defined in common/mission.hpp
/// so the ground station can use it too; named here as agent::default_epsilon.
///
/// Why: the default linear activation is scale-free (f_rel is linear on
/// either side of D_r = 0 and does not saturate at these spacings), so the
/// equilibrium shape scales with D_int. Six drones at one altitude settle as
/// a pentagon around a centre drone: ring radius 0.81 D_int (3.2 m), widest
/// pair 1.53 D_int (6.1 m), closest 0.81 D_int. 2 D_int is 30 % above that
/// diameter, so the timer stops once the gathering has converged to within
/// about one spacing instead of waiting for the last centimetres of creep;
/// the extra metre absorbs altitude wobble, obstacle pushes and small D_int.
/// Because every drone attracts every other one (Eq. 3.2), the settled
/// diameter barely grows with n (about 1.75 D_int for 8 to 30 drones), so the
/// default also holds for larger swarms. They get denser instead: from about
/// 10 drones the closest settled pair is under 1 m apart, a limit of the
/// summed linear law itself, not of epsilon. With activation.neighbours the
/// swarm spreads with n instead (about D_int between neighbours), and this
/// default is too small past about 7 drones: set task.epsilon_m.
using ddswarm::default_epsilon;

}  // namespace ddswarm::agent
