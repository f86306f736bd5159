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
// 0.95 d.
//
// β-agents from rays. Each ray that hits is one obstacle: the flat wall
// through the hit point whose normal is the ray (the paper's hyperplane
// β-agent with a_k = the ray's world direction u_k, y_k = the hit point). The
// projection of q_i on that wall is the hit point itself and the β-agent's
// velocity is the part of p_i along the wall:
//   q̂_k = q_i + S_k u_k,   p̂_k = (I − u_k u_kᵀ) p_i,  so  p̂_k − p_i = −(u_k·p_i) u_k.
// A pillar seen by several rays is several walls, each repelling: the closer
// the drone, the more rays see it and the stronger the push. The walls carry
// no sideways cue, so a drone whose only hitting ray points at the pillar
// (with 16 rays: its path within about 0.4 m of a 0.5 m pillar's centre)
// stops about 2 m short of it and stays, as potential fields do; the flock
// around it flies on.
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
// The law is planar: u and v_c are horizontal (z = 0), distances are 3D, and
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
//   c1_gamma       1/s²   0.5               [0, 1000]
//   c2_gamma       1/s    2√c1_gamma (1.41) [0, 1000]              2√c1_γ
//   gamma_position -      sigma1            linear | sigma1        linear (as written)
// A c2 left out follows its c1 as set. The gains make u an acceleration in
// m/s², reading σ-norms as metres (φ and φ_β are pure numbers). c1_α stays
// small because φ_α is stiff: at d = 4 m one pair's spring is about
// 31 c1_α 1/s², and with c1_α = 1 the flock keeps oscillating against the
// velocity loop's lag (order after 60 s ≥ 0.99 in 1 of 20 seeds, down to
// 0.87). c1_β = 5 keeps drones 1.8 m or more from a pillar at up to 1 m/s.
#include <Eigen/Core>
#include <memory>

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
  double c1_gamma = 0.5;                 ///< 1/s², goal position gain, >= 0
  double c2_gamma = 1.4142135623730951;  ///< 1/s, mission velocity gain, default 2√c1_gamma
  bool gamma_sigma1 = true;  ///< goal term −c1_γ σ₁(q − q_r); false: −c1_γ (q − q_r)
};

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
