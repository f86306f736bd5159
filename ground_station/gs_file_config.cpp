#include "ground_station/gs_file_config.hpp"

#include "common/scenario.hpp"

namespace ddswarm::gs {

GsFileConfig load_gs_config(const std::string& path) {
  GsFileConfig c;
  if (path.empty()) return c;
  auto doc = load_scenario(path);
  doc.guard([&] {
    ScenarioConfig sc;
    load(doc.section("scenario"), sc);
    sc.validate();
    c.drones = sc.drones;
    load(doc.section("ground_station"), c.gs);
    load(doc.section("task"), c.task);
    load(doc.section("dds"), c.dds);
    c.gs.validate();
    c.task.validate();
    c.dds.validate();
  });
  return c;
}

}  // namespace ddswarm::gs
