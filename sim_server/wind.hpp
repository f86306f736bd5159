#pragma once
// Wind: YAML `wind`. A steady vector, Dryden turbulence and discrete
// 1-cosine gusts, as one seeded, spatially coherent field w(p, t) (m/s,
// world ENU) that the airframe's drag acts through.
//
// Turbulence: the MIL-HDBK-1797 Dryden model at low altitude. From the mean
// wind W20 at 6 m (20 ft, |steady_mps|) and the altitude h (ft, >= 10):
//   sigma_w = 0.1 W20,  sigma_u = sigma_v = sigma_w / (0.177 + 0.000823 h)^0.4,
//   L_u = 2 L_v = h / (0.177 + 0.000823 h)^1.2,  2 L_w = h,
// with the spatial spectra (Omega, rad/m; u along the mean wind, v across, w up)
//   Phi_u = sigma_u^2 (2 L_u / pi) / (1 + (L_u Omega)^2),
//   Phi_v = sigma_v^2 (2 L_v / pi) (1 + 12 (L_v Omega)^2) / (1 + 4 (L_v Omega)^2)^2,
//   Phi_w likewise with sigma_w, L_w.
// The field is frozen and carried by the mean wind (Taylor's hypothesis):
// w(p, t) = f(p - U t). f is a sum of random Fourier modes per component,
// each mode's wavenumber along the wind drawn from that component's Dryden
// spectrum (so the along-wind correlation is the spectrum's, e.g.
// R_u(r) = sigma_u^2 exp(-r / L_u)) and across the wind from a Cauchy law of
// the same length scale, so drones a metre apart feel nearly the same gust
// and drones 50 m apart do not.
//
// Gusts: at seeded Poisson times, a 1-cosine gust (MIL-F-8785C's discrete
// gust shape) along the mean wind (or +x without one),
//   g(x) = A / 2 (1 - cos(2 pi x / (U T))),  0 <= x <= U T,
// a front that reaches a point at the gust's time plus its along-wind
// distance over U (at once everywhere without a mean wind).
//
// Pure: no clock, no I/O; the same seed gives the same field.
#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "common/config_fields.hpp"
#include "common/yaml_section.hpp"

namespace ddswarm::sim {

struct WindConfig {
  Eigen::Vector3d steady_mps{0, 0, 0};
  bool turbulence = false;
  double turbulence_altitude_m = 3.05;
  double turbulence_scale = 1.0;
  int turbulence_modes = 64;
  double gusts_per_minute = 0;
  Eigen::Vector2d gust_amplitude_mps{1, 3};
  Eigen::Vector2d gust_duration_s{1, 3};
  std::uint64_t seed = 0;

  template <class Self, class V>
  static void fields(Self& c, V& v) {
    v.field("steady_mps", c.steady_mps,
            {"m/s", any(), "the mean wind, world ENU (its size is W20, the wind at 6 m)"});
    v.field("turbulence", c.turbulence,
            {"", any(), "Dryden turbulence from the mean wind (MIL-HDBK-1797, low altitude)"});
    v.field("turbulence_altitude_m", c.turbulence_altitude_m,
            {"m", in(3.05, 300), "the altitude the length scales and intensities are taken at"});
    v.field("turbulence_scale", c.turbulence_scale,
            {"", in(0, 10), "multiplies the Dryden intensities"});
    v.field("turbulence_modes", c.turbulence_modes,
            {"", in(8, 1024), "Fourier modes per component"});
    v.field("gusts_per_minute", c.gusts_per_minute,
            {"1/min", in(0, 600), "mean rate of 1-cosine gusts; 0 = none"});
    v.field("gust_amplitude_mps", c.gust_amplitude_mps,
            {"m/s", any(), "[min, max] peak speed, 0 < min <= max"});
    v.field("gust_duration_s", c.gust_duration_s,
            {"s", any(), "[min, max] length, 0 < min <= max"});
    v.field("seed", c.seed, {"", any(), "the wind's seed; 0 = scenario.seed"});
  }

  bool enabled() const {
    return steady_mps.squaredNorm() > 0 || turbulence || gusts_per_minute > 0;
  }
  /// Bounds from the field list, then: turbulence needs a mean wind, gust ranges ordered.
  void validate() const;  ///< throws FieldError("wind.…")
};

/// The Dryden parameters at altitude h_m for a mean wind w20_mps at 6 m.
struct DrydenScales {
  double sigma_u, sigma_v, sigma_w;  ///< m/s
  double L_u, L_v, L_w;              ///< m
};
DrydenScales dryden_scales(double w20_mps, double h_m);

/// One gust of the seeded schedule.
struct Gust {
  double t_s;  ///< when its front passes the origin
  double amplitude_mps;
  double duration_s;
};

class WindField {
 public:
  /// seed: c.seed, or the scenario's when that is 0.
  WindField(const WindConfig& c, std::uint64_t seed);

  /// Draws the gusts that can reach the world by sim time t (call once a
  /// step, before at(); at() itself is const and safe from many threads).
  void advance_to(double t);
  /// The wind (m/s, world ENU) at p (m, world ENU) and sim time t (s).
  Eigen::Vector3d at(const Eigen::Vector3d& p, double t) const;
  /// Its turbulence part alone, and its gust part alone.
  Eigen::Vector3d turbulence(const Eigen::Vector3d& p, double t) const;
  Eigen::Vector3d gust(const Eigen::Vector3d& p, double t) const;

  const DrydenScales& scales() const { return scales_; }
  const std::vector<Gust>& gusts() const { return gusts_; }  ///< the schedule drawn so far
  bool enabled() const { return enabled_; }

 private:
  struct Mode {
    Eigen::Vector3d k;  ///< rad/m, in the wind frame (along, across, up)
    double phase;
    double amplitude;  ///< m/s
  };
  Eigen::Vector3d to_wind_frame(const Eigen::Vector3d& p_world, double t) const;

  WindConfig cfg_;
  bool enabled_ = false;
  Eigen::Matrix3d world_from_wind_ = Eigen::Matrix3d::Identity();
  double mean_speed_ = 0;
  DrydenScales scales_{};
  std::vector<Mode> modes_[3];  ///< u, v, w
  // Gusts are drawn as time goes on (a Poisson process), from their own stream.
  std::vector<Gust> gusts_;
  std::uint64_t gust_state_ = 0;
  double next_gust_s_ = 0;
};

/// Reads section `wind`; unknown keys throw ConfigError with file and line.
void load(YamlSection s, WindConfig& c);

}  // namespace ddswarm::sim
