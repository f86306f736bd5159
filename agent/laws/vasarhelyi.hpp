#pragma once
// The `vasarhelyi` swarm law: the velocity-level flocking model of
// G. Vásárhelyi, C. Virágh, G. Somorjai, T. Nepusz, A. E. Eiben, T. Vicsek,
// "Optimized flocking of autonomous drones in confined environments",
// Science Robotics 3(20), eaat3536, 2018. World frame ENU, metres, seconds.
//
// Notation (the paper's): r position, v velocity; i this drone, j a peer, s a
// shill (virtual) agent on an obstacle; r_ij = |r_i − r_j|, v_ij = |v_i − v_j|.
//
// The braking curve: the largest speed from which a drone braking at a, with
// a linear gain p near the stopping point, stops within distance r:
//   D(r, a, p) = 0                    for r ≤ 0
//              = r p                  for 0 < r p < a / p
//              = √(2 a r − a² / p²)    otherwise
// Both pieces meet at r = a / p² with value a / p and slope p, so D is C¹.
//
// The desired velocity is the sum
//   v_i^d = v_i^spp + Σ_j v_ij^rep + Σ_j v_ij^frict + Σ_s v_is^shill
//   self-propulsion  v_i^spp = v_flock v_i / |v_i|                (the paper)
//   repulsion        v_ij^rep = p_rep (r0_rep − r_ij) (r_i − r_j) / r_ij      for r_ij < r0_rep
//   alignment        v_ij^frictmax = max(v_frict, D(r_ij − r0_frict, a_frict, p_frict))
//                    v_ij^frict = C_frict (v_ij − v_ij^frictmax) (v_j − v_i) / v_ij
//                                                                  for v_ij > v_ij^frictmax
//   shill agents     v_is^smax = D(r_is − r0_shill, a_shill, p_shill)
//                    v_is^shill = C_shill (v_is − v_is^smax) (v_s − v_i) / v_is
//                                                                  for v_is > v_is^smax
// then cut to v_max: v_i^d ← v_i^d min(|v_i^d|, v_max) / |v_i^d|, with v_max
// never above o.max_speed_mps (but see "Speed" below). The paper has no
// attraction: the alignment term (a friction on velocity differences, allowed
// to grow with distance along the braking curve) holds the flock together,
// and the repulsion spaces it at about r0_rep.
//
// Self-propulsion in ddswarm. The law's velocity stands for C + V_mission
// (law.hpp), so when the mission asks a horizontal velocity (task, move,
// swarm gathering, follow) the self-propulsion term is o.mission_velocity
// itself, at the mission's speed: the task flies at the speed the scenario
// configures, and a gathering ends at the goal, whose pull the mission
// velocity already carries (o.goal_world only breaks the slide's ties, below).
// With no horizontal mission velocity (hold, landing):
//   self_propulsion = mission (default): no self-propulsion; the drones
//     hover, spread by the repulsion and calmed by the alignment term.
//   self_propulsion = heading: the paper's v_flock v_i / |v_i| (nothing
//     while |v_i| < 1 mm/s), so a flock in hold flies on as in the paper's
//     free flight; except in landing, where it would carry landing drones off.
//
// Speed (keep_speed = true, the default; ddswarm's, after the authors'
// code). The paper cuts the sum at v_max. The authors' simulation code
// (robotsim, github.com/csviragh/robotsim, src/algo_spp_evol.c, its "SPP
// algorithm for testing evolution algorithms") instead sets the sum's length
// to v_flock every step (the cut at V_Max is the branch it does not take), so
// there the terms turn a drone and never slow it. Here, while the mission
// propels horizontally and the sum heads forward (its dot product with the
// mission velocity is positive), a sum slower than the mission is raised to
// the mission's speed (at most v_max); a faster one is cut at v_max as in the
// paper, so the repulsion can still push harder than the mission. A sum
// heading backward, and any sum without a horizontal mission velocity (hold,
// landing, free flight), is the paper's. Without it the shill agents' braking
// (their term grows with the drone's own speed toward them) holds a drone to
// a crawl at every gap of a pillar field: the thesis course takes 132-138 s
// instead of 110-114 s (seeds 1-3).
//
// Shill agents from rays. A ray hit at horizontal distance S_k in the world
// direction u_k (from the body yaw and pitch through o.q_world_body) is a
// shill agent at r_i + S_k u_k moving away from the obstacle, along the
// surface normal approximated by the reversed ray: v_s = −v_shill u_k, r_is = S_k.
//   shill_agents = nearest (default): the paper puts one shill agent on each
//     obstacle, at its point nearest the drone. Here a shill agent stands on
//     every local minimum of the ring's range profile (rays sorted by
//     azimuth, a miss counting as infinitely far): one for a pillar, one for
//     a wall, two for a corridor, whatever the ray count. Rays all equally
//     far (inside a ring) each give one.
//   shill_agents = every_ray: every hit is a shill agent, so a surface seen
//     by more rays pushes harder.
// Rays within about 6° of vertical are ignored; a negative range reads as 0 m.
//
// Scaling. The paper optimises its parameters for v_flock = 4 m/s and a
// flock spaced about r0_rep = 25.6 m apart; ddswarm flies about D_int = 4 m
// apart at up to 3 m/s. A parameter not given is the paper's value made
// dynamically similar, with a length scale s and a speed scale k:
//   lengths × s,  speeds × k,  rates (1/s) × k / s,  accelerations × k² / s,
//   C_frict and C_shill unchanged,
// so D scales by k (D(s r, a k²/s, p k/s) = k D(r, a, p)): the repulsion and
// the shill agents act as in the paper, s times smaller and s / k times faster.
//   s = scale, or o.inter_distance_m / 25.6 m when scale is not given, re-read
//       every tick, so r0_rep = D_int and a mission's change of D_int rescales
//       the flock;
//   k = v_flock_mps / 4 m/s.
// The alignment's braking curve keeps the paper's lengths (its s is 1, its
// speeds still × k): r0_frict is the reach of the velocity matching (about
// the paper's communication range), not a spacing. Shrunk with D_int to
// 13.3 m it leaves two drones closing at 6 m/s about 1.5 s, five lags of the
// velocity loop, to align before they are out of reach, and flocks started
// with random headings break up (20 drones, 20 seeds: 2 of 20 reach
// φ_corr 0.95 in 10 s, against 20 of 20 with 85.3 m).
// With the defaults (D_int 4 m, max speed 3 m/s: s = 0.156, k = 0.75):
// r0_rep 4 m, p_rep 0.62 /s, r0_frict 85.3 m, v_frict 0.47 m/s, p_frict
// 2.4 /s, a_frict 2.34 m/s², r0_shill 0.047 m; the shill agents' speed scale
// k_s follows the self-propulsion (below): in hold k_s = k, v_shill 10.2 m/s,
// p_shill 17.0 /s, a_shill 10.9 m/s²; in a task at 0.8 m/s k_s = 0.2,
// v_shill 2.72 m/s, p_shill 4.55 /s, a_shill 0.77 m/s². Either way a
// hovering drone feels an obstacle from 4.8 m (1.2 r0_rep; the paper's walls
// act from 31 m at 25.6 m spacing). scale = 1 with v_flock_mps = 4 is the
// paper's set itself (with shill_speed = v_flock, or without a mission
// velocity). A parameter given explicitly is used as written, unscaled.
//
// Shill agents' speed (shill_speed = propulsion, the default). The shill
// agents balance the self-propulsion: the paper's set holds a drone flying at
// v_flock off a wall. So their speeds, rates and decelerations (v_shill,
// p_shill, a_shill) take their speed scale from the self-propulsion actually
// flown, k_s = v_p / 4 m/s, where v_p is the mission's horizontal speed
// (task, move, follow), in a gathering the larger of it and the last such
// speed (the gathering's pull fades at the goal; its cruise speed does not),
// and v_flock without a mission velocity; v_p in [0.1 m/s, v_max]. Their
// lengths (r0_shill, the reach) do not follow it: under dynamic similarity
// the reach does not depend on the speed. shill_speed = v_flock scales them with
// k, as the other terms (the repulsion and the alignment keep k: they space
// and align drones that the obstacles and each other push at up to v_max).
// That was the trap on the thesis course: the task flies at 0.8 m/s, but a
// shill set made for 3 m/s (v_shill 10.2 m/s) pushes a hovering drone off a
// pillar at up to 10 m/s; in front of a 6 m gap the two pillars' shill
// agents, 45° to either side, together push it back at the mission's 0.8 m/s
// 3.4 m short of the row, and it hovers there (6 drones, 200 s: at most 2
// past the finish). With k_s = 0.2 the same agents push it back at 0.2 m/s.
// Scaling the repulsion and the alignment with k_s too weakens the repulsion
// fourfold: drones then come within 0.8-1.4 m of each other on the course
// (2.2-2.8 m with k).
//
// The shill agents' reach (shill_scale, default 1: the paper's). Even so the
// thesis course is narrow for the paper's set: its gaps are 1.5 r0_rep wide,
// and the shill agents brake a drone from 4.8 m (1.2 r0_rep) of each pillar,
// further when it flies at them, so every gap brakes the flock. One drone
// alone (FlockSim, 0.8 m/s from y = 0) reaches the finish line in 114-116 s
// when 64 rays see every pillar, 94-97 s with the course's 8 rays (which miss
// a pillar between them), where the mission's pace is 85 s. shill_scale
// multiplies the shill set's length scale (r0_shill and the reach ×
// shill_scale, rates and decelerations ÷ shill_scale), keeping it dynamically
// similar to itself at a shorter reach: 0.625 (3 m) flies the course in
// 98-99 s, the default in 110-114 s (seeds 1-5; no contact in either).
//
// The slide (ddswarm's, not the paper's; slide = false turns it off). The
// paper's self-propulsion follows the drone's own velocity, so a drone that
// the shill agents slow in front of an obstacle turns with them. The
// mission's direction does not turn: a drone flying it straight at a pillar
// stops in front of it for good. So the part of the mission propulsion that
// the strongest shill agent cancels, c = min(b, −shill_s · u) with u the
// direction to its obstacle and b = propulsion · u, is turned along the
// obstacle's tangent: propulsion − c u + c t. Nothing turns at the edge of
// the agent's reach; all of b where the agent holds the drone (at the stall).
// The side t is the one the propulsion leans to. Dead centre (within about
// 1°, as a pillar seen by a single ray usually is: the ring quantises its
// direction to the ray spacing), it is the side the slide took within the
// last 1 s, else the side of the goal (o.goal_world), else left. The memory
// keeps a drone from turning back and forth across a pillar's front; the
// goal keeps every pillar from being passed on its left, which walks a flock
// 4 m sideways per row of a staggered field (with "left" alone the thesis
// course's flock reaches the finish 11-17 m west of the goal).
//
// Peers. Distances and velocities are horizontal (the framework flies the
// law at one altitude). A peer with a non-finite position is ignored; one
// without a velocity (NaN) repels but takes no part in the alignment. The
// command's vertical part is the mission's (o.mission_velocity.z), which the
// altitude hold replaces when on. The law uses no randomness and handles
// obstacles itself (uses_obstacle_term() is false). Its state: the last
// cruise speed (shill agents' speed) and the slide's side memory.
//
// Parameters (agent.law.params). Default: the paper's value for v_flock =
// 4 m/s (its Table 1 as SwarmLab, lis-epfl/swarmlab, and other reference
// implementations transcribe it), scaled as above.
//   name         unit    default              range            paper (4 m/s)
//   scale        -       D_int / 25.6 m       [0.001, 100]     1
//   v_flock_mps  m/s     min(4, max speed)    [0.1, 50]        4
//   v_max_mps    m/s     agent.max_speed_mps  [0.1, 50], ≥ v_flock   not optimised
//   r0_rep_m     m       25.6 s               [0, 1000]        25.6
//   p_rep        1/s     0.13 k/s             [0, 100]         0.13
//   r0_frict_m   m       85.3                 [0, 1000]        85.3
//   c_frict      -       0.05                 [0, 10]          0.05
//   v_frict_mps  m/s     0.63 k               [0, 50]          0.63
//   p_frict      1/s     3.20 k               [0.001, 1000]    3.20
//   a_frict      m/s²    4.16 k²              [0.001, 1000]    4.16
//   r0_shill_m   m       0.3 s                [-100, 100]      0.3
//   v_shill_mps  m/s     13.6 k_s             [0, 100]         13.6
//   p_shill      1/s     3.55 k_s/s           [0.001, 1000]    3.55
//   a_shill      m/s²    3.02 k_s²/s          [0.001, 1000]    3.02
//   c_shill      -       1                    [0, 10]          1 (no coefficient)
//   self_propulsion  -   mission              mission | heading
//   shill_agents     -   nearest              nearest | every_ray
//   slide            -   true                 true | false
//   shill_speed      -   propulsion           propulsion | v_flock
//   shill_scale      -   1                    [0.05, 20]       -
//   keep_speed       -   true                 true | false
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <memory>
#include <span>
#include <vector>

