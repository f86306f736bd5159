#pragma once
// The `ground_station:` section.
#include <string>

#include "common/yaml_section.hpp"

namespace ddswarm::gs {

struct GroundStationConfig {
  std::string name = "gs";       ///< issuer name on mission commands
  double ack_timeout_s = 5.0;    ///< s wall: how long to wait for every live agent's ack
  double online_window_s = 1.5;  ///< s wall: an agent heard within this is online
  double discovery_timeout_s =
      10.0;  ///< s wall: how long to wait for the server at start (docs/configuration.md: why 10)
  double task_timeout_s = 900.0;  ///< s wall: give up waiting for a task
  double server_timeout_s =
      30.0;  ///< s wall: give up on a task whose server stays silent this long
  double max_input_speed_mps = 10;  ///< m/s, the console refuses faster moves
  double max_input_time_s = 3600;   ///< s, the console refuses longer moves
  std::string results_csv;          ///< append each task's result here ("" = don't)
  bool shared_memory =
      false;  ///< the ground station's own participants add SHM (docs/configuration.md: why not)

  void validate() const;
};

void load(YamlSection s, GroundStationConfig& c);

/// The `task:` section: the thesis task as the ground station issues it.
struct TaskConfig {
  double speed_mps = 0.8;  ///< m/s, wanted velocity toward the goal (thesis Sim 1), (0, 50]
  double epsilon_m = 0.0;  ///< m, swarm-condition size (Eq. 3.1); 0 = 2 * D_int + 1
  void validate() const;
};

void load(YamlSection s, TaskConfig& c);

}  // namespace ddswarm::gs
