#include "ground_station/gs_config.hpp"

namespace ddswarm::gs {

void load(YamlSection s, GroundStationConfig& c) {
  s.get("name", c.name);
  s.get("ack_timeout_s", c.ack_timeout_s);
  s.get("online_window_s", c.online_window_s);
  s.get("discovery_timeout_s", c.discovery_timeout_s);
  s.get("task_timeout_s", c.task_timeout_s);
  s.get("server_timeout_s", c.server_timeout_s);
  s.get("max_input_speed_mps", c.max_input_speed_mps);
  s.get("max_input_time_s", c.max_input_time_s);
  s.get("results_csv", c.results_csv);
  s.get("shared_memory", c.shared_memory);
  s.finish();
}

void GroundStationConfig::validate() const {
  check_range("ground_station.ack_timeout_s", ack_timeout_s, 0.1, 600.0);
  check_range("ground_station.online_window_s", online_window_s, 0.3, 60.0);
  check_range("ground_station.discovery_timeout_s", discovery_timeout_s, 0.1, 600.0);
  check_positive("ground_station.task_timeout_s", task_timeout_s);
  check_positive("ground_station.server_timeout_s", server_timeout_s);
  check_positive("ground_station.max_input_speed_mps", max_input_speed_mps);
  check_positive("ground_station.max_input_time_s", max_input_time_s);
}

void load(YamlSection s, TaskConfig& c) {
  s.get("speed_mps", c.speed_mps);
  s.get("epsilon_m", c.epsilon_m);
  s.finish();
}

void TaskConfig::validate() const {
  check_range("task.speed_mps", speed_mps, 0.01, 50.0);
  check_range("task.epsilon_m", epsilon_m, 0.0, 10000.0);
}

}  // namespace ddswarm::gs
