#pragma once
// reynolds: C. W. Reynolds, "Flocks, herds and schools: a distributed
// behavioral model", SIGGRAPH '87, Computer Graphics 21(4):25-34, 1987
// (reference [17] of the thesis). The paper's three steering behaviours, in
// its order of precedence: collision avoidance (separation), velocity
// matching (alignment), flock centering (cohesion), each from the drone's
// neighbourhood only. World frame ENU, metres, seconds.
//
// Velocity level. A boid integrates steering accelerations; our drones are
// velocity-commanded and the flight controller tracks the command, so each
// behaviour here is a velocity (m/s) added to a reference velocity V_ref:
//
//   v = limit(V_ref + A(s, a, c), max_speed_mps)
//   V_ref = V_mission + v_cruise · unit(v_i − V_mission)   (v_cruise = 0: V_mission)
//
//   s = k_s · Σ_{j: d_j < r_s} r_s · (r_s / d_j − 1) · (p_i − p_j) / d_j   (separation)
//   a = k_a · (mean_{j ∈ N} v_j − v_i)                                     (alignment)
//   c = k_c · (mean_{j ∈ N} p_j − p_i)                                     (cohesion)
//
// with d_j = |p_j − p_i|, r_s the separation distance (D_int in force by
// default), and N the neighbourhood: the peers with d_j ≤ R (every peer
// when R = 0) whose bearing p_j − p_i is within fov/2 of the drone's own
// velocity v_i (every bearing when fov = 360° or |v_i| < 0.1 m/s). Peers
// whose velocity is NaN count for cohesion but not for alignment; a peer
// with a non-finite position, or at the drone's own position (no
// direction), is ignored. An empty neighbourhood gives a = c = 0.
//
// The separation weight r_s (r_s/d − 1) is an inverse distance shifted to
// be 0 at d = r_s (no step as a peer crosses r_s): r_s/3 at 0.75 r_s, r_s
// at r_s/2, without bound near contact, where the cap below takes over. A
// drone hears its peers all around, so separation ignores the field of
// view: the field of view shapes whom a drone follows, not whom it avoids.
//
// Prioritised acceleration allocation (combine = priority, the paper's
// scheme): the terms are taken in precedence order from a budget
// B = max_term_mps, each trimmed to what is left of it,
//   s' = cap(s, B),  a' = cap(a, B − |s'|),  c' = cap(c, B − |s'| − |a'|),
// A = s' + a' + c', so |A| ≤ B and a drone pressed by a close peer spends
// the whole budget on avoiding it before it follows or centres. With
// combine = sum, A = cap(s, B) + cap(a, B) + cap(c, B) (a weighted sum,
// each term capped alone). cap(x, m) scales x down to length m when longer.
//
// Units: k_s and k_c in 1/s (metres to m/s), k_a dimensionless (m/s to
// m/s). At velocity level, a = k_a (mean − v_i) moves a drone's command,
// not its acceleration, toward its neighbours' velocity. With v_cruise = 0
// a flock's common motion relaxes to V_mission (the flock hovers when
// V_mission = 0), while the differences between its drones' velocities
// decay 1 + k_a times faster. v_cruise > 0 gives each drone a boid's
// momentum: it keeps flying at v_cruise relative to V_mission in the
// direction it already flies (V_ref = V_mission while it is within 1 mm/s
// of V_mission), so a free flock wanders as Reynolds's does, and velocity
// matching alone picks the common heading. Keep it 0 for missions: with it
// the flock flies V_mission plus v_cruise in a direction of its own. The
// framework adds the sensor term for obstacles (uses_obstacle_term() is true).
//
// With the defaults and D_int = 4 m, 16 drones started at random in a
// 10 m square with random headings at 1.5 m/s (FlockSim, seeds 1-30, with
// V_mission = (0.8, 0, 0), or with v_cruise = 1 m/s and no mission): order
// > 0.95 within 5.3 s; the closest pair from 5 s on at least 2.8 m
// (0.7 D_int); the flock at most 15.1 m (3.8 D_int) across from 20 s on;
// the 10 m neighbourhood graph never splits. Separation settles the pairs
// inside r_s, where it balances centering; separation_gain sets how deep
// (0.5 /s: 0.6 D_int, 2 /s: 0.8 D_int apart). A capped sum instead of the
// priority lets the closest pair come to 2.0 m. A field of view below 360°
// lets the front drones lose those behind: at 270° the neighbourhood graph
// splits in 2 runs of 30.
//
// Parameters (agent.law.params; unit, default, range):
//   radius_m          m    2.5 · D_int in force  [0, 1000]; 0 = every peer
//   separation_m      m    0 = D_int in force    [0, 1000]; < radius_m
//   separation_gain   1/s  1.0                   [0, 100]
//   alignment_gain    -    1.0                   [0, 20]
//   cohesion_gain     1/s  0.3                   [0, 10]
//   fov_deg           deg  360                   [1, 360]
//   max_term_mps      m/s  1.5                   (0, 20]  the budget B
//   cruise_speed_mps  m/s  0                     [0, 20]
//   combine           -    priority              priority | sum
// Cross-field: the separation distance must be below the radius (both as in
// force at build time, D_int = LawContext::inter_distance_m) unless
// radius_m = 0. The law is stateless and draws no random numbers.
#include <Eigen/Core>
#include <memory>
#include <span>

