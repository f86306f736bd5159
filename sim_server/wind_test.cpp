#include "sim_server/wind.hpp"

#include "common/config_reference.hpp"
#include "sim_server/aero.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

using namespace ddswarm;
using namespace ddswarm::sim;
using Eigen::Vector3d;

namespace {

constexpr double kFt = 0.3048;

WindConfig turbulent(double w20, double h_m = 3.05) {
  WindConfig c;
  c.steady_mps = Vector3d(w20, 0, 0);
  c.turbulence = true;
  c.turbulence_altitude_m = h_m;
  return c;
}

/// Correlation of the along-wind turbulence at a and b over a long run, over several seeds.
double correlation(const WindConfig& c, const Vector3d& a, const Vector3d& b, double dt_s,
                   int comp = 0) {
  double sab = 0, saa = 0, sbb = 0;
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    const WindField f(c, seed);
    for (int k = 0; k < 4000; ++k) {
      const double t = 0.25 * k;
      const double x = f.turbulence(a, t)[comp], y = f.turbulence(b, t + dt_s)[comp];
      sab += x * y, saa += x * x, sbb += y * y;
    }
  }
  return sab / std::sqrt(saa * sbb);
}

}  // namespace

TEST(Dryden, ScalesFollowTheHandbooksLowAltitudeFormulas) {
  // At 1000 ft the low-altitude model meets the medium-altitude one:
  // sigma_u = sigma_v = sigma_w and L_u = 2 L_v = 2 L_w = 1000 ft.
  const DrydenScales hi = dryden_scales(10.0, 1000 * kFt);
  EXPECT_NEAR(hi.sigma_w, 1.0, 1e-12) << "sigma_w = 0.1 W20";
  EXPECT_NEAR(hi.sigma_u, hi.sigma_w, 1e-12);
  EXPECT_NEAR(hi.L_u, 1000 * kFt, 1e-9);
  EXPECT_NEAR(hi.L_v, 500 * kFt, 1e-9);
  EXPECT_NEAR(hi.L_w, 500 * kFt, 1e-9);
  // At 10 ft, the lowest it holds (and below, where it is held).
  const DrydenScales lo = dryden_scales(10.0, 1.0);
  const double base = 0.177 + 0.000823 * 10;
  EXPECT_NEAR(lo.sigma_u, 1.0 / std::pow(base, 0.4), 1e-12);
  EXPECT_NEAR(lo.L_u, 10 / std::pow(base, 1.2) * kFt, 1e-9);
  EXPECT_NEAR(lo.L_w, 5 * kFt, 1e-12);
  EXPECT_GT(lo.sigma_u, 1.9) << "near the ground the horizontal gusts are twice the vertical";
}

TEST(Dryden, ALongRunHasTheSpectrumsStandardDeviation) {
  const WindConfig c = turbulent(6.0);
  const DrydenScales d = dryden_scales(6.0, 3.05);
  for (std::uint64_t seed : {3u, 4u}) {
    const WindField f(c, seed);
    Vector3d sum = Vector3d::Zero(), sq = Vector3d::Zero();
    const int n = 200000;
    for (int k = 0; k < n; ++k) {
      const Vector3d w = f.turbulence(Vector3d(0, 0, 2), 0.05 * k);
      sum += w;
      sq += w.cwiseProduct(w);
    }
    const Vector3d mean = sum / n, sd = (sq / n - mean.cwiseProduct(mean)).cwiseSqrt();
    EXPECT_NEAR(sd.x(), d.sigma_u, 0.05 * d.sigma_u);
    EXPECT_NEAR(sd.y(), d.sigma_v, 0.05 * d.sigma_v);
    EXPECT_NEAR(sd.z(), d.sigma_w, 0.05 * d.sigma_w);
    EXPECT_LT(std::abs(mean.x()), 0.1 * d.sigma_u);
  }
}

TEST(Dryden, ItsAutocorrelationTimeIsTheSpectrums) {
  // Frozen and carried at U, the along-wind correlation at a point after tau
  // is exp(-U tau / L_u): 1/e after L_u / U.
  const WindConfig c = turbulent(6.0);
  const DrydenScales d = dryden_scales(6.0, 3.05);
  const Vector3d p(0, 0, 2);
  EXPECT_NEAR(correlation(c, p, p, d.L_u / 6.0), std::exp(-1.0), 0.08);
  EXPECT_NEAR(correlation(c, p, p, 0.25 * d.L_u / 6.0), std::exp(-0.25), 0.06);
  // The vertical component's (Dryden's transverse form) correlation after
  // L_w / U: e^{-1/2} (1 - 1/4) = 0.455.
  EXPECT_NEAR(correlation(c, p, p, d.L_w / 6.0, 2), std::exp(-0.5) * 0.75, 0.08);
}

