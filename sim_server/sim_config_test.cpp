#include "sim_server/sim_server.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include "common/config_reference.hpp"

using namespace ddswarm;
using namespace ddswarm::sim;

namespace {
std::string error_for(const std::string& yaml) {
  const std::string path = ::testing::TempDir() + "/scenario_under_test.yaml";
  std::ofstream(path) << yaml;
  try {
    load_server_config(path);
  } catch (const ConfigError& e) {
    std::string m = e.what();
    return m.substr(m.find(':') + 1);  // drop the temp path
  }
  return "";
}
}  // namespace

TEST(ServerConfig, TheShippedScenarioLoads) {
  auto c = load_server_config(std::string(DDSWARM_CONFIG_DIR) + "/thesis_course.yaml");
  EXPECT_EQ(c.scenario.drones, 6);
  EXPECT_EQ(c.sim.substeps(), 20);
  EXPECT_GE(c.scene.cylinders.size(), 10u);
  EXPECT_FALSE(c.sim.lockstep_pipeline);  // the thesis's lockstep: a command flies the step right
                                          // after its state
  EXPECT_FALSE(c.sim.realtime_pipeline);
}

TEST(ServerConfig, BadInputNamesLineFieldAndValue) {
  EXPECT_EQ(error_for("scenario:\n  drones: 0\n"), "2: scenario.drones = 0: must be in [1, 1024]");
  EXPECT_EQ(error_for("sim:\n  physics_rate_hz: 1000\n  control_rate_hz: 30\n"),
            "3: sim.control_rate_hz = 30: must divide physics_rate_hz (1000)");
  EXPECT_EQ(error_for("scene:\n  cylinders:\n    - {center_xy: [5, 5], radius_m: -2}\n"),
            "3: scene.cylinders[0].radius_m = -2: must be > 0");
  EXPECT_EQ(error_for("sim:\n  realtime_grace: 1.5\n"),
            "2: sim.realtime_grace = 1.5: must be in [0, 0.9]");
  EXPECT_EQ(error_for("sim:\n  lockstep_pipeline: maybe\n"),
            "2: sim.lockstep_pipeline = maybe: must be true or false");
  EXPECT_EQ(error_for("sim:\n  realtime_pipeline: 2\n"),
            "2: sim.realtime_pipeline = 2: must be true or false");
  // Lockstep reads its streams reliably whatever dds.best_effort_streams says.
  EXPECT_EQ(error_for("scenario:\n  mode: lockstep\ndds:\n  best_effort_streams: true\n"), "");
  EXPECT_EQ(error_for("dds:\n  best_effort_streams: sometimes\n"),
            "2: dds.best_effort_streams = sometimes: must be true or false");
  EXPECT_EQ(error_for("dds:\n  shm_transport: false\n"), "");
  EXPECT_EQ(error_for("dds:\n  shm_transport: udp\n"),
            "2: dds.shm_transport = udp: must be true or false");
  EXPECT_EQ(error_for("sim:\n  colour: red\n"), "2: sim.colour: unknown key");
  EXPECT_EQ(error_for("sim:\n  task_timeout_s: 60\n  metrics_range_m: 0\n"),
            "3: sim.metrics_range_m = 0: must be > 0");
  EXPECT_EQ(error_for("sim:\n  near_miss_m: -0.5\n"), "2: sim.near_miss_m = -0.5: must be > 0");
  EXPECT_EQ(error_for("sim:\n  near_miss_m: 2000\n"), "2: sim.near_miss_m = 2000: must be <= 1000");
  EXPECT_EQ(error_for("sim:\n  metrics_lambda2_max_drones: 2048\n"),
            "2: sim.metrics_lambda2_max_drones = 2048: must be in [0, 1024]");
  EXPECT_EQ(error_for("sim:\n  metrics_lambda2_max_drones: many\n"),
            "2: sim.metrics_lambda2_max_drones = many: must be an integer");
  EXPECT_EQ(error_for("wings: 2\n"), "1: wings: unknown section");
  EXPECT_EQ(error_for("sensors:\n  count: many\n"), "2: sensors.count = many: must be an integer");
  EXPECT_EQ(error_for("scene:\n  bounds_min: [0, 0, 0]\n  bounds_max: [12, 16, 15]\nsensors:\n  "
                      "max_range_m: 26\n"),
            "5: sensors.max_range_m = 26: must be <= the world's size (diagonal of "
            "scene.bounds_min..bounds_max, 25 m)");
}

TEST(ServerConfig, TheReferenceDescribesEverySimField) {
  EXPECT_EQ(reference_mismatches(configuration_reference(), "### `sim:`", field_rows<SimConfig>()),
            std::vector<std::string>{});
}

TEST(ServerConfig, SwarmMetricsFieldsReachTheRefereesOptions) {
  const std::string path = ::testing::TempDir() + "/metrics_scenario.yaml";
  std::ofstream(path) << "sim:\n  metrics_range_m: 25\n  near_miss_m: 0.6\n"
                         "  metrics_lambda2_max_drones: 0\n";
  const SwarmMetricsOptions o = load_server_config(path).sim.metrics();
  EXPECT_EQ(o.range_m, 25.0);
  EXPECT_EQ(o.near_miss_m, 0.6);
  EXPECT_EQ(o.lambda2_max_drones, 0);
  const SimConfig defaults;
  EXPECT_EQ(defaults.metrics().range_m, 10.0);
  EXPECT_EQ(defaults.metrics().near_miss_m, 1.0);
  EXPECT_EQ(defaults.metrics().lambda2_max_drones, 128);
}

TEST(ServerConfig, MissingFileIsAClearError) {
  try {
    load_server_config("/no/such/scenario.yaml");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_STREQ(e.what(), "/no/such/scenario.yaml: cannot open file");
  }
}

TEST(ServerConfig, WindAeroAndGeneratedWorldsAreReadChecked) {
  EXPECT_EQ(
      error_for("wind:\n  steady_mps: [3, 0, 0]\n  turbulence: true\n  gusts_per_minute: 2\naero:\n"
                "  ground_effect: true\n  downwash: true\n"),
      "");
  EXPECT_EQ(error_for("wind:\n  turbulence: true\n")
                .rfind("2: wind.turbulence = true: Dryden turbulence", 0),
            0u);
  EXPECT_EQ(error_for("wind:\n  gusts_per_minute: -1\n"),
            "2: wind.gusts_per_minute = -1: must be in [0, 600]");
  EXPECT_NE(error_for("aero:\n  ground_efect: true\n").find("ground_efect"), std::string::npos);
  EXPECT_EQ(
      error_for("scene:\n  generate:\n    walls:\n      count: 1\n      window_height_m: 9\n"),
      "5: scene.generate.walls.window_height_m = 9: a window from 1 m up this tall does not fit in "
      "a "
      "wall 6 m high");
  // The server generates the world once, into the scene it publishes.
  const std::string path = ::testing::TempDir() + "/forest.yaml";
  std::ofstream(path)
      << "scenario:\n  seed: 5\nscene:\n  generate:\n    forest:\n      density_per_100m2: 1\n";
  const ServerConfig c = load_server_config(path);
  EXPECT_EQ(c.scene.cylinders.size(), 36u) << "1 per 100 m² over the default 80 m x 45 m";
  EXPECT_NE(c.generated_world.find("a forest of 36 pillars (of 36 wanted)"), std::string::npos)
      << c.generated_world;
  EXPECT_EQ(load_server_config(path).scene.cylinders[7].center_xy, c.scene.cylinders[7].center_xy)
      << "seeded";
}
