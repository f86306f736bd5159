#pragma once
// The `ground_station:` section.
#include <string>

#include "common/config_fields.hpp"
#include "common/yaml_section.hpp"

namespace ddswarm::gs {

struct GroundStationConfig {
  std::string name = "gs";
  double ack_timeout_s = 5.0;
  double online_window_s = 1.5;
  double discovery_timeout_s = 10.0;  // docs/configuration.md: why 10
  double task_timeout_s = 900.0;
  double server_timeout_s = 30.0;
  double max_input_speed_mps = 10;
  double max_input_time_s = 3600;
  std::string results_csv;
  bool shared_memory = false;  // docs/configuration.md: why not

  template <class Self, class V>
  static void fields(Self& c, V& v) {
    v.field("name", c.name, {"", any(), "issuer name on mission commands"});
    v.field("ack_timeout_s", c.ack_timeout_s,
            {"s (wall)", in(0.1, 600), "how long to wait for every live agent's ack"});
    v.field("online_window_s", c.online_window_s,
            {"s (wall)", in(0.3, 60), "an agent heard within this is online"});
    v.field("discovery_timeout_s", c.discovery_timeout_s,
            {"s (wall)", in(0.1, 600), "how long to wait for the server at start"});
    v.field("task_timeout_s", c.task_timeout_s,
            {"s (wall)", positive(), "give up waiting for a task"});
    v.field("server_timeout_s", c.server_timeout_s,
            {"s (wall)", positive(), "give up on a task whose server stays silent this long"});
    v.field("max_input_speed_mps", c.max_input_speed_mps,
            {"m/s", positive(), "the console refuses faster moves"});
    v.field("max_input_time_s", c.max_input_time_s,
            {"s", positive(), "the console refuses longer moves"});
    v.field("results_csv", c.results_csv,
            {"", any(), "append each task's result here; \"\" = don't"});
    v.field("shared_memory", c.shared_memory,
            {"", any(), "the ground station's own participants add the shared-memory transport"});
  }

  void validate() const;  ///< throws FieldError("ground_station.…")
};

void load(YamlSection s, GroundStationConfig& c);

/// The `task:` section: the thesis task as the ground station issues it.
struct TaskConfig {
  double speed_mps = 0.8;
  double epsilon_m = 0.0;

  template <class Self, class V>
  static void fields(Self& c, V& v) {
    v.field("speed_mps", c.speed_mps,
            {"m/s", in(0.01, 50), "wanted velocity toward the goal (thesis Sim 1)"});
    v.field("epsilon_m", c.epsilon_m,
            {"m", in(0, 10000), "swarm-condition size (Eq. 3.1); 0 = 2 * D_int + 1"});
  }

  void validate() const;  ///< throws FieldError("task.…")
};

void load(YamlSection s, TaskConfig& c);

}  // namespace ddswarm::gs