TEST(Dryden, DronesAMetreApartFeelTheSameGustAndFiftyMetresApartDoNot) {
  const WindConfig c = turbulent(6.0);
  const Vector3d p(0, 0, 2);
  EXPECT_GT(correlation(c, p, p + Vector3d(0, 1, 0), 0), 0.9);
  EXPECT_LT(std::abs(correlation(c, p, p + Vector3d(0, 50, 0), 0)), 0.2);
  EXPECT_LT(std::abs(correlation(c, p, p + Vector3d(50, 0, 0), 0)), 0.2);
  // Downwind, the same air comes by later: 12 m at 6 m/s is 2 s.
  EXPECT_GT(correlation(c, p, p + Vector3d(12, 0, 0), 2.0), 0.97);
}

TEST(Wind, ASeedIsAWind) {
  WindConfig c = turbulent(5.0);
  c.gusts_per_minute = 6;
  WindField a(c, 7), b(c, 7), other(c, 8);
  a.advance_to(100), b.advance_to(100), other.advance_to(100);
  for (double t = 0; t < 100; t += 1.7) {
    EXPECT_EQ(a.at(Vector3d(1, 2, 3), t), b.at(Vector3d(1, 2, 3), t));
  }
  EXPECT_NE(a.at(Vector3d(1, 2, 3), 50), other.at(Vector3d(1, 2, 3), 50));
  EXPECT_EQ(WindField(WindConfig{}, 1).at(Vector3d(1, 2, 3), 5), Vector3d::Zero())
      << "calm by default";
}

TEST(Wind, AGustHasTheOneCosineShapeAndTravelsWithTheWind) {
  WindConfig c;
  c.steady_mps = Vector3d(5, 0, 0);
  c.gusts_per_minute = 1;
  c.gust_amplitude_mps = {3, 3};
  c.gust_duration_s = {2, 2};
  WindField f(c, 11);
  f.advance_to(600);
  ASSERT_GT(f.gusts().size(), 3u);
  const Gust g = f.gusts()[1];
  const Vector3d origin(0, 0, 2), downwind(10, 0, 2);
  for (double tau = 0; tau <= 2.0; tau += 0.1) {
    const double want = 1.5 * (1 - std::cos(M_PI * tau));
    EXPECT_NEAR(f.gust(origin, g.t_s + tau).x(), want, 1e-9) << tau;
    EXPECT_NEAR(f.gust(downwind, g.t_s + 2.0 + tau).x(), want, 1e-9)
        << "10 m downwind at 5 m/s: 2 s later";
  }
  EXPECT_NEAR(f.gust(origin, g.t_s + 1.0).x(), 3.0, 1e-12) << "its peak, halfway";
  EXPECT_EQ(f.gust(origin, g.t_s + 1.0).y(), 0) << "along the mean wind";
  EXPECT_EQ(f.gust(origin, g.t_s - 0.01).x(), 0) << "not before its front";
  // About the rate asked for: 1 a minute over 10 minutes.
  std::size_t in_ten = 0;
  for (const auto& x : f.gusts()) in_ten += x.t_s < 600;
  EXPECT_GE(in_ten, 3u);
  EXPECT_LE(in_ten, 25u);
}

TEST(Wind, BadInputNamesTheField) {
  auto error = [](const WindConfig& c) {
    try {
      c.validate();
    } catch (const FieldError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  WindConfig c;
  c.turbulence = true;
  EXPECT_NE(error(c).find("wind.turbulence = true: Dryden turbulence takes its intensity"),
            std::string::npos);
  c = WindConfig{};
  c.gusts_per_minute = 2;
  c.gust_duration_s = {3, 1};
  EXPECT_EQ(error(c), "wind.gust_duration_s = [3, 1]: must be [min, max] with 0 < min <= max");
  c = WindConfig{};
  c.turbulence_altitude_m = 1;
  EXPECT_EQ(error(c), "wind.turbulence_altitude_m = 1: must be in [3.05, 300]");
}

TEST(Wind, TheReferenceDescribesEveryField) {
  EXPECT_EQ(
      reference_mismatches(configuration_reference(), "### `wind:`", field_rows<WindConfig>()),
      std::vector<std::string>{});
  EXPECT_EQ(
      reference_mismatches(configuration_reference(), "### `aero:`", field_rows<AeroConfig>()),
      std::vector<std::string>{});
}
