// The vehicle model and the three config structs: defaults match AirSim's
// generic quadrotor, validation names the bad field, loading is strict.
#include "sim_server/quadrotor.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "sim_server/flight_controller.hpp"

namespace ddswarm::sim {
namespace {

template <class T>
std::string field_error_of(const T& c) {
  try {
    c.validate();
  } catch (const FieldError& e) {
    return e.field();
  }
  return "(no error)";
}

TEST(QuadrotorParams, DefaultsAreAirSimGenericQuad) {
  QuadrotorParams q;
  EXPECT_NO_THROW(q.validate());
  EXPECT_NEAR(q.omega_max_rad_s(), 669.87, 0.05);
  EXPECT_NEAR(q.max_rotor_thrust_n(), 4.179, 0.005);
  // AirSim's max torque: C_P rho n^2 D^5 / 2pi at max RPM.
  EXPECT_NEAR(q.k_m() * std::pow(q.omega_max_rad_s(), 2), 0.0556, 0.0005);
}

TEST(QuadrotorParams, HoverThrustEqualsWeight) {
  QuadrotorParams q;
  const double w = q.hover_omega();
  const Wrench f = q.rotor_wrench({w, w, w, w});
  const double weight = q.mass_kg * kGravityMps2;
  EXPECT_NEAR(f.thrust_n, weight, 0.01 * weight);
  EXPECT_NEAR(f.torque_body_nm.norm(), 0.0, 1e-9);
  EXPECT_LT(w, q.omega_max_rad_s());
}

TEST(QuadrotorParams, InertiaFromBoxAndMotors) {
  QuadrotorParams q;
  const Eigen::Vector3d j = q.inertia();
  // Box 0.78 kg plus four 0.055 kg point masses at 0.2275 m (45 deg), 0.025 m up.
  const double arm_xy = 0.2275 / std::sqrt(2.0);
  const double ixx =
      0.78 / 12 * (0.11 * 0.11 + 0.04 * 0.04) + 4 * 0.055 * (arm_xy * arm_xy + 0.025 * 0.025);
  const double izz = 0.78 / 12 * (0.18 * 0.18 + 0.11 * 0.11) + 4 * 0.055 * 0.2275 * 0.2275;
  EXPECT_NEAR(j.x(), ixx, 1e-9);
  EXPECT_NEAR(j.z(), izz, 1e-9);
  EXPECT_GT(j.y(), j.x());
  q.inertia_kgm2 = {0.01, 0.02, 0.03};
  EXPECT_EQ(q.inertia(), Eigen::Vector3d(0.01, 0.02, 0.03));
}

TEST(QuadrotorParams, RotorLayoutIsPx4QuadX) {
  QuadrotorParams q;
  const auto p0 = q.rotor_position_body(0), p1 = q.rotor_position_body(1);
  const auto p2 = q.rotor_position_body(2), p3 = q.rotor_position_body(3);
  EXPECT_TRUE(p0.x() > 0 && p0.y() < 0);  // front-right
  EXPECT_TRUE(p1.x() < 0 && p1.y() > 0);  // rear-left
  EXPECT_TRUE(p2.x() > 0 && p2.y() > 0);  // front-left
  EXPECT_TRUE(p3.x() < 0 && p3.y() < 0);  // rear-right
  EXPECT_NEAR(p0.norm(), q.arm_length_m, 1e-12);
  // Speeding up the CCW pair (0, 1) yaws the body clockwise (negative z).
  const double w = q.hover_omega();
  EXPECT_LT(q.rotor_wrench({w + 50, w + 50, w, w}).torque_body_nm.z(), 0);
  // Faster left rotors (1, 2) lift the left side: positive torque about x.
  EXPECT_GT(q.rotor_wrench({w, w + 50, w + 50, w}).torque_body_nm.x(), 0);
  // Front rotors (0, 2) faster pitch the nose up: negative torque about y.
  EXPECT_LT(q.rotor_wrench({w + 50, w, w + 50, w}).torque_body_nm.y(), 0);
}

TEST(YawOf, ReadsHeading) {
  const Eigen::Quaterniond q(Eigen::AngleAxisd(1.2, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()));
  EXPECT_NEAR(yaw_of(q), 1.2, 1e-9);
}

TEST(Validation, NamesTheBadField) {
  QuadrotorParams q;
  q.mass_kg = -1;
  EXPECT_EQ(field_error_of(q), "quadrotor.mass_kg");
  q = {};
  q.mass_kg = 2.0;  // more than the rotors can lift with margin
  EXPECT_EQ(field_error_of(q), "quadrotor.mass_kg");
  q = {};
  q.body_box_m.y() = 0;
  EXPECT_EQ(field_error_of(q), "quadrotor.body_box_m");
  q = {};
  q.inertia_kgm2 = {0.01, 0, 0.02};
  EXPECT_EQ(field_error_of(q), "quadrotor.inertia_kgm2");
  q = {};
  q.omega_min_rad_s = 700;
  EXPECT_EQ(field_error_of(q), "quadrotor.omega_min_rad_s");

  SensorConfig s;
  EXPECT_NO_THROW(s.validate());
  s.count = 0;
  EXPECT_EQ(field_error_of(s), "sensors.count");
  s = {};
  s.count = 257;
  EXPECT_EQ(field_error_of(s), "sensors.count");
  s = {};
  s.max_range_m = 0.04;
  EXPECT_EQ(field_error_of(s), "sensors.max_range_m");
  s = {};
  s.noise_sigma_m = -0.1;
  EXPECT_EQ(field_error_of(s), "sensors.noise_sigma_m");
  s = {};
  s.count = 256;  // one row of 256 is the most a scan carries
  EXPECT_NO_THROW(s.validate());

  ControllerConfig c;
  EXPECT_NO_THROW(c.validate());
  c.max_speed_mps = 0;
  EXPECT_EQ(field_error_of(c), "controller.max_speed_mps");
  c = {};
  c.max_tilt_rad = 1.5;
  EXPECT_EQ(field_error_of(c), "controller.max_tilt_rad");
  c = {};
  c.vel_i_z = -1;
  EXPECT_EQ(field_error_of(c), "controller.vel_i_z");
  c = {};
  c.max_yaw_accel_rad_s2 = 0;
  EXPECT_EQ(field_error_of(c), "controller.max_yaw_accel_rad_s2");
}

TEST(Validation, MessageNamesValueAndReason) {
  QuadrotorParams q;
  q.mass_kg = -1;
  try {
    q.validate();
    FAIL();
  } catch (const FieldError& e) {
    EXPECT_STREQ(e.what(), "quadrotor.mass_kg = -1: must be > 0");
  }
}

TEST(Load, ReadsEveryKey) {
  auto doc = YamlDocument::parse(R"(
quadrotor:
  mass_kg: 1.2
  arm_length_m: 0.25
  body_box_m: [0.2, 0.1, 0.05]
  motor_mass_kg: 0.06
  rotor_z_m: 0.02
  inertia_kgm2: [0.01, 0.01, 0.02]
  thrust_coeff: 0.12
  power_coeff: 0.04
  prop_diameter_m: 0.25
  air_density_kgm3: 1.2
  max_rpm: 7000
  omega_min_rad_s: 10
  motor_tau_s: 0.02
  drag_quadratic_body: [0.01, 0.01, 0.1]
  drag_linear_n_per_mps: 0.05
  angular_drag_nm_per_rad_s: 0.001
  collision_radius_m: 0.35
  collision_half_height_m: 0.06
sensors: {count: 16, max_range_m: 6, min_range_m: 0.1, noise_sigma_m: 0, yaw_offset_rad: 0.1}
controller: {max_speed_mps: 3, vel_p_xy: 2.5, rate_d_rp: 0.01, drag_feedforward: false,
             max_yaw_accel_rad_s2: 3, vel_i_band_mps: 0.2}
)",
                                 "test.yaml");
  QuadrotorParams q;
  SensorConfig s;
  ControllerConfig c;
  doc.guard([&] {
    load(doc.section("quadrotor"), q);
    q.validate();
    load(doc.section("sensors"), s);
    s.validate();
    load(doc.section("controller"), c);
    c.validate();
  });
  EXPECT_EQ(q.mass_kg, 1.2);
  EXPECT_EQ(q.inertia(), Eigen::Vector3d(0.01, 0.01, 0.02));
  EXPECT_EQ(q.motor_tau_s, 0.02);
  EXPECT_EQ(q.collision_half_height_m, 0.06);
  EXPECT_EQ(s.count, 16);
  EXPECT_EQ(s.yaw_offset_rad, 0.1);
  EXPECT_EQ(c.max_speed_mps, 3);
  EXPECT_EQ(c.rate_d_rp, 0.01);
  EXPECT_FALSE(c.drag_feedforward);
  EXPECT_EQ(c.max_yaw_accel_rad_s2, 3);
  EXPECT_EQ(c.vel_i_band_mps, 0.2);
  EXPECT_EQ(c.max_tilt_rad, ControllerConfig{}.max_tilt_rad);  // absent keys keep defaults
}

TEST(Load, UnknownKeyIsAnError) {
  auto doc = YamlDocument::parse("quadrotor:\n  mass_kg: 1\n  mass: 2\n", "t.yaml");
  QuadrotorParams q;
  try {
    load(doc.section("quadrotor"), q);
    FAIL() << "unknown key accepted";
  } catch (const ConfigError& e) {
    EXPECT_STREQ(e.what(), "t.yaml:3: quadrotor.mass: unknown key");
  }
  auto doc2 = YamlDocument::parse("sensors:\n  cout: 8\n", "t.yaml");
  SensorConfig s;
  EXPECT_THROW(load(doc2.section("sensors"), s), ConfigError);
  auto doc3 = YamlDocument::parse("controller:\n  max_sped_mps: 8\n", "t.yaml");
  ControllerConfig c;
  EXPECT_THROW(load(doc3.section("controller"), c), ConfigError);
}

TEST(Sensors, RowsSpreadEvenlyInElevationAndOneRowIsTheThesisRing) {
  SensorConfig ring;
  ASSERT_EQ(ring.rays(), 8);
  for (int k = 0; k < 8; ++k) {
    const double a = 2 * std::numbers::pi * k / 8;  // as the ring was always cast
    EXPECT_EQ(ring.ray_direction_body(k), Eigen::Vector3d(std::cos(a), std::sin(a), 0.0)) << k;
    EXPECT_EQ(ring.ray_elevation_rad(k), 0.0);
  }
  SensorConfig s;
  s.rows = 5;
  s.vertical_fov_deg = 40;
  s.count = 8;
  ASSERT_EQ(s.rays(), 40);
  const double deg = std::numbers::pi / 180;
  // Ray k = row k / 8, column k % 8; rows at -20, -10, 0, 10, 20 deg.
  for (int r = 0; r < 5; ++r)
    for (int c = 0; c < 8; ++c) {
      const int k = r * 8 + c;
      EXPECT_NEAR(s.ray_elevation_rad(k), (-20 + 10 * r) * deg, 1e-12) << k;
      EXPECT_DOUBLE_EQ(s.ray_yaw_rad(k), 2 * std::numbers::pi * c / 8) << k;
      const Eigen::Vector3d d = s.ray_direction_body(k);
      EXPECT_NEAR(d.norm(), 1.0, 1e-12);
      EXPECT_NEAR(std::asin(d.z()), s.ray_elevation_rad(k), 1e-12);
      EXPECT_NEAR(std::atan2(d.y(), d.x()), std::remainder(s.ray_yaw_rad(k), 2 * std::numbers::pi),
                  1e-12);
    }
  EXPECT_EQ(s.ray_elevation_rad(16), 0.0);  // the middle row is exactly level
  EXPECT_EQ(s.ray_elevation_rad(0), -s.ray_elevation_rad(39));
  // Two rows over 180 deg: straight down and straight up.
  s.rows = 2;
  s.vertical_fov_deg = 180;
  EXPECT_NEAR(s.ray_direction_body(0).z(), -1.0, 1e-12);
  EXPECT_NEAR(s.ray_direction_body(8).z(), 1.0, 1e-12);
}

TEST(Sensors, ABadRowPatternIsOneLineNamingTheFieldTheValueAndTheLine) {
  auto error = [](const std::string& yaml) {
    auto doc = YamlDocument::parse(yaml, "s.yaml");
    SensorConfig s;
    try {
      doc.guard([&] {
        load(doc.section("sensors"), s);
        s.validate();
      });
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(error("sensors:\n  count: 8\n  rows: 0\n"),
            "s.yaml:3: sensors.rows = 0: must be in [1, 32]");
  EXPECT_EQ(error("sensors:\n  rows: 3\n  vertical_fov_deg: 200\n"),
            "s.yaml:3: sensors.vertical_fov_deg = 200: must be in [0, 180]");
  EXPECT_EQ(error("sensors:\n  count: 100\n  rows: 3\n  vertical_fov_deg: 30\n"),
            "s.yaml:3: sensors.rows = 3: rows x count = 300 rays: must be <= 256 (count 100)");
  EXPECT_EQ(error("sensors:\n  count: 8\n  rows: 3\n"),
            "s.yaml:3: sensors.rows = 3: needs vertical_fov_deg > 0 (with 0 every row looks the "
            "same way)");
  EXPECT_EQ(error("sensors: {rows: 5, vertical_fov_deg: 40, count: 8}\n"), "accepted");
  EXPECT_EQ(error("sensors: {rows: 32, vertical_fov_deg: 90, count: 8}\n"), "accepted");
}

TEST(Load, ValidationErrorGetsFileAndLine) {
  auto doc = YamlDocument::parse("sensors:\n  count: 8\n  max_range_m: -3\n", "s.yaml");
  SensorConfig s;
  try {
    doc.guard([&] {
      load(doc.section("sensors"), s);
      s.validate();
    });
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()), "s.yaml:3: sensors.max_range_m = -3: must be > 0");
  }
}

}  // namespace
}  // namespace ddswarm::sim