#include "ddswarm/law.hpp"

namespace ddswarm::agent::laws {

namespace vasarhelyi {

inline constexpr double kPaperVFlockMps = 4.0;  ///< m/s, the v_flock of the set below
inline constexpr double kPaperSpacingM = 25.6;  ///< m, the set's r0_rep: the length s = 1 means

/// Where the self-propulsion comes from without a horizontal mission velocity.
enum class Propulsion { kMission, kHeading };
/// Which ray hits stand for shill agents.
enum class ShillAgents { kNearest, kEveryRay };
/// Which speed the shill agents are scaled to (see "Shill agents' speed").
enum class ShillSpeed { kPropulsion, kVFlock };

/// m/s, the slowest self-propulsion the shill agents are scaled to (v_flock's lower bound)
inline constexpr double kMinPropulsionMps = 0.1;
/// s, how long the slide keeps a side for a dead-centre obstacle after it last acted
inline constexpr double kSlideMemoryS = 1.0;

/// The model's parameters in SI units. The defaults are the paper's
/// optimised set for v_flock = 4 m/s, unscaled.
struct Config {
  double v_flock_mps = 4.0;   ///< m/s, self-propulsion speed (heading mode)
  double v_max_mps = 6.0;     ///< m/s, cut-off of the sum (robotsim's default for 4 m/s)
  double r0_rep_m = 25.6;     ///< m, repulsion range
  double p_rep = 0.13;        ///< 1/s, repulsion gain
  double r0_frict_m = 85.3;   ///< m, alignment: the braking curve's stopping-point offset
  double c_frict = 0.05;      ///< -, alignment coefficient
  double v_frict_mps = 0.63;  ///< m/s, alignment: velocity slack always allowed
  double p_frict = 3.20;      ///< 1/s, alignment braking curve's gain, > 0
  double a_frict = 4.16;      ///< m/s², alignment braking curve's deceleration, > 0
  double r0_shill_m = 0.3;    ///< m, shill braking curve's stopping-point offset
  double v_shill_mps = 13.6;  ///< m/s, shill agents' speed
  double p_shill = 3.55;      ///< 1/s, shill braking curve's gain, > 0
  double a_shill = 3.02;      ///< m/s², shill braking curve's deceleration, > 0
  double c_shill = 1.0;       ///< -, shill coefficient (the paper has none: 1)
  Propulsion propulsion = Propulsion::kMission;
  ShillAgents shill_agents = ShillAgents::kNearest;
  bool slide = true;       ///< turn a blocked mission propulsion along the obstacle (ddswarm's)
  bool keep_speed = true;  ///< never slower than the mission while heading forward (ddswarm's)
  /// Read by the law when it scales the set, not by evaluate().
  ShillSpeed shill_speed = ShillSpeed::kPropulsion;
};

/// c made dynamically similar (see "Scaling"): lengths × length_scale,
/// speeds × speed_scale, rates × speed_scale / length_scale, accelerations ×
/// speed_scale² / length_scale, but the alignment's braking curve with length
/// scale 1 (r0_frict kept, p_frict × speed_scale, a_frict × speed_scale²);
/// coefficients, v_flock, v_max and the choices unchanged. Both scales > 0.
Config scaled(const Config& c, double length_scale, double speed_scale);

/// scaled(c, length_scale, speed_scale), but the shill agents' set
/// (r0_shill, v_shill, p_shill, a_shill) scaled with the speed scale
/// shill_speed_scale and the length scale length_scale · shill_scale. All
/// scales > 0.
Config scaled(const Config& c, double length_scale, double speed_scale, double shill_speed_scale,
              double shill_scale = 1.0);

/// D(r, a, p) in m/s: 0 for r ≤ 0 (and NaN r), r p below r = a / p²,
/// √(2 a r − a² / p²) above. a > 0 (m/s²), p > 0 (1/s), r in m.
double braking_curve(double r_m, double a, double p);

/// v_ij^rep (m/s): p_rep (r0_rep − r_ij) (r_i − r_j) / r_ij for
/// 0 < r_ij < r0_rep, else 0 (also for coincident drones: no direction).
Eigen::Vector2d repulsion(const Eigen::Vector2d& r_i, const Eigen::Vector2d& r_j, const Config& c);

/// v_ij^frict (m/s): C_frict (v_ij − v_frictmax) (v_j − v_i) / v_ij when
/// v_ij exceeds v_frictmax = max(v_frict, D(r_ij − r0_frict, a_frict,
/// p_frict)), else 0.
Eigen::Vector2d friction(const Eigen::Vector2d& r_i, const Eigen::Vector2d& v_i,
                         const Eigen::Vector2d& r_j, const Eigen::Vector2d& v_j, const Config& c);

/// v_is^shill (m/s) for a shill agent at distance r_is_m in the unit
/// direction toward_obstacle, moving at v_s = −v_shill toward_obstacle:
/// C_shill (v_is − v_smax) (v_s − v_i) / v_is when v_is = |v_s − v_i| exceeds
/// v_smax = D(r_is − r0_shill, a_shill, p_shill), else 0.
Eigen::Vector2d shill(const Eigen::Vector2d& v_i, const Eigen::Vector2d& toward_obstacle,
                      double r_is_m, const Config& c);

/// One shill agent: where the obstacle is (unit, world, horizontal) and how
/// far (m, horizontal).
struct ShillAgent {
  Eigen::Vector2d toward_obstacle{1, 0};
  double distance_m = 0;
};

/// The shill agents of one scan (see "Shill agents from rays" above), in
/// ray-azimuth order.
std::vector<ShillAgent> shill_agents(std::span<const law::Ray> rays,
                                     const Eigen::Quaterniond& q_world_body, ShillAgents mode);

/// The self-propulsion term (m/s, horizontal): the mission velocity's
/// horizontal part when nonzero; else v_flock along v_i with
/// Propulsion::kHeading (outside landing, |v_i| ≥ 1 mm/s); else zero.
Eigen::Vector2d self_propulsion(const Eigen::Vector2d& v_i, const Eigen::Vector3d& mission_velocity,
                                law::Phase phase, const Config& c);

/// The side the slide turns to: +1 left of toward_obstacle, −1 right; the
/// side propulsion leans to, or tie (+1 or −1) when it is dead centre
/// (within about 1°).
int slide_side(const Eigen::Vector2d& propulsion, const Eigen::Vector2d& toward_obstacle, int tie);

/// The slide: propulsion − c u + c t, with u = toward_obstacle, c = amount
/// clamped to [0, b], b = propulsion · u (its part into the obstacle), and t
/// the unit tangent on side (+1 left of u, −1 right). Unchanged when b ≤ 0.
Eigen::Vector2d slide(const Eigen::Vector2d& propulsion, const Eigen::Vector2d& toward_obstacle,
                      int side, double amount);

/// The whole slide (amount b) on slide_side(propulsion, toward_obstacle, +1).
Eigen::Vector2d slide(const Eigen::Vector2d& propulsion, const Eigen::Vector2d& toward_obstacle);

/// What the slide remembers between ticks: the side it last took and when.
struct SlideMemory {
  int side = 0;          ///< +1 left of the obstacle, −1 right, 0 none yet
  double time_s = -1e9;  ///< s, o.sim_time_s when it last acted
};

/// The terms of one evaluation (m/s, horizontal), for logging and tests.
struct Terms {
  Eigen::Vector2d propulsion{0, 0};  ///< after the slide
  Eigen::Vector2d repulsion{0, 0};
  Eigen::Vector2d friction{0, 0};
  Eigen::Vector2d shill{0, 0};
  Eigen::Vector2d velocity{0, 0};  ///< the sum, cut to min(v_max, o.max_speed_mps)
};

/// Every term for one drone's observation with parameters c (already scaled).
/// memory: the slide's memory, read and updated; nullptr = none (a
/// dead-centre obstacle then goes by the goal's side, else left).
Terms evaluate(const law::Observation& o, const Config& c, SlideMemory* memory = nullptr);

}  // namespace vasarhelyi

/// The law for one drone: reads and checks p (table above), then p.finish().
/// Throws law::ParamError naming agent.law.params.<key> for a value out of
/// range, an unknown key, or v_flock_mps > v_max_mps. Draws no random numbers.
std::unique_ptr<law::SwarmLaw> make_vasarhelyi(law::Params& p, law::Rng rng,
                                               const law::LawContext& ctx);

}  // namespace ddswarm::agent::laws
