#include "ground_station/gs_config.hpp"

namespace ddswarm::gs {

void load(YamlSection s, GroundStationConfig& c) {
  FieldLoader load(s);
  GroundStationConfig::fields(c, load);
  s.finish();
}

void GroundStationConfig::validate() const {
  FieldChecker check("ground_station");
  fields(*this, check);
}

void load(YamlSection s, TaskConfig& c) {
  FieldLoader load(s);
  TaskConfig::fields(c, load);
  s.finish();
}

void TaskConfig::validate() const {
  FieldChecker check("task");
  fields(*this, check);
}

}  // namespace ddswarm::gs
