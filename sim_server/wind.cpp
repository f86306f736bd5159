#include "sim_server/wind.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <string>

#include "common/config_error.hpp"

namespace ddswarm::sim {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kFt = 0.3048;  // m per foot

std::uint64_t splitmix(std::uint64_t& s) {
  std::uint64_t z = (s += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}
/// (0, 1): its own draw, so the wind is the same on every standard library.
double unit(std::uint64_t& s) { return (static_cast<double>(splitmix(s) >> 11) + 0.5) * 0x1.0p-53; }

/// A wavenumber (rad/m) drawn from the density proportional to the Dryden
/// spectrum of length scale L: longitudinal 1 / (1 + (L W)^2) (a Cauchy law,
/// drawn exactly), transverse (1 + 12 (L W)^2) / (1 + 4 (L W)^2)^2 (drawn by
/// rejection from the Cauchy law of scale L / 2, whose density bounds it 3 times).
double dryden_wavenumber(bool longitudinal, double L, std::uint64_t& s) {
  if (longitudinal) return std::tan(kPi * (unit(s) - 0.5)) / L;
  for (;;) {
    const double w = std::tan(kPi * (unit(s) - 0.5)) / (2 * L);
    const double x = L * w;
    if (3 * unit(s) <= (1 + 12 * x * x) / (1 + 4 * x * x)) return w;
  }
}

void check_ordered(const std::string& field, const Eigen::Vector2d& v) {
  if (!(v.x() > 0 && v.y() >= v.x()))
    throw FieldError(field, "[" + to_text(v.x()) + ", " + to_text(v.y()) + "]",
                     "must be [min, max] with 0 < min <= max");
}

}  // namespace

void WindConfig::validate() const {
  FieldChecker check("wind");
  fields(*this, check);
  if (!steady_mps.allFinite())
    throw FieldError("wind.steady_mps", to_text(steady_mps.transpose()), "must be finite");
  if (turbulence && steady_mps.norm() < 0.1)
    throw FieldError(
        "wind.turbulence", "true",
        "Dryden turbulence takes its intensity and length scales from the mean wind: set "
        "wind.steady_mps (its size is the wind at 6 m) to at least 0.1 m/s");
  if (gusts_per_minute > 0) {
    check_ordered("wind.gust_amplitude_mps", gust_amplitude_mps);
    check_ordered("wind.gust_duration_s", gust_duration_s);
  }
}

void load(YamlSection s, WindConfig& c) {
  FieldLoader load(s);
  WindConfig::fields(c, load);
  s.finish();
}

DrydenScales dryden_scales(double w20_mps, double h_m) {
  const double h = std::max(h_m / kFt, 10.0);  // ft; the low-altitude model holds from 10 ft
  const double base = 0.177 + 0.000823 * h;
  DrydenScales d{};
  d.sigma_w = 0.1 * w20_mps;
  d.sigma_u = d.sigma_v = d.sigma_w / std::pow(base, 0.4);
  d.L_u = h / std::pow(base, 1.2) * kFt;
  d.L_v = 0.5 * d.L_u;
  d.L_w = 0.5 * h * kFt;
  return d;
}

WindField::WindField(const WindConfig& c, std::uint64_t seed) : cfg_(c), enabled_(c.enabled()) {
  if (c.seed) seed = c.seed;
  mean_speed_ = c.steady_mps.norm();
  // The wind frame: x along the mean wind (horizontal part; +x without one), z up.
  Eigen::Vector3d along(c.steady_mps.x(), c.steady_mps.y(), 0);
  if (along.norm() < 1e-9) along = Eigen::Vector3d::UnitX();
  along.normalize();
  world_from_wind_.col(0) = along;
  world_from_wind_.col(1) = Eigen::Vector3d::UnitZ().cross(along);
  world_from_wind_.col(2) = Eigen::Vector3d::UnitZ();
  gust_state_ = seed ^ 0x6a09e667f3bcc909ULL;
  next_gust_s_ =
      c.gusts_per_minute > 0 ? -std::log(unit(gust_state_)) * 60.0 / c.gusts_per_minute : 1e300;
  if (!c.turbulence) return;
  scales_ = dryden_scales(mean_speed_, c.turbulence_altitude_m);
  const double sigma[3] = {scales_.sigma_u * c.turbulence_scale,
                           scales_.sigma_v * c.turbulence_scale,
                           scales_.sigma_w * c.turbulence_scale};
  const double L[3] = {scales_.L_u, scales_.L_v, scales_.L_w};
  for (int comp = 0; comp < 3; ++comp) {
    std::uint64_t s = seed ^ (0xbb67ae8584caa73bULL * static_cast<std::uint64_t>(comp + 1));
    // Sum of n modes of amplitude sigma sqrt(2 / n): variance sigma^2.
    const double a = sigma[comp] * std::sqrt(2.0 / c.turbulence_modes);
    for (int k = 0; k < c.turbulence_modes; ++k) {
      Mode m;
      m.k.x() = dryden_wavenumber(comp == 0, L[comp], s);
      // Across the wind and vertically: a Cauchy law of the same scale
      // (correlation exp(-r / L)), so the field decorrelates with distance.
      m.k.y() = dryden_wavenumber(true, L[comp], s);
      m.k.z() = dryden_wavenumber(true, L[comp], s);
      m.phase = 2 * kPi * unit(s);
      m.amplitude = a;
      modes_[comp].push_back(m);
    }
  }
}

Eigen::Vector3d WindField::to_wind_frame(const Eigen::Vector3d& p_world, double t) const {
  // Frozen turbulence carried by the mean wind: the air now at p was at p - U t.
  return world_from_wind_.transpose() * p_world - Eigen::Vector3d(mean_speed_ * t, 0, 0);
}

Eigen::Vector3d WindField::turbulence(const Eigen::Vector3d& p, double t) const {
  if (!cfg_.turbulence) return Eigen::Vector3d::Zero();
  const Eigen::Vector3d x = to_wind_frame(p, t);
  Eigen::Vector3d w = Eigen::Vector3d::Zero();
  for (int comp = 0; comp < 3; ++comp)
    for (const Mode& m : modes_[comp]) w[comp] += m.amplitude * std::cos(m.k.dot(x) + m.phase);
  return world_from_wind_ * w;
}

void WindField::advance_to(double t) {
  // A gust reaches points up to the world's size upwind before it passes the
  // origin; drawing ahead by the longest gust and 10 km keeps every one that
  // can matter by t.
  const double ahead = cfg_.gust_duration_s.y() + (mean_speed_ > 0 ? 1e4 / mean_speed_ : 0.0);
  while (next_gust_s_ <= t + ahead) {
    Gust g;
    g.t_s = next_gust_s_;
    g.amplitude_mps =
        cfg_.gust_amplitude_mps.x() +
        (cfg_.gust_amplitude_mps.y() - cfg_.gust_amplitude_mps.x()) * unit(gust_state_);
    g.duration_s = cfg_.gust_duration_s.x() +
                   (cfg_.gust_duration_s.y() - cfg_.gust_duration_s.x()) * unit(gust_state_);
    gusts_.push_back(g);
    next_gust_s_ += -std::log(unit(gust_state_)) * 60.0 / cfg_.gusts_per_minute;
  }
}

Eigen::Vector3d WindField::gust(const Eigen::Vector3d& p, double t) const {
  if (gusts_.empty()) return Eigen::Vector3d::Zero();
  // The front passes the origin at g.t_s, and p a along-wind distance later.
  const double delay = mean_speed_ > 0 ? world_from_wind_.col(0).dot(p) / mean_speed_ : 0.0;
  // The gusts are in time order: only those that began at most one longest
  // gust ago can still blow here.
  const double from = t - delay - cfg_.gust_duration_s.y();
  auto it = std::lower_bound(gusts_.begin(), gusts_.end(), from,
                             [](const Gust& g, double x) { return g.t_s < x; });
  double a = 0;
  for (; it != gusts_.end() && it->t_s <= t - delay; ++it) {
    const double tau = t - it->t_s - delay;
    if (tau <= it->duration_s)
      a += 0.5 * it->amplitude_mps * (1 - std::cos(2 * kPi * tau / it->duration_s));
  }
  return a * world_from_wind_.col(0);
}

Eigen::Vector3d WindField::at(const Eigen::Vector3d& p, double t) const {
  if (!enabled_) return Eigen::Vector3d::Zero();
  return cfg_.steady_mps + turbulence(p, t) + gust(p, t);
}

}  // namespace ddswarm::sim
