#include "olfati_saber.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

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
  c.beta_slide = p.number("beta_slide", c.beta_slide, 0.0, 10.0);
  p.finish();
  return c;
}

namespace {

constexpr double kMaxNeighbourGapRad = std::numbers::pi / 3 + 1e-9;  ///< 60°
constexpr double kMinHorizontal = 0.5;  ///< cos 60°: steeper rays are not the ring's
constexpr double kMaxSphereRadiusM = 100.0;
constexpr double kSlideCommitMps = 0.05;  ///< m/s along the surface that picks the slide's side

/// One ray of the scan, in the horizontal plane relative to the drone.
struct Hit {
  double pitch = 0, yaw = 0;  ///< rad, body: the ring and the place in it
  Eigen::Vector2d u{0, 0};    ///< world horizontal unit direction
  Eigen::Vector2d w{0, 0};    ///< m, hit point − q_i (horizontal)
  bool hit = false;
};

Eigen::Vector2d normal_toward_drone(const Eigen::Vector2d& chord, const Eigen::Vector2d& w) {
  Eigen::Vector2d a(-chord.y(), chord.x());
  a.normalize();
  return a.dot(w) > 0 ? Eigen::Vector2d(-a) : a;
}

}  // namespace

std::vector<Obstacle> obstacles_from_rays(const law::Observation& o) {
  std::vector<Hit> rays;
  rays.reserve(o.rays.size());
  for (const law::Ray& ray : o.rays) {
    if (!std::isfinite(ray.yaw_body_rad) || !std::isfinite(ray.pitch_body_rad)) continue;
    const double cp = std::cos(ray.pitch_body_rad);
    const Eigen::Vector3d dir = o.q_world_body * Eigen::Vector3d(cp * std::cos(ray.yaw_body_rad),
                                                                 cp * std::sin(ray.yaw_body_rad),
                                                                 std::sin(ray.pitch_body_rad));
    const Eigen::Vector2d h = dir.head<2>();
    if (h.norm() < kMinHorizontal) continue;
    Hit r;
    r.pitch = ray.pitch_body_rad;
    r.yaw = std::remainder(ray.yaw_body_rad, 2 * std::numbers::pi);
    r.u = h.normalized();
    r.hit = ray.hit && std::isfinite(ray.range_m);
    r.w = r.hit ? Eigen::Vector2d(std::max(ray.range_m, 0.0) * h) : Eigen::Vector2d::Zero();
    rays.push_back(r);
  }
  // Rings: by pitch, then yaw.
  std::sort(rays.begin(), rays.end(), [](const Hit& a, const Hit& b) {
    return a.pitch != b.pitch ? a.pitch < b.pitch : a.yaw < b.yaw;
  });

  const Eigen::Vector2d q = o.p_world.head<2>();
  std::vector<Obstacle> out;
  std::size_t begin = 0;
  while (begin < rays.size()) {
    std::size_t end = begin + 1;
    while (end < rays.size() && rays[end].pitch == rays[begin].pitch) ++end;
    const std::size_t n = end - begin;
    auto at = [&](std::size_t i) -> const Hit& { return rays[begin + i % n]; };
    // The neighbour of ring place i on side s (−1, +1) when it hit the same obstacle.
    auto neighbour = [&](std::size_t i, int s) -> const Hit* {
      if (n < 3) return nullptr;
      const Hit& h = at(i);
      const Hit& m = at(s > 0 ? i + 1 : i + n - 1);
      if (!m.hit) return nullptr;
      const double gap = std::abs(std::remainder(m.yaw - h.yaw, 2 * std::numbers::pi));
      if (gap > kMaxNeighbourGapRad) return nullptr;
      const double chord = 2 * std::max(h.w.norm(), m.w.norm()) * std::sin(gap / 2);
      return (m.w - h.w).norm() <= 1.5 * chord ? &m : nullptr;
    };
    for (std::size_t i = 0; i < n; ++i) {
      const Hit& h = at(i);
      if (!h.hit) continue;
      const double s = h.w.norm();
      const Hit* prev = neighbour(i, -1);
      const Hit* next = neighbour(i, +1);
      // The local minimum: no neighbour nearer; of equal ones, the first in the ring.
      auto beats = [&](const Hit* m, bool m_first) {
        return m && (m->w.norm() < s || (m->w.norm() == s && m_first));
      };
      if (beats(prev, i > 0) || beats(next, i + 1 == n)) continue;

      Obstacle k;
      k.y = q + h.w;
      k.a = -h.u;
      if (prev && next) {
        // The circle through the three hits, relative to the middle one.
        const Eigen::Vector2d A = prev->w - h.w, C = next->w - h.w;
        const double det = 2 * (A.x() * C.y() - A.y() * C.x());
        bool sphere = false;
        if (std::abs(det) > 1e-12) {
          const Eigen::Vector2d c((C.y() * A.squaredNorm() - A.y() * C.squaredNorm()) / det,
                                  (A.x() * C.squaredNorm() - C.x() * A.squaredNorm()) / det);
          const Eigen::Vector2d centre = h.w + c;  // relative to q_i
          const double R = c.norm(), dist = centre.norm();
          // Convex toward the drone: the middle hit on the circle's near half.
          if (R <= kMaxSphereRadiusM && dist > R && c.dot(centre) > 0) {
            sphere = true;
            k.sphere = true;
            k.y = q + centre;
            k.radius_m = std::max(R, dist - s);  // q̂ no farther than the nearest hit
            k.a = -centre / dist;
          }
        }
        if (!sphere) k.a = normal_toward_drone(next->w - prev->w, h.w);
      } else if (prev || next) {
        k.a = normal_toward_drone((prev ? prev : next)->w - h.w, h.w);
      }
      if (!k.sphere && !k.a.allFinite()) k.a = -h.u;
      out.push_back(k);
    }
    begin = end;
  }
  return out;
}

