#include "olfati_saber.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

namespace ddswarm::agent::laws {

double sigma_norm(double s, double epsilon) {
  const double s2 = s * s;
  return s2 / (std::sqrt(1.0 + epsilon * s2) + 1.0);
}

Eigen::Vector3d sigma_gradient(const Eigen::Vector3d& z, double epsilon) {
  return z / std::sqrt(1.0 + epsilon * z.squaredNorm());
}

double sigma1(double z) { return z / std::sqrt(1.0 + z * z); }

double bump(double z, double h) {
  if (z < 0 || z > 1) return 0;
  if (z < h) return 1;
  return 0.5 * (1.0 + std::cos(std::numbers::pi * (z - h) / (1.0 - h)));
}

double phi(double z, double a, double b) {
  const double c = std::abs(a - b) / std::sqrt(4.0 * a * b);
  return 0.5 * ((a + b) * sigma1(z + c) + (a - b));
}

double phi_alpha(double z, double r_alpha, double d_alpha, double h, double a, double b) {
  return bump(z / r_alpha, h) * phi(z - d_alpha, a, b);
}

double phi_beta(double z, double d_beta, double h) {
  return bump(z / d_beta, h) * (sigma1(z - d_beta) - 1.0);
}

namespace {

std::string field(const law::Params& p, const std::string& key) { return p.prefix() + "." + key; }

std::string text(double v) {
  std::string s = std::to_string(v);
  while (s.size() > 1 && s.back() == '0') s.pop_back();
  if (!s.empty() && s.back() == '.') s.pop_back();
  return s;
}

/// A number in (0, hi]: Params::number checks [0, hi], this refuses 0.
double positive(law::Params& p, const std::string& key, double def, double hi) {
  const double v = p.number(key, def, 0.0, hi);
  if (v <= 0) throw law::ParamError(field(p, key), text(v), "must be > 0");
  return v;
}

}  // namespace

OlfatiSaberConfig olfati_saber_config(law::Params& p) {
  OlfatiSaberConfig c;
  c.d_m = p.number("d_m", c.d_m, 0.0, 1000.0);
  if (c.d_m != 0 && c.d_m < 0.1)
    throw law::ParamError(field(p, "d_m"), text(c.d_m), "must be 0 (D_int) or in [0.1, 1000]");
  c.r_ratio = p.number("r_ratio", c.r_ratio, 1.0, 5.0);
  if (c.r_ratio <= 1.0)
    throw law::ParamError(field(p, "r_ratio"), text(c.r_ratio),
                          "must be > 1 (r = r_ratio * d lies beyond d)");
  c.epsilon = positive(p, "epsilon", c.epsilon, 10.0);
  c.a = positive(p, "a", c.a, 100.0);
  c.b = positive(p, "b", c.b, 100.0);
  if (c.a > c.b)
    throw law::ParamError(field(p, "a"), text(c.a),
                          "must be <= b (" + text(c.b) + "): 0 < a <= b puts phi's zero at d");
  c.h_alpha = p.number("h_alpha", c.h_alpha, 0.0, 0.99);
  c.h_beta = p.number("h_beta", c.h_beta, 0.0, 0.99);
  c.obstacle_ratio = positive(p, "obstacle_ratio", c.obstacle_ratio, 5.0);
  c.c1_alpha = p.number("c1_alpha", c.c1_alpha, 0.0, 1000.0);
  c.c2_alpha = p.number("c2_alpha", 2.0 * std::sqrt(c.c1_alpha), 0.0, 1000.0);
  c.c1_beta = p.number("c1_beta", c.c1_beta, 0.0, 1000.0);
  c.c2_beta = p.number("c2_beta", 2.0 * std::sqrt(c.c1_beta), 0.0, 1000.0);
  c.c1_gamma = p.number("c1_gamma", c.c1_gamma, 0.0, 1000.0);
  c.c2_gamma = p.number("c2_gamma", 2.0 * std::sqrt(c.c1_gamma), 0.0, 1000.0);
  c.gamma_sigma1 = p.choice("gamma_position", "sigma1", {"linear", "sigma1"}) == "sigma1";
  p.finish();
  return c;
}

Eigen::Vector3d olfati_saber_acceleration(const law::Observation& o, const Eigen::Vector3d& p_self,
                                          const OlfatiSaberConfig& c) {
  const double eps = c.epsilon;
  const double d = c.d_m > 0 ? c.d_m : o.inter_distance_m;
  const double r = c.r_ratio * d;
  const double d_alpha = sigma_norm(d, eps), r_alpha = sigma_norm(r, eps);
  const double d_obst = c.obstacle_ratio * d;
  const double r_obst = c.r_ratio * d_obst;
  const double d_beta = sigma_norm(d_obst, eps);
  const Eigen::Vector3d& q = o.p_world;
  const Eigen::Vector3d& p = p_self;

  Eigen::Vector3d u = Eigen::Vector3d::Zero();
  for (const law::Peer& peer : o.peers) {
    if (!peer.p_world.allFinite()) continue;
    const Eigen::Vector3d z = peer.p_world - q;
    if (z.norm() >= r) continue;
    const double zs = sigma_norm(z.norm(), eps);
    u += c.c1_alpha * phi_alpha(zs, r_alpha, d_alpha, c.h_alpha, c.a, c.b) * sigma_gradient(z, eps);
    if (peer.v_world.allFinite())
      u += c.c2_alpha * bump(zs / r_alpha, c.h_alpha) * (peer.v_world - p);
  }

  for (const law::Ray& ray : o.rays) {
    if (!ray.hit || !std::isfinite(ray.range_m) || ray.range_m >= r_obst) continue;
    const double range = std::max(ray.range_m, 0.0);
    const double cp = std::cos(ray.pitch_body_rad);
    const Eigen::Vector3d dir = o.q_world_body * Eigen::Vector3d(cp * std::cos(ray.yaw_body_rad),
                                                                 cp * std::sin(ray.yaw_body_rad),
                                                                 std::sin(ray.pitch_body_rad));
    const double zs = sigma_norm(range, eps);
    u += c.c1_beta * phi_beta(zs, d_beta, c.h_beta) * sigma_gradient(range * dir, eps);
    // p̂ − p = (I − u uᵀ) p − p = −(u·p) u for the wall normal to the ray.
    u -= c.c2_beta * bump(zs / d_beta, c.h_beta) * dir.dot(p) * dir;
  }

  u -= c.c2_gamma * (p - o.mission_velocity);
  if (o.goal_world.allFinite()) {
    const Eigen::Vector3d e = q - o.goal_world;
    u -= c.c1_gamma * (c.gamma_sigma1 ? Eigen::Vector3d(e / std::sqrt(1.0 + e.squaredNorm())) : e);
  }
  u.z() = 0;
  return u;
}

namespace {

class OlfatiSaberLaw final : public law::SwarmLaw {
 public:
  explicit OlfatiSaberLaw(const OlfatiSaberConfig& c) : c_(c) {}

