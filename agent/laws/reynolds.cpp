#include "reynolds.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>

namespace ddswarm::agent::laws {
namespace {

constexpr double kSamePointM = 1e-9;  // closer peers have no direction

Eigen::Vector3d cap(const Eigen::Vector3d& x, double max_len) {
  const double n = x.norm();
  if (max_len <= 0) return Eigen::Vector3d::Zero();
  return n > max_len ? Eigen::Vector3d(x * (max_len / n)) : x;
}

std::string text(double v) {
  std::string s = std::to_string(v);
  while (s.size() > 1 && s.back() == '0') s.pop_back();
  if (!s.empty() && s.back() == '.') s.pop_back();
  return s;
}

class ReynoldsLaw final : public law::SwarmLaw {
 public:
  explicit ReynoldsLaw(const ReynoldsConfig& c) : c_(c) {}
  law::Command step(const law::Observation& o) override {
    law::Command cmd;
    cmd.velocity_world = reynolds_terms(o, c_).velocity;
    return cmd;
  }

 private:
  ReynoldsConfig c_;
};

}  // namespace

bool in_neighbourhood(const Eigen::Vector3d& offset, const Eigen::Vector3d& v_world,
                      const Neighbourhood& n) {
  if (!offset.allFinite()) return false;
  const double d = offset.norm();
  if (n.radius_m > 0 && d > n.radius_m) return false;
  const double speed = v_world.norm();
  if (n.fov_deg >= 360.0 || !(speed >= kReynoldsHeadingMinMps) || d < kSamePointM) return true;
  const double cos_half = std::cos(n.fov_deg * std::numbers::pi / 360.0);
  return offset.dot(v_world) >= cos_half * d * speed;
}

Eigen::Vector3d separation(const Eigen::Vector3d& p_world, std::span<const law::Peer> peers,
                           double separation_m, double gain_per_s) {
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  for (const auto& q : peers) {
    const Eigen::Vector3d away = p_world - q.p_world;
    if (!away.allFinite()) continue;
    const double d = away.norm();
    if (d < kSamePointM || d >= separation_m) continue;
    s += separation_m * (separation_m / d - 1.0) * (away / d);
  }
  return gain_per_s * s;
}

Eigen::Vector3d alignment(const Eigen::Vector3d& p_world, const Eigen::Vector3d& v_world,
                          std::span<const law::Peer> peers, const Neighbourhood& n, double gain) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
  for (const auto& q : peers) {
    if (!q.v_world.allFinite() || !in_neighbourhood(q.p_world - p_world, v_world, n)) continue;
    sum += q.v_world;
    ++count;
  }
  if (count == 0) return Eigen::Vector3d::Zero();
  return gain * (sum / count - v_world);
}

Eigen::Vector3d cohesion(const Eigen::Vector3d& p_world, const Eigen::Vector3d& v_world,
                         std::span<const law::Peer> peers, const Neighbourhood& n,
                         double gain_per_s) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
  for (const auto& q : peers) {
    const Eigen::Vector3d offset = q.p_world - p_world;
    if (!in_neighbourhood(offset, v_world, n)) continue;
    sum += offset;  // relative offsets: no loss of precision far from the origin
    ++count;
  }
  if (count == 0) return Eigen::Vector3d::Zero();
  return gain_per_s * (sum / count);
}

Eigen::Vector3d allocate_by_priority(std::span<const Eigen::Vector3d> terms, double budget_mps) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double left = budget_mps;
  for (const auto& t : terms) {
    if (left <= 0) break;
    const Eigen::Vector3d part = cap(t, left);
    sum += part;
    left -= part.norm();
  }
  return sum;
}

ReynoldsTerms reynolds_terms(const law::Observation& o, const ReynoldsConfig& c) {
  const double d_int = o.inter_distance_m;
  const Neighbourhood n{c.radius_m < 0 ? kReynoldsRadiusFactor * d_int : c.radius_m, c.fov_deg};
  const double r_s = c.separation_m > 0 ? c.separation_m : d_int;

  ReynoldsTerms t;
  t.separation = separation(o.p_world, o.peers, r_s, c.separation_gain);
  t.alignment = alignment(o.p_world, o.v_world, o.peers, n, c.alignment_gain);
  t.cohesion = cohesion(o.p_world, o.v_world, o.peers, n, c.cohesion_gain);

  t.reference = o.mission_velocity;
  const Eigen::Vector3d relative = o.v_world - o.mission_velocity;
  // Below 1 mm/s the heading is noise: the drone waits for steering to pick one.
  if (c.cruise_speed_mps > 0 && relative.norm() > 1e-3)
    t.reference += c.cruise_speed_mps * relative.normalized();

  Eigen::Vector3d steer;
  if (c.priority) {
    const std::array<Eigen::Vector3d, 3> by_precedence{t.separation, t.alignment, t.cohesion};
    steer = allocate_by_priority(by_precedence, c.max_term_mps);
  } else {
    steer = cap(t.separation, c.max_term_mps) + cap(t.alignment, c.max_term_mps) +
            cap(t.cohesion, c.max_term_mps);
  }
  t.velocity = cap(t.reference + steer, o.max_speed_mps);
  return t;
}

std::unique_ptr<law::SwarmLaw> make_reynolds(law::Params& p, law::Rng /*rng*/,
                                             const law::LawContext& ctx) {
  ReynoldsConfig c;
  const bool radius_set = p.has("radius_m");
  const bool separation_set = p.has("separation_m");
  c.radius_m = p.number("radius_m", -1, 0, 1000);
  c.separation_m = p.number("separation_m", 0, 0, 1000);
  c.separation_gain = p.number("separation_gain", c.separation_gain, 0, 100);
  c.alignment_gain = p.number("alignment_gain", c.alignment_gain, 0, 20);
  c.cohesion_gain = p.number("cohesion_gain", c.cohesion_gain, 0, 10);
  c.fov_deg = p.number("fov_deg", c.fov_deg, 1, 360);
  const std::string field = p.prefix() + ".";
  c.max_term_mps = p.number("max_term_mps", c.max_term_mps, 0, 20);
  if (c.max_term_mps <= 0)
    throw law::ParamError(field + "max_term_mps", p.values().at("max_term_mps"), "must be > 0");
  c.cruise_speed_mps = p.number("cruise_speed_mps", c.cruise_speed_mps, 0, 20);
  c.priority = p.choice("combine", "priority", {"priority", "sum"}) == "priority";

  const double d_int = ctx.inter_distance_m;
  const double radius = radius_set ? c.radius_m : kReynoldsRadiusFactor * d_int;
  const double sep = c.separation_m > 0 ? c.separation_m : d_int;
  if (radius > 0 && sep >= radius) {
    if (separation_set && c.separation_m > 0) {
      throw law::ParamError(field + "separation_m", p.values().at("separation_m"),
                            "must be < the neighbourhood radius (radius_m = " + text(radius) +
                                (radius_set ? ")" : ", 2.5 * D_int)"));
    }
    throw law::ParamError(field + "radius_m", p.values().at("radius_m"),
                          "must be > the separation distance (D_int = " + text(d_int) + " m) or 0");
  }
  p.finish();
  return std::make_unique<ReynoldsLaw>(c);
}

}  // namespace ddswarm::agent::laws
