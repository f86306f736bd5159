#pragma once
// The `olfati_saber` swarm law: Algorithm 2 of R. Olfati-Saber, "Flocking
// for multi-agent dynamic systems: algorithms and theory", IEEE Trans.
// Automatic Control 51(3), 401-420, 2006: flocking with a γ-agent, with
// Algorithm 3's β-agents on obstacles. World frame ENU, metres, seconds.
//
// Notation (the paper's): q position, p velocity; i this drone, j a peer, k an
// obstacle's β-agent; ‖·‖ Euclidean, ‖·‖_σ the σ-norm.
//
//   σ-norm     ‖z‖_σ = (√(1 + ε‖z‖²) − 1) / ε
//   its gradient σ_ε(z) = z / √(1 + ε‖z‖²) = z / (1 + ε‖z‖_σ)
//   σ₁(z)      = z / √(1 + z²)          (scalar; for a vector, z / √(1 + ‖z‖²))
//   bump       ρ_h(z) = 1 on [0, h); ½[1 + cos(π (z − h)/(1 − h))] on [h, 1];
//                       0 otherwise
//   φ(z)       = ½[(a + b) σ₁(z + c) + (a − b)],  c = |a − b| / √(4ab),
//                0 < a ≤ b, so φ(0) = 0, φ increasing from −b to a
//   φ_α(z)     = ρ_h(z / r_α) φ(z − d_α),  r_α = ‖r‖_σ, d_α = ‖d‖_σ
//   φ_β(z)     = ρ_h(z / d_β) (σ₁(z − d_β) − 1),  d_β = ‖d'‖_σ
//   n_ij = σ_ε(q_j − q_i),  a_ij = ρ_h(‖q_j − q_i‖_σ / r_α)  with h = h_α
//   n̂_ik = σ_ε(q̂_k − q_i),  b_ik = ρ_h(‖q̂_k − q_i‖_σ / d_β) with h = h_β
//
//   u_i = u_α + u_β + u_γ
//   u_α = c1_α Σ_{‖q_j−q_i‖<r} φ_α(‖q_j − q_i‖_σ) n_ij + c2_α Σ_{‖q_j−q_i‖<r} a_ij (p_j − p_i)
//   u_β = c1_β Σ_{‖q̂_k−q_i‖<r'} φ_β(‖q̂_k − q_i‖_σ) n̂_ik + c2_β Σ_{‖q̂_k−q_i‖<r'} b_ik (p̂_k − p_i)
//   u_γ = −c1_γ (q_i − q_r) − c2_γ (p_i − p_r)
//
// φ_α is repulsive (< 0) below d, attractive (> 0) from d to r and 0 from r
// on: at d every pair is in equilibrium, the α-lattice ‖q_j − q_i‖ = d. φ_β
// only repels, and only closer than d'; r' = r_ratio · d' bounds the
// β-neighbourhood as in the paper (every β term is 0 from d' on anyway).
//
// The scales. d (m) is d_m, or D_int (o.inter_distance_m, which follows the
// mission) when d_m = 0; r = r_ratio · d; d' = obstacle_ratio · d; all
// re-read every tick, so a mission's change of D_int rescales the lattice.
// ε is applied to distances in metres as the paper applies it to its units
// (d = 7 there). The σ-norm is not scale-free: the forces grow with d, so a
// small D_int makes a softer lattice (see docs/laws.md).
//
// The γ-agent. p_r is the mission velocity (o.mission_velocity). q_r is the
// goal (o.goal_world) when it is finite; otherwise the position term is left
// out and only the velocity feedback acts (Algorithm 2 needs q_r for
// cohesion: without it, a flock that starts disconnected stays so). The
// position term is, by default (gamma_position = sigma1), the bounded
//   u_γ = −c1_γ σ₁(q_i − q_r) − c2_γ (p_i − p_r),   σ₁(z) = z / √(1 + ‖z‖²),
// so a far goal pulls with at most c1_γ m/s² (the form common reference
// implementations fly). gamma_position = linear is the term above as
// written. Why not linear by default: every drone is pulled to the same
// point with a force that grows with distance, while φ_α's push fades to 0
// as two drones meet (n_ij → 0). In FlockSim 15 drones gathering at a goal
// 24 m away end with pairs 0.00 m apart; with σ₁ no pair ends closer than
// 0.89 d. The bounded pull has a price while the goal is far: the drone
// cruises at p_r + c1_γ/c2_γ = p_r + √c1_γ / 2 along the goal's direction
// (1.3 m/s for a 0.8 m/s task with the defaults).
// Why c1_γ = 1. The thesis task ends when every pair is closer than
// 2 D_int + 1 = 9 m. Six drones arriving at the goal in a column settle, with
// c1_γ ≤ 0.85, as a staggered 1-2-2-1 patch of the α-lattice that the goal
// pull squeezes only to 9.25 m (0.5), 8.86 m (0.7) or 8.53 m (0.85) across:
// the task times out at c1_γ = 0.5 on 3 of 5 seeds, and passes by 0.14 m at
// 0.7. From c1_γ = 0.9 the pull folds the patch into a compact cluster about
// 6.2 m across (closest pair 3.2 m). At 1.3 two drones touch on the way.
//
// β-agents from rays (Sec. VII). The rays are read as obstacles, one β-agent
// per obstacle, in the horizontal plane (the law is planar). A ring is the
// rays of one body pitch, in yaw order; rays steeper than 60° are left out.
// Two neighbouring hits (at most 60° apart) are one obstacle when their hit
// points lie within 1.5 times the chord the ray spacing spans at their
// range. Each hit whose range no neighbour of its obstacle beats (the
// pattern's local minimum) is the nearest point of one obstacle, and its
// neighbours give the surface:
//   - both neighbours hit it: the circle through the three hit points, a
//     sphere of centre y_k and radius R_k (seen from outside, on its near
//     half, R_k ≤ 100 m; else the wall below). The paper's sphere β-agent:
//       μ = R_k / ‖q_i − y_k‖,  a_k = (q_i − y_k)/‖q_i − y_k‖,  P = I − a_k a_kᵀ,
//       q̂_k = μ q_i + (1 − μ) y_k,   p̂_k = μ P p_i;
//     R_k is raised so that q̂_k is no farther than the nearest hit;
//   - one neighbour hits it (or three points on a line): the wall through
//     the hits, a_k the chord's normal facing the drone. The paper's
//     hyperplane β-agent:  q̂_k = P q_i + (I − P) y_k,  p̂_k = P p_i;
//   - no neighbour hits it: the wall through the hit facing the ray,
//     a_k = −u_k, so q̂_k is the hit point and p̂_k − p_i = −(u_k·p_i) u_k.
// With 16 rays, three hit a 0.5 m pillar from within about 0.8 m of it;
// with the thesis course's 8 rays, a 1 m pillar only from within 0.41 m
// (R(√2 − 1)), so there nearly every pillar is a one-ray wall. The
// simulator's rays also hit other drones: those hits are obstacles too.
// The slide (not in the paper; beta_slide = 0 turns it off). One hit cannot
// tell which side of a pillar the drone is on, and a drone flying at a
// pillar's centre sees the pillar in one ray only (with 8 rays, a 1 m pillar
// anywhere within ±1 m of its path): a_k is then the ray, exactly against
// the mission, and p̂_k = P p_i carries no sideways motion. Every force is
// along the path, so the drone stops about d' short of the pillar and stays
// (the local minimum of potential fields; on the thesis course, 2 of 6
// drones never reached the finish). The slide moves the β-agent along the
// surface with the part of the γ-agent's velocity that the obstacle blocks:
//   into_k = beta_slide · max(0, −p_r·a_k),  t_k ⊥ a_k (horizontal),
//   p̂_k ← p̂_k + max(0, into_k − t_k·p̂_k) t_k,
// so the damping term c2_β b_ik (p̂_k − p_i) carries the drone round the
// obstacle as fast as the obstacle holds it back, and never past that. t_k
// points the way the drone already moves along the surface (|t_k·p_i| >
// 0.05 m/s), else the way p_r leans (|t_k·p_r| > 10⁻³ |p_r|), else a_k turned
// +90° (counter-clockwise: a drone flying north passes on the east), the
// tie-break the framework's C_s slide makes. It acts only while p_r pushes
// into the obstacle and only within d', where b_ik > 0.
//
// Velocity command. The paper's agents are double integrators (q̇ = p,
// ṗ = u); our drones track a commanded velocity. The law keeps the double
// integrator's velocity itself: v_c, set to the measured horizontal velocity
// on the first call and after a gap in ticks (o.tick ≠ last tick + 1), then
//   v_c ← v_c + u_i · o.dt_s,   |v_c| clamped to o.max_speed_mps,
// and answers v_c. The drone's own p_i in u_i is v_c, so the damping terms
// (−c2 p_i) act on the integrator at once instead of through the velocity
// loop's lag; q_i, q_j and p_j are as observed. (With p_i = o.v_world the
// lattice stops settling once the loop is slower: in FlockSim with a 0.6 s
// time constant, 15 drones, 20 seeds, order after 60 s is down to 0.65,
// against at least 0.9989 with v_c.)
// The law is planar: u and v_c are horizontal (z = 0), distances to peers
// are 3D and to obstacles horizontal, and
// the command's vertical part is the mission's (o.mission_velocity.z), which
// the framework's altitude hold replaces when on.
//
// A peer with a non-finite position is ignored; one without a velocity (NaN)
// acts through φ_α only, with no velocity-matching term. The law uses no
// randomness and handles obstacles itself (uses_obstacle_term() is false).
//
// Parameters (agent.law.params). The paper's values are its Sec. VIII's; it
// gives no values for the gains, only c1_α < c1_γ < c1_β and c2 = 2√c1.
//   name           unit   default           range                  paper
//   d_m            m      0 (= D_int)       0 or [0.1, 1000]       7
//   r_ratio        -      1.2               (1, 5]                 1.2  (r = 1.2 d)
//   epsilon        -      0.1               (0, 10]                0.1
//   a              -      5                 (0, 100], a ≤ b        5
//   b              -      5                 (0, 100]               5
//   h_alpha        -      0.2               [0, 0.99]              0.2
//   h_beta         -      0.9               [0, 0.99]              0.9
//   obstacle_ratio -      0.6               (0, 5]                 0.6  (d' = 0.6 d)
//   c1_alpha       1/s²   0.3               [0, 1000]              c1_α < c1_γ < c1_β
//   c2_alpha       1/s    2√c1_alpha (1.10) [0, 1000]              2√c1_α
//   c1_beta        1/s²   5                 [0, 1000]
//   c2_beta        1/s    2√c1_beta (4.47)  [0, 1000]              2√c1_β
//   c1_gamma       1/s²   1                 [0, 1000]
//   c2_gamma       1/s    2√c1_gamma (2)    [0, 1000]              2√c1_γ
//   gamma_position -      sigma1            linear | sigma1        linear (as written)
//   beta_slide     -      1                 [0, 10]                0 (no slide)
// A c2 left out follows its c1 as set. The gains make u an acceleration in
// m/s², reading σ-norms as metres (φ and φ_β are pure numbers). c1_α stays
// small because φ_α is stiff: at d = 4 m one pair's spring is about
// 31 c1_α 1/s², and with c1_α = 1 the flock keeps oscillating against the
// velocity loop's lag (order after 60 s ≥ 0.99 in 1 of 20 seeds, down to
// 0.87). c1_β = 5 keeps drones 1.5 m or more from a pillar at up to 1 m/s
// in FlockSim, and 1.1 m or more on the thesis course (squeezed between
// pillars by their peers).
#include <Eigen/Core>
#include <memory>
#include <vector>