  law::Command step(const law::Observation& o) override {
    if (!started_ || o.tick != last_tick_ + 1)
      v_c_ = Eigen::Vector3d(o.v_world.x(), o.v_world.y(), 0);
    started_ = true;
    last_tick_ = o.tick;
    v_c_ += olfati_saber_acceleration(o, v_c_, c_) * o.dt_s;
    const double speed = v_c_.norm();
    if (speed > o.max_speed_mps) v_c_ *= o.max_speed_mps / speed;
    law::Command cmd;
    cmd.velocity_world = Eigen::Vector3d(v_c_.x(), v_c_.y(), o.mission_velocity.z());
    return cmd;
  }

  bool uses_obstacle_term() const override { return false; }

 private:
  OlfatiSaberConfig c_;
  Eigen::Vector3d v_c_ = Eigen::Vector3d::Zero();  ///< m/s, horizontal: the integrator's p_i
  std::uint64_t last_tick_ = 0;
  bool started_ = false;
};

}  // namespace

std::unique_ptr<law::SwarmLaw> make_olfati_saber(law::Params& p, law::Rng /*rng*/,
                                                 const law::LawContext& /*ctx*/) {
  return std::make_unique<OlfatiSaberLaw>(olfati_saber_config(p));
}

}  // namespace ddswarm::agent::laws
