// ServerConfig: what the server reads from a scenario file, and its checks.
#include "sim_server/sim_server.hpp"

#include <filesystem>

#include "common/mesh_loader.hpp"
#include "common/world_gen.hpp"

namespace ddswarm::sim {

void ServerConfig::validate() const {
  scenario.validate();
  sim.validate();
  quadrotor.validate();
  controller.validate();
  (void)fleet();  // the groups' airframes, gains and ids
  sensors.validate();
  scene.validate();
  wind.validate();
  // Nothing lies beyond the world's bounds: a longer ray is a typo (cm for m?).
  const double world_m = (scene.bounds_max - scene.bounds_min).norm();
  if (sensors.max_range_m > world_m)
    throw FieldError("sensors.max_range_m", to_text(sensors.max_range_m),
                     "must be <= the world's size (diagonal of scene.bounds_min..bounds_max, " +
                         to_text(world_m) + " m)");
  dds.validate();
  (void)scene.start_positions(scenario.drones, scenario.seed);
}

Fleet ServerConfig::fleet() const {
  return make_fleet(quadrotor, controller, airframe_groups, scenario.drones);
}

ServerConfig load_server_config(const std::string& path) {
  auto doc = load_scenario(path);
  ServerConfig c;
  doc.guard([&] {
    load(doc.section("scenario"), c.scenario);
    load(doc.section("sim"), c.sim);
    // The airframe sets the controller's gains; `controller:` goes over them.
    load_airframes(doc.section("quadrotor"), c.quadrotor, c.controller, c.airframe_groups);
    load(doc.section("controller"), c.controller);
    load(doc.section("sensors"), c.sensors);
    load(doc.section("scene"), c.scene);
    load(doc.section("wind"), c.wind);
    load(doc.section("aero"), c.aero);
    load(doc.section("dds"), c.dds);
    c.scene.validate();
    // Mesh files are read by the server alone, relative to the scenario file.
    load_meshes(c.scene, std::filesystem::path(path).parent_path());
    // The server generates the world once, before anything is placed in it;
    // every other process receives it in the Scene.
    if (c.scene.generate.enabled())
      c.generated_world = generate_world(c.scene.generate, c.scenario.seed, c.scene).summary();
    c.validate();
  });
  return c;
}

}  // namespace ddswarm::sim
