// Airframes: the Crazyflie preset carries its published parameters, a
// scenario picks the airframe for all drones or per group of drones, bad
// input names file, line, field and value, and the reference tables of
// quadrotor, controller and sensors describe every field.
#include "sim_server/airframe.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <numbers>

#include "common/config_reference.hpp"
#include "sim_server/sim_server.hpp"

namespace ddswarm::sim {
namespace {

std::string write(const std::string& yaml) {
  const std::string path = ::testing::TempDir() + "/airframe_under_test.yaml";
  std::ofstream(path) << yaml;
  return path;
}

/// The error after the file name ("line: field = value: reason"), or "".
std::string error_for(const std::string& yaml) {
  try {
    load_server_config(write(yaml));
  } catch (const ConfigError& e) {
    const std::string m = e.what();
    return m.substr(m.find(':') + 1);
  }
  return "";
}

TEST(Crazyflie, CarriesFoerstersIdentifiedParameters) {
  const QuadrotorParams q = QuadrotorParams::preset(Airframe::kCrazyflie);
  EXPECT_NO_THROW(q.validate());
  EXPECT_EQ(q.mass_kg, 0.027);
  EXPECT_EQ(q.arm_length_m, 0.046);
  // k_F in rpm^2 form: 10 000 rpm gives 3.1582e-10 * 1e8 N per rotor.
  const double w10k = 10000.0 * 2 * std::numbers::pi / 60;
  EXPECT_NEAR(q.k_f() * w10k * w10k, 0.031582, 1e-9);
  EXPECT_NEAR(q.k_m() * w10k * w10k, 7.9379e-4, 1e-12);
  EXPECT_EQ(q.inertia(), Eigen::Vector3d(1.6572e-5, 1.6656e-5, 2.9262e-5));
  // Full speed lifts 2.25 times the weight (gym-pybullet-drones' cf2x.urdf).
  EXPECT_NEAR(4 * q.max_rotor_thrust_n() / (q.mass_kg * kGravityMps2), 2.25, 0.001);
  // Hover at 14 478 rpm, two thirds of full speed (sqrt(1/2.25)).
  EXPECT_NEAR(q.hover_omega() * 60 / (2 * std::numbers::pi), 14478, 1);
  EXPECT_EQ(q.motor_tau_s, 0.0125);
  EXPECT_EQ(q.motor_tau_down_s, 0.025);
  EXPECT_LT(q.collision_radius_m, 0.1) << "a 92 mm frame";
  // The generic preset is the defaults: Table 1's vehicle.
  const QuadrotorParams g = QuadrotorParams::preset(Airframe::kGeneric);
  EXPECT_EQ(g.mass_kg, QuadrotorParams{}.mass_kg);
  EXPECT_EQ(g.k_f(), QuadrotorParams{}.k_f());
}

TEST(Airframes, TheQuadrotorSectionPicksOneForEveryDroneAndOverridesIt) {
  ServerConfig c = load_server_config(
      write("scenario:\n  drones: 4\nquadrotor:\n  airframe: crazyflie\n  mass_kg: 0.030\n"
            "controller:\n  max_speed_mps: 2\n"));
  EXPECT_EQ(c.quadrotor.airframe, Airframe::kCrazyflie);
  EXPECT_EQ(c.quadrotor.mass_kg, 0.030);
  EXPECT_EQ(c.quadrotor.arm_length_m, 0.046) << "the rest is the preset";
  // The controller starts from the airframe's gains; `controller:` goes over them.
  const ControllerConfig cf = ControllerConfig::preset(Airframe::kCrazyflie);
  EXPECT_EQ(c.controller.max_speed_mps, 2);
  EXPECT_EQ(c.controller.rate_p_rp, cf.rate_p_rp);
  EXPECT_EQ(c.controller.vel_p_xy, cf.vel_p_xy);
  const Fleet f = c.fleet();
  EXPECT_EQ(f.airframe_of, std::vector<int>(4, 0));
  EXPECT_EQ(fleet_summary(f), "crazyflie: drones 0-3");
}

TEST(Airframes, GroupsGiveSomeDronesAnotherAirframe) {
  ServerConfig c = load_server_config(
      write("scenario:\n  drones: 6\nquadrotor:\n  groups:\n    - ids: \"0-1,4\"\n"
            "      airframe: crazyflie\n      quadrotor: {motor_tau_s: 0.02}\n"
            "      controller: {vel_p_xy: 2.0}\n"));
  EXPECT_EQ(c.quadrotor.airframe, Airframe::kGeneric);
  const Fleet f = c.fleet();
  ASSERT_EQ(f.quadrotors.size(), 2u);
  EXPECT_EQ(f.airframe_of, (std::vector<int>{1, 1, 0, 0, 1, 0}));
  EXPECT_EQ(f.quadrotors[1].airframe, Airframe::kCrazyflie);
  EXPECT_EQ(f.quadrotors[1].motor_tau_s, 0.02);
  EXPECT_EQ(f.quadrotors[1].mass_kg, 0.027);
  EXPECT_EQ(f.controllers[1].vel_p_xy, 2.0);
  EXPECT_EQ(f.controllers[1].rate_p_rp, ControllerConfig::preset(Airframe::kCrazyflie).rate_p_rp);
  EXPECT_EQ(f.controllers[0].vel_p_xy, ControllerConfig{}.vel_p_xy);
  EXPECT_EQ(fleet_summary(f), "generic: drones 2-3,5; crazyflie: drones 0-1,4");
}

TEST(Airframes, BadInputNamesLineFieldAndValue) {
  EXPECT_EQ(error_for("quadrotor:\n  airframe: tello\n"),
            "2: quadrotor.airframe = tello: must be one of crazyflie|generic");
  EXPECT_EQ(error_for("quadrotor:\n  groups:\n    - ids: \"1\"\n      airframe: mavic\n"),
            "4: quadrotor.groups[0].airframe = mavic: must be one of crazyflie|generic");
  EXPECT_EQ(error_for("scenario:\n  drones: 6\nquadrotor:\n  groups:\n    - ids: \"4-7\"\n"
                      "      airframe: crazyflie\n"),
            "5: quadrotor.groups[0].ids = \"4-7\": ids must be in [0, 5]");
  EXPECT_EQ(error_for("quadrotor:\n  groups:\n    - {ids: \"0-2\", airframe: crazyflie}\n"
                      "    - {ids: \"2\", airframe: generic}\n"),
            "4: quadrotor.groups[1].ids = \"2\": drone 2 is already in groups[0]");
  EXPECT_EQ(error_for("quadrotor:\n  groups:\n    - ids: \"0\"\n      airframe: crazyflie\n"
                      "      quadrotor:\n        mass_kg: -1\n"),
            "6: quadrotor.groups[0].quadrotor.mass_kg = -1: must be > 0");
  EXPECT_EQ(error_for("quadrotor:\n  groups:\n    - ids: \"0\"\n      controller:\n"
                      "        rate_p_rp: 0\n"),
            "5: quadrotor.groups[0].controller.rate_p_rp = 0: must be > 0");
  EXPECT_EQ(error_for("quadrotor:\n  groups:\n    - {airframe: crazyflie}\n"),
            "3: quadrotor.groups[0].ids = \"\": every group needs its drone ids");
  EXPECT_EQ(error_for("quadrotor:\n  groups:\n    - {ids: \"0\", colour: red}\n"),
            "3: quadrotor.groups[0].colour: unknown key");
  EXPECT_EQ(error_for("quadrotor:\n  airframe: crazyflie\n  mass_kg: 0.1\n"),
            "3: quadrotor.mass_kg = 0.1: needs more than 91 % of the rotors' total thrust "
            "(0.595743 N) to hover");
}

TEST(Airframes, TheReferenceDescribesEveryField) {
  using Mismatches = std::vector<std::string>;
  const std::string doc = configuration_reference();
  EXPECT_EQ(reference_mismatches(doc, "### `quadrotor:`", field_rows<QuadrotorParams>()),
            Mismatches{});
  EXPECT_EQ(reference_mismatches(doc, "### `controller:`", field_rows<ControllerConfig>()),
            Mismatches{});
  EXPECT_EQ(reference_mismatches(doc, "### `sensors:`", field_rows<SensorConfig>()), Mismatches{});
}

}  // namespace
}  // namespace ddswarm::sim