#include "ddswarm/law.hpp"

namespace ddswarm::agent::laws {

inline constexpr double kReynoldsRadiusFactor = 2.5;   ///< default radius, in D_int
inline constexpr double kReynoldsHeadingMinMps = 0.1;  ///< m/s, slower: the view is all around

/// Who a drone's alignment and cohesion listen to.
struct Neighbourhood {
  double radius_m = 10.0;  ///< m, > 0; 0 = every peer
  double fov_deg = 360.0;  ///< deg, (0, 360], centred on the drone's velocity
};

/// Whether a peer at offset = p_j − p_i (m) is in the neighbourhood of a
/// drone flying at v_world (m/s): |offset| ≤ radius (any when radius is 0)
/// and the bearing within fov/2 of v_world (any bearing when fov ≥ 360 or
/// |v_world| < kReynoldsHeadingMinMps). False for a non-finite offset.
bool in_neighbourhood(const Eigen::Vector3d& offset, const Eigen::Vector3d& v_world,
                      const Neighbourhood& n);

/// s (m/s, world): gain_per_s · Σ over peers closer than separation_m of
/// separation_m · (separation_m / d − 1) · unit(p_world − p_j); 0 from
/// separation_m on. Peers at the drone's position (< 1e-9 m) or with a
/// non-finite position contribute nothing. Not capped.
Eigen::Vector3d separation(const Eigen::Vector3d& p_world, std::span<const law::Peer> peers,
                           double separation_m, double gain_per_s);

/// a (m/s, world): gain · (mean v_j − v_world) over the peers in the
/// neighbourhood whose velocity is finite; 0 when there are none. Not capped.
Eigen::Vector3d alignment(const Eigen::Vector3d& p_world, const Eigen::Vector3d& v_world,
                          std::span<const law::Peer> peers, const Neighbourhood& n, double gain);

/// c (m/s, world): gain_per_s · (mean p_j − p_world) over the peers in the
/// neighbourhood; 0 when there are none. Not capped.
Eigen::Vector3d cohesion(const Eigen::Vector3d& p_world, const Eigen::Vector3d& v_world,
                         std::span<const law::Peer> peers, const Neighbourhood& n,
                         double gain_per_s);

/// Reynolds's prioritised allocation: the terms, highest precedence first,
/// each trimmed to what the earlier ones left of budget_mps; returns their
/// sum, whose length is at most budget_mps.
Eigen::Vector3d allocate_by_priority(std::span<const Eigen::Vector3d> terms, double budget_mps);

/// The law's settings, resolved from agent.law.params (see the table above).
struct ReynoldsConfig {
  double radius_m = -1;          ///< m; 0 = every peer; < 0 = 2.5 · D_int in force
  double separation_m = 0;       ///< m; 0 = D_int in force
  double separation_gain = 1.0;  ///< 1/s
  double alignment_gain = 1.0;   ///< dimensionless
  double cohesion_gain = 0.3;    ///< 1/s
  double fov_deg = 360;          ///< deg
  double max_term_mps = 1.5;     ///< m/s, the budget B (priority) or per-term cap (sum)
  double cruise_speed_mps = 0;   ///< m/s, 0 = no momentum of its own
  bool priority = true;          ///< true: prioritised allocation; false: capped sum
};

/// The terms and command of one evaluation, for tests and logging (m/s, world).
struct ReynoldsTerms {
  Eigen::Vector3d separation{0, 0, 0};  ///< s, uncapped
  Eigen::Vector3d alignment{0, 0, 0};   ///< a, uncapped
  Eigen::Vector3d cohesion{0, 0, 0};    ///< c, uncapped
  Eigen::Vector3d reference{0, 0, 0};   ///< V_ref
  Eigen::Vector3d velocity{0, 0, 0};    ///< the command, |v| ≤ o.max_speed_mps
};

/// Evaluates the law for one observation (pure).
ReynoldsTerms reynolds_terms(const law::Observation& o, const ReynoldsConfig& c);

/// Builds the law from agent.law.params. Throws law::ParamError naming the
/// field for a value out of range, a separation distance not below the
/// radius, or an unknown key (p.finish()). rng is unused.
std::unique_ptr<law::SwarmLaw> make_reynolds(law::Params& p, law::Rng rng,
                                             const law::LawContext& ctx);

}  // namespace ddswarm::agent::laws
