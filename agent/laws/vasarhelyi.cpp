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
/// The slide: a propulsion within this sine (about 1°) of the obstacle's
/// direction is dead centre.
constexpr double kDeadCentre = 0.02;

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

Config scaled(const Config& c, double length_scale, double speed_scale, double shill_speed_scale,
              double shill_scale) {
  Config out = scaled(c, length_scale, speed_scale);
  const Config shill = scaled(c, length_scale * shill_scale, shill_speed_scale);
  out.r0_shill_m = shill.r0_shill_m;
  out.v_shill_mps = shill.v_shill_mps;
  out.p_shill = shill.p_shill;
  out.a_shill = shill.a_shill;
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

int slide_side(const Eigen::Vector2d& propulsion, const Eigen::Vector2d& toward_obstacle, int tie) {
  const Eigen::Vector2d left(-toward_obstacle.y(), toward_obstacle.x());
  const double lean = left.dot(propulsion);
  if (!(std::abs(lean) > kDeadCentre * propulsion.norm())) return tie < 0 ? -1 : 1;
  return lean < 0 ? -1 : 1;
}

Eigen::Vector2d slide(const Eigen::Vector2d& propulsion, const Eigen::Vector2d& toward_obstacle,
                      int side, double amount) {
  const double blocked = propulsion.dot(toward_obstacle);
  if (!(blocked > 0)) return propulsion;
  const double c = std::clamp(std::isnan(amount) ? 0.0 : amount, 0.0, blocked);
  const Eigen::Vector2d left(-toward_obstacle.y(), toward_obstacle.x());
  const Eigen::Vector2d tangent = side < 0 ? Eigen::Vector2d(-left) : left;
  return propulsion - c * toward_obstacle + c * tangent;
}

Eigen::Vector2d slide(const Eigen::Vector2d& propulsion, const Eigen::Vector2d& toward_obstacle) {
  return slide(propulsion, toward_obstacle, slide_side(propulsion, toward_obstacle, 1),
               propulsion.dot(toward_obstacle));
}

Terms evaluate(const law::Observation& o, const Config& c, SlideMemory* memory) {
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
  Eigen::Vector2d strongest_term(0, 0);
  const std::vector<ShillAgent> agents = shill_agents(o.rays, o.q_world_body, c.shill_agents);
  for (const auto& s : agents) {
    const Eigen::Vector2d term = shill(v_i, s.toward_obstacle, s.distance_m, c);
    t.shill += term;
    if (term.norm() > strongest_term.norm()) {
      strongest_term = term;
      strongest = &s;
    }
  }
  const Eigen::Vector2d m = o.mission_velocity.head<2>();
  const bool propelled = finite2(m) && m.norm() > 0;
  if (c.slide && strongest && propelled) {
    const Eigen::Vector2d& u = strongest->toward_obstacle;
    // The part of the propulsion the agent cancels.
    const double cancelled = std::min(t.propulsion.dot(u), -strongest_term.dot(u));
    if (cancelled > 0) {
      // Dead centre: the side kept from the last second, else the goal's, else left.
      int tie = 1;
      if (memory && memory->side != 0 && o.sim_time_s - memory->time_s <= kSlideMemoryS) {
        tie = memory->side;
      } else {
        const Eigen::Vector2d to_goal = o.goal_world.head<2>() - r_i;
        if (finite2(to_goal) && to_goal.norm() > 0) tie = slide_side(to_goal, u, 1);
      }
      const int side = slide_side(t.propulsion, u, tie);
      t.propulsion = slide(t.propulsion, u, side, cancelled);
      if (memory) *memory = {side, o.sim_time_s};
    }
  }

  t.velocity = t.propulsion + t.repulsion + t.friction + t.shill;
  const double v_max = std::max(0.0, std::min(c.v_max_mps, o.max_speed_mps));
  const double speed = t.velocity.norm();
  if (speed > v_max) t.velocity *= v_max / speed;
  // Speed: never slower than the mission while heading forward.
  const double floor = propelled ? std::min(v_max, m.norm()) : 0.0;
  if (c.keep_speed && speed > 0 && speed < floor && t.velocity.dot(m) > 0)
    t.velocity *= floor / speed;
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
  /// speed_scale: k; shill_scale: the shill set's length factor;
  /// length_scale: s, or nullopt to follow D_int; overrides: the values
  /// given explicitly, applied after scaling.
  VasarhelyiLaw(Config paper, double speed_scale, double shill_scale,
                std::optional<double> length_scale, double d_int_m,
                std::vector<std::pair<double Config::*, double>> overrides)
      : paper_(paper),
        speed_scale_(speed_scale),
        shill_scale_(shill_scale),
        length_scale_(length_scale),
        d_int_m_(d_int_m),
        overrides_(std::move(overrides)) {}

  law::Command step(const law::Observation& o) override {
    const double d_int = o.inter_distance_m > 0 ? o.inter_distance_m : d_int_m_;
    const double s = length_scale_.value_or(d_int / vasarhelyi::kPaperSpacingM);
    const double k_shill = paper_.shill_speed == vasarhelyi::ShillSpeed::kPropulsion
                               ? propulsion_speed(o) / vasarhelyi::kPaperVFlockMps
                               : speed_scale_;
    if (!config_ || s != config_s_ || k_shill != config_k_shill_) {
      Config c = vasarhelyi::scaled(paper_, s, speed_scale_, k_shill, shill_scale_);
      for (const auto& [field, value] : overrides_) c.*field = value;
      config_ = c;
      config_s_ = s;
      config_k_shill_ = k_shill;
    }
    const vasarhelyi::Terms t = vasarhelyi::evaluate(o, *config_, &slide_memory_);
    law::Command cmd;
    const double vz = std::isfinite(o.mission_velocity.z()) ? o.mission_velocity.z() : 0.0;
    cmd.velocity_world = Eigen::Vector3d(t.velocity.x(), t.velocity.y(), vz);
    return cmd;
  }

  bool uses_obstacle_term() const override { return false; }

 private:
  /// v_p (m/s, "Shill agents' speed" in the header): the mission's
  /// horizontal speed; in a gathering the larger of it and the last cruise
  /// speed; v_flock without a mission velocity; in [0.1 m/s, v_max].
  double propulsion_speed(const law::Observation& o) {
    const Eigen::Vector2d m = o.mission_velocity.head<2>();
    const double mission = std::isfinite(m.x()) && std::isfinite(m.y()) ? m.norm() : 0.0;
    double v = paper_.v_flock_mps;
    if (mission > 0 && o.phase == law::Phase::kSwarm) {
      v = std::max(mission, cruise_mps_);
    } else if (mission > 0) {
      v = mission;
      cruise_mps_ = mission;
    }
    return std::clamp(v, vasarhelyi::kMinPropulsionMps,
                      std::max(vasarhelyi::kMinPropulsionMps, paper_.v_max_mps));
  }

  Config paper_;
  double speed_scale_;
  double shill_scale_;
  std::optional<double> length_scale_;
  double d_int_m_;
  std::vector<std::pair<double Config::*, double>> overrides_;
  std::optional<Config> config_;  // the scaled set for config_s_ and config_k_shill_
  double config_s_ = 0, config_k_shill_ = 0;
  double cruise_mps_ = 0;  // m/s, the last mission speed outside a gathering
  vasarhelyi::SlideMemory slide_memory_;
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
  const double shill_scale = p.number("shill_scale", 1.0, 0.05, 20);
  // The defaults at D_int in ctx (the shill set as in hold: k_s = k).
  const Config shown = vasarhelyi::scaled(paper, s, k, k, shill_scale);

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
  paper.shill_speed = p.choice("shill_speed", "propulsion", {"propulsion", "v_flock"}) == "v_flock"
                          ? vasarhelyi::ShillSpeed::kVFlock
                          : vasarhelyi::ShillSpeed::kPropulsion;
  paper.keep_speed = p.flag("keep_speed", true);
  p.finish();
  return std::make_unique<VasarhelyiLaw>(paper, k, shill_scale,
                                         scale_given ? std::optional<double>(s) : std::nullopt,
                                         d_int, std::move(overrides));
}

}  // namespace ddswarm::agent::laws