#include "ddswarm/law.hpp"

namespace ddswarm::agent::laws {

/// ‖z‖_σ = (√(1 + ε‖z‖²) − 1) / ε for a distance s = ‖z‖ (m), ε > 0;
/// computed as s² / (√(1 + ε s²) + 1), exact also for tiny ε s².
double sigma_norm(double s, double epsilon);

/// σ_ε(z) = z / √(1 + ε‖z‖²), the gradient of ‖z‖_σ; 0 at z = 0, norm < 1/√ε.
Eigen::Vector3d sigma_gradient(const Eigen::Vector3d& z, double epsilon);

/// σ₁(z) = z / √(1 + z²), in (−1, 1).
double sigma1(double z);

/// ρ_h(z): 1 on [0, h), ½[1 + cos(π (z − h)/(1 − h))] on [h, 1], 0 elsewhere
/// (also for z < 0). 0 ≤ h < 1.
double bump(double z, double h);

/// φ(z) = ½[(a + b) σ₁(z + c) + (a − b)], c = |a − b| / √(4ab); 0 < a ≤ b.
double phi(double z, double a, double b);

/// φ_α(z) = ρ_h(z / r_α) φ(z − d_α) for a σ-norm z ≥ 0; 0 < d_α < r_α.
double phi_alpha(double z, double r_alpha, double d_alpha, double h, double a, double b);

/// φ_β(z) = ρ_h(z / d_β) (σ₁(z − d_β) − 1) for a σ-norm z ≥ 0: ≤ 0, 0 from d_β on.
double phi_beta(double z, double d_beta, double h);

/// The law's parameters, read from agent.law.params (see the table above).
struct OlfatiSaberConfig {
  double d_m = 0;                        ///< m, lattice distance d; 0 = D_int (o.inter_distance_m)
  double r_ratio = 1.2;                  ///< r / d, > 1
  double epsilon = 0.1;                  ///< σ-norm ε, > 0
  double a = 5;                          ///< φ's attraction bound, 0 < a ≤ b
  double b = 5;                          ///< φ's repulsion bound
  double h_alpha = 0.2;                  ///< ρ_h's plateau for α terms, [0, 0.99]
  double h_beta = 0.9;                   ///< ρ_h's plateau for β terms, [0, 0.99]
  double obstacle_ratio = 0.6;           ///< d' / d, > 0
  double c1_alpha = 0.3;                 ///< 1/s², lattice (gradient) gain, >= 0
  double c2_alpha = 1.0954451150103321;  ///< 1/s, velocity-matching gain, default 2√c1_alpha
  double c1_beta = 5;                    ///< 1/s², obstacle repulsion gain, >= 0
  double c2_beta = 4.4721359549995796;   ///< 1/s, obstacle damping gain, default 2√c1_beta
  double c1_gamma = 1.0;                 ///< 1/s², goal position gain, >= 0
  double c2_gamma = 2.0;                 ///< 1/s, mission velocity gain, default 2√c1_gamma
  bool gamma_sigma1 = true;  ///< goal term −c1_γ σ₁(q − q_r); false: −c1_γ (q − q_r)
  double beta_slide = 1;     ///< β-agents slide along the surface, [0, 10]; 0 = paper
};

/// One obstacle as the law reads it off the rays, in the horizontal plane
/// (world x, y): a sphere (circle) of centre y and radius R, or a wall through
/// y with unit normal a facing the drone.
struct Obstacle {
  bool sphere = false;
  Eigen::Vector2d y{0, 0};  ///< m, world: the centre (sphere) or a point on the wall
  Eigen::Vector2d a{0, 0};  ///< unit normal toward the drone (walls; spheres: from y)
  double radius_m = 0;      ///< m, R (spheres only)
};

/// The obstacles o.rays show, one per local minimum of the ray pattern (see
/// the header comment), relative to the drone at o.p_world.
std::vector<Obstacle> obstacles_from_rays(const law::Observation& o);

/// An obstacle's β-agent for a drone at q with velocity p (horizontal, m and
/// m/s): the paper's projection, q̂ and p̂ (before the slide), and a_k.
struct BetaAgent {
  Eigen::Vector2d q{0, 0};  ///< m, world: q̂_k
  Eigen::Vector2d p{0, 0};  ///< m/s: p̂_k
  Eigen::Vector2d a{0, 0};  ///< unit normal at q̂_k toward the drone
};
BetaAgent beta_agent(const Obstacle& k, const Eigen::Vector2d& q, const Eigen::Vector2d& p);

/// Reads the parameters (defaults above), checks ranges and a ≤ b, then
/// p.finish(). Throws law::ParamError naming agent.law.params.<key>.
OlfatiSaberConfig olfati_saber_config(law::Params& p);

/// Algorithm 2's u_i (m/s², world, z = 0) for one drone at q_i = o.p_world
/// with velocity p_i = p_self (m/s), peers and rays from o.
Eigen::Vector3d olfati_saber_acceleration(const law::Observation& o, const Eigen::Vector3d& p_self,
                                          const OlfatiSaberConfig& c);

/// The law for one drone (reads and checks p; the law draws no random numbers).
std::unique_ptr<law::SwarmLaw> make_olfati_saber(law::Params& p, law::Rng rng,
                                                 const law::LawContext& ctx);

}  // namespace ddswarm::agent::laws
