#include "ground_station/gs_config.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "common/config_error.hpp"
#include "common/config_reference.hpp"

namespace ddswarm::gs {
namespace {

template <class C>
std::string error(const C& c) {
  try {
    c.validate();
  } catch (const FieldError& e) {
    return e.what();
  }
  return "";
}

TEST(GsConfig, DefaultsAreValid) {
  EXPECT_EQ(error(GroundStationConfig{}), "");
  EXPECT_EQ(error(TaskConfig{}), "");
}

TEST(GsConfig, OutOfRangeValuesNameTheirField) {
  GroundStationConfig g;
  g.discovery_timeout_s = 0;
  EXPECT_EQ(error(g), "ground_station.discovery_timeout_s = 0: must be in [0.1, 600]");
  g = GroundStationConfig{};
  g.server_timeout_s = -1;
  EXPECT_EQ(error(g), "ground_station.server_timeout_s = -1: must be > 0");
  TaskConfig t;
  t.speed_mps = 80;
  EXPECT_EQ(error(t), "task.speed_mps = 80: must be in [0.01, 50]");
}

TEST(GsConfig, TheReferenceDescribesEveryField) {
  EXPECT_EQ(reference_mismatches(configuration_reference(), "### `ground_station:`",
                                 field_rows<GroundStationConfig>()),
            std::vector<std::string>{});
  EXPECT_EQ(
      reference_mismatches(configuration_reference(), "### `task:`", field_rows<TaskConfig>()),
      std::vector<std::string>{});
}

}  // namespace
}  // namespace ddswarm::gs
