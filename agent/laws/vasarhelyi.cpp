#include "vasarhelyi.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <utility>

namespace ddswarm::agent::laws {

namespace vasarhelyi {

namespace {

/// |v| below this has no direction (m/s).
constexpr double kTinySpeedMps = 1e-3;
/// A ray whose world direction has a horizontal part below this (about 6°
/// from vertical) sees no horizontal obstacle.
constexpr double kMinHorizontal = 0.1;

bool finite2(const Eigen::Vector2d& v) { return std::isfinite(v.x()) && std::isfinite(v.y()); }

}  // namespace

Config scaled(const Config& c, double length_scale, double speed_scale) {
  const double s = length_scale, k = speed_scale;
  const double rate = k / s, accel = k * k / s;
  Config out = c;
  out.r0_rep_m = c.r0_rep_m * s;
  out.p_rep = c.p_rep * rate;
  // The alignment's braking curve keeps its lengths (length scale 1): see
  // "Scaling" in the header.
  out.v_frict_mps = c.v_frict_mps * k;
  out.p_frict = c.p_frict * k;
  out.a_frict = c.a_frict * k * k;
  out.r0_shill_m = c.r0_shill_m * s;
  out.v_shill_mps = c.v_shill_mps * k;
  out.p_shill = c.p_shill * rate;
  out.a_shill = c.a_shill * accel;
  return out;
}

double braking_curve(double r_m, double a, double p) {
  if (!(r_m > 0)) return 0.0;  // also NaN
  const double linear = r_m * p;
  if (linear < a / p) return linear;
  return std::sqrt(2.0 * a * r_m - a * a / (p * p));
}

Eigen::Vector2d repulsion(const Eigen::Vector2d& r_i, const Eigen::Vector2d& r_j, const Config& c) {
  const Eigen::Vector2d d = r_i - r_j;
  const double r = d.norm();
  if (!(r < c.r0_rep_m) || r < 1e-9) return Eigen::Vector2d::Zero();
  return c.p_rep * (c.r0_rep_m - r) * d / r;
}

Eigen::Vector2d friction(const Eigen::Vector2d& r_i, const Eigen::Vector2d& v_i,
                         const Eigen::Vector2d& r_j, const Eigen::Vector2d& v_j, const Config& c) {
  const Eigen::Vector2d dv = v_j - v_i;
  const double v_ij = dv.norm();
  const double r_ij = (r_i - r_j).norm();
  const double allowed =
      std::max(c.v_frict_mps, braking_curve(r_ij - c.r0_frict_m, c.a_frict, c.p_frict));
  if (!(v_ij > allowed)) return Eigen::Vector2d::Zero();
  return c.c_frict * (v_ij - allowed) * dv / v_ij;
}

Eigen::Vector2d shill(const Eigen::Vector2d& v_i, const Eigen::Vector2d& toward_obstacle,
                      double r_is_m, const Config& c) {
  const Eigen::Vector2d dv = -c.v_shill_mps * toward_obstacle - v_i;
  const double v_is = dv.norm();
  const double allowed = braking_curve(r_is_m - c.r0_shill_m, c.a_shill, c.p_shill);
  if (!(v_is > allowed)) return Eigen::Vector2d::Zero();
  return c.c_shill * (v_is - allowed) * dv / v_is;
}

std::vector<ShillAgent> shill_agents(std::span<const law::Ray> rays,
                                     const Eigen::Quaterniond& q_world_body, ShillAgents mode) {
  struct Entry {
    double azimuth;
    double range;  // horizontal m; +inf for a miss
    Eigen::Vector2d dir;
  };
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<Entry> ring;
  ring.reserve(rays.size());
  for (const auto& ray : rays) {
    const double cp = std::cos(ray.pitch_body_rad);
    const Eigen::Vector3d body(cp * std::cos(ray.yaw_body_rad), cp * std::sin(ray.yaw_body_rad),
                               std::sin(ray.pitch_body_rad));
    const Eigen::Vector3d world = q_world_body * body;
    const Eigen::Vector2d h = world.head<2>();
    const double n = h.norm();
    if (!(n >= kMinHorizontal)) continue;
    double range = kInf;
    if (ray.hit && !std::isnan(ray.range_m)) range = std::max(ray.range_m, 0.0) * n;
    ring.push_back({std::atan2(h.y(), h.x()), range, h / n});
  }
  std::stable_sort(ring.begin(), ring.end(),
                   [](const Entry& a, const Entry& b) { return a.azimuth < b.azimuth; });

  std::vector<ShillAgent> out;
  const std::size_t n = ring.size();
  auto add = [&](const Entry& e) { out.push_back({e.dir, e.range}); };
  if (mode == ShillAgents::kEveryRay || n == 1) {
    for (const auto& e : ring)
      if (std::isfinite(e.range)) add(e);
    return out;
  }
  bool any_hit = false;
  for (std::size_t k = 0; k < n; ++k) {
    const double r = ring[k].range;
    if (!std::isfinite(r)) continue;
    any_hit = true;
    const double prev = ring[(k + n - 1) % n].range, next = ring[(k + 1) % n].range;
    // Strict on one side, so a plateau of equal ranges gives one agent.
    if (r < prev && r <= next) add(ring[k]);
  }
  if (any_hit && out.empty()) {
    // Every ray equally far (a drone inside a ring): each is a nearest point.
    for (const auto& e : ring)
      if (std::isfinite(e.range)) add(e);
  }
  return out;
}

Eigen::Vector2d self_propulsion(const Eigen::Vector2d& v_i, const Eigen::Vector3d& mission_velocity,
                                law::Phase phase, const Config& c) {
  const Eigen::Vector2d m = mission_velocity.head<2>();
  if (finite2(m) && m.norm() > 0) return m;
  if (c.propulsion != Propulsion::kHeading || phase == law::Phase::kLanding)
    return Eigen::Vector2d::Zero();
  const double speed = v_i.norm();
  if (!(speed >= kTinySpeedMps)) return Eigen::Vector2d::Zero();
  return c.v_flock_mps * v_i / speed;
}

Eigen::Vector2d slide(const Eigen::Vector2d& propulsion, const Eigen::Vector2d& toward_obstacle) {
  const double blocked = propulsion.dot(toward_obstacle);
  if (!(blocked > 0)) return propulsion;
  // The side the propulsion leans to; left of the obstacle when dead centre.
  const double side = toward_obstacle.x() * propulsion.y() - toward_obstacle.y() * propulsion.x();
  const Eigen::Vector2d left(-toward_obstacle.y(), toward_obstacle.x());
  const Eigen::Vector2d tangent = side < 0 ? Eigen::Vector2d(-left) : left;
  return propulsion - blocked * toward_obstacle + blocked * tangent;
}

Terms evaluate(const law::Observation& o, const Config& c) {
  Terms t;
  const Eigen::Vector2d r_i = o.p_world.head<2>();
  Eigen::Vector2d v_i = o.v_world.head<2>();
  if (!finite2(v_i)) v_i.setZero();
  t.propulsion = self_propulsion(v_i, o.mission_velocity, o.phase, c);
  for (const auto& peer : o.peers) {
    const Eigen::Vector2d r_j = peer.p_world.head<2>();
    if (!finite2(r_j)) continue;
    t.repulsion += repulsion(r_i, r_j, c);
    const Eigen::Vector2d v_j = peer.v_world.head<2>();
    if (finite2(v_j)) t.friction += friction(r_i, v_i, r_j, v_j, c);
  }
  const ShillAgent* strongest = nullptr;
  double strongest_mps = 0;
  const std::vector<ShillAgent> agents = shill_agents(o.rays, o.q_world_body, c.shill_agents);
  for (const auto& s : agents) {
    const Eigen::Vector2d term = shill(v_i, s.toward_obstacle, s.distance_m, c);
    t.shill += term;
    if (term.norm() > strongest_mps) {
      strongest_mps = term.norm();
      strongest = &s;
    }
  }
  const Eigen::Vector2d m = o.mission_velocity.head<2>();
  if (c.slide && strongest && finite2(m) && m.norm() > 0)
    t.propulsion = slide(t.propulsion, strongest->toward_obstacle);

  t.velocity = t.propulsion + t.repulsion + t.friction + t.shill;
  const double v_max = std::max(0.0, std::min(c.v_max_mps, o.max_speed_mps));
  const double speed = t.velocity.norm();
  if (speed > v_max) t.velocity *= v_max / speed;
  return t;
}

}  // namespace vasarhelyi

namespace {

using vasarhelyi::Config;

std::string text(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

class VasarhelyiLaw final : public law::SwarmLaw {
 public:
  /// paper: the unscaled set with v_flock, v_max and the choices in force;
  /// length_scale: s, or nullopt to follow D_int; overrides: the values
  /// given explicitly, applied after scaling.
  VasarhelyiLaw(Config paper, double speed_scale, std::optional<double> length_scale,
                double d_int_m, std::vector<std::pair<double Config::*, double>> overrides)
      : paper_(paper),
        speed_scale_(speed_scale),
        length_scale_(length_scale),
        d_int_m_(d_int_m),
        overrides_(std::move(overrides)) {}

  law::Command step(const law::Observation& o) override {
    const double d_int = o.inter_distance_m > 0 ? o.inter_distance_m : d_int_m_;
    const double s = length_scale_.value_or(d_int / vasarhelyi::kPaperSpacingM);
    if (!config_ || s != config_s_) {
      Config c = vasarhelyi::scaled(paper_, s, speed_scale_);
      for (const auto& [field, value] : overrides_) c.*field = value;
      config_ = c;
      config_s_ = s;
    }
    const vasarhelyi::Terms t = vasarhelyi::evaluate(o, *config_);
    law::Command cmd;
    const double vz = std::isfinite(o.mission_velocity.z()) ? o.mission_velocity.z() : 0.0;
    cmd.velocity_world = Eigen::Vector3d(t.velocity.x(), t.velocity.y(), vz);
    return cmd;
  }

  bool uses_obstacle_term() const override { return false; }

 private:
  Config paper_;
  double speed_scale_;
  std::optional<double> length_scale_;
  double d_int_m_;
  std::vector<std::pair<double Config::*, double>> overrides_;
  std::optional<Config> config_;  // the scaled set for config_s_
  double config_s_ = 0;
};

}  // namespace

std::unique_ptr<law::SwarmLaw> make_vasarhelyi(law::Params& p, law::Rng /*rng*/,
                                               const law::LawContext& ctx) {
  const Config paper_set;
  const double d_int = ctx.inter_distance_m > 0 ? ctx.inter_distance_m : 4.0;
  const double max_speed = ctx.max_speed_mps > 0 ? ctx.max_speed_mps : 3.0;

  const bool scale_given = p.has("scale");
  const double s = p.number("scale", d_int / vasarhelyi::kPaperSpacingM, 0.001, 100);
  Config paper = paper_set;
  paper.v_flock_mps =
      p.number("v_flock_mps", std::min(vasarhelyi::kPaperVFlockMps, max_speed), 0.1, 50);
  paper.v_max_mps = p.number("v_max_mps", max_speed, 0.1, 50);
  if (paper.v_flock_mps > paper.v_max_mps)
    throw law::ParamError(p.prefix() + ".v_flock_mps", text(paper.v_flock_mps),
                          "must be <= v_max_mps (" + text(paper.v_max_mps) + ")");
  const double k = paper.v_flock_mps / vasarhelyi::kPaperVFlockMps;
  const Config shown = vasarhelyi::scaled(paper, s, k);  // the defaults at D_int in ctx

  struct Field {
    const char* key;
    double Config::*member;
    double lo, hi;
  };
  const Field fields[] = {
      {"r0_rep_m", &Config::r0_rep_m, 0, 1000},      {"p_rep", &Config::p_rep, 0, 100},
      {"r0_frict_m", &Config::r0_frict_m, 0, 1000},  {"c_frict", &Config::c_frict, 0, 10},
      {"v_frict_mps", &Config::v_frict_mps, 0, 50},  {"p_frict", &Config::p_frict, 0.001, 1000},
      {"a_frict", &Config::a_frict, 0.001, 1000},    {"r0_shill_m", &Config::r0_shill_m, -100, 100},
      {"v_shill_mps", &Config::v_shill_mps, 0, 100}, {"p_shill", &Config::p_shill, 0.001, 1000},
      {"a_shill", &Config::a_shill, 0.001, 1000},    {"c_shill", &Config::c_shill, 0, 10},
  };
  std::vector<std::pair<double Config::*, double>> overrides;
  for (const auto& f : fields) {
    const bool given = p.has(f.key);
    const double v = p.number(f.key, shown.*(f.member), f.lo, f.hi);
    if (given) overrides.emplace_back(f.member, v);
  }
  paper.propulsion = p.choice("self_propulsion", "mission", {"mission", "heading"}) == "heading"
                         ? vasarhelyi::Propulsion::kHeading
                         : vasarhelyi::Propulsion::kMission;
  paper.shill_agents = p.choice("shill_agents", "nearest", {"nearest", "every_ray"}) == "every_ray"
                           ? vasarhelyi::ShillAgents::kEveryRay
                           : vasarhelyi::ShillAgents::kNearest;
  paper.slide = p.flag("slide", true);
  p.finish();
  return std::make_unique<VasarhelyiLaw>(
      paper, k, scale_given ? std::optional<double>(s) : std::nullopt, d_int, std::move(overrides));
}

}  // namespace ddswarm::agent::laws
