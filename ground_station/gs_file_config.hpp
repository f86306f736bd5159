#pragma once
// Loading the ground station's sections from a scenario file.
#include <string>

#include "common/dds_config.hpp"
#include "ground_station/gs_config.hpp"

namespace ddswarm::gs {

struct GsFileConfig {
  GroundStationConfig gs;
  TaskConfig task;
  DdsConfig dds;
  int drones = 6;  ///< scenario.drones
};

/// Reads ground_station, task, dds and scenario.drones; path empty = defaults.
GsFileConfig load_gs_config(const std::string& path);

}  // namespace ddswarm::gs