BetaAgent beta_agent(const Obstacle& k, const Eigen::Vector2d& q, const Eigen::Vector2d& p) {
  BetaAgent b;
  if (k.sphere) {
    const Eigen::Vector2d e = q - k.y;
    const double dist = e.norm();
    const double mu = k.radius_m / dist;
    b.a = e / dist;
    const Eigen::Matrix2d P = Eigen::Matrix2d::Identity() - b.a * b.a.transpose();
    b.q = mu * q + (1 - mu) * k.y;
    b.p = mu * P * p;
  } else {
    b.a = k.a;
    const Eigen::Matrix2d P = Eigen::Matrix2d::Identity() - b.a * b.a.transpose();
    b.q = P * q + (Eigen::Matrix2d::Identity() - P) * k.y;
    b.p = P * p;
  }
  return b;
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

  const Eigen::Vector2d q2 = q.head<2>(), p2 = p.head<2>();
  const Eigen::Vector2d p_r = o.mission_velocity.head<2>();
  for (const Obstacle& k : obstacles_from_rays(o)) {
    const BetaAgent beta = beta_agent(k, q2, p2);
    const Eigen::Vector3d z(beta.q.x() - q2.x(), beta.q.y() - q2.y(), 0);
    if (z.norm() >= r_obst) continue;
    const double zs = sigma_norm(z.norm(), eps);
    Eigen::Vector2d p_hat = beta.p;
    const double into = c.beta_slide * std::max(0.0, -p_r.dot(beta.a));
    if (into > 0) {
      Eigen::Vector2d t(-beta.a.y(), beta.a.x());  // a_k turned +90°
      const double own = t.dot(p2), lean = t.dot(p_r);
      if (own < -kSlideCommitMps || (std::abs(own) <= kSlideCommitMps && lean < -1e-3 * p_r.norm()))
        t = -t;
      p_hat += std::max(0.0, into - t.dot(p_hat)) * t;
    }
    u += c.c1_beta * phi_beta(zs, d_beta, c.h_beta) * sigma_gradient(z, eps);
    const Eigen::Vector2d dv = c.c2_beta * bump(zs / d_beta, c.h_beta) * (p_hat - p2);
    u += Eigen::Vector3d(dv.x(), dv.y(), 0);
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
