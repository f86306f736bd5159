#include "common/world_gen.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "common/config_reference.hpp"
#include "common/scene.hpp"

using namespace ddswarm;
using Eigen::Vector2d;
using Eigen::Vector3d;

namespace {

/// The thesis course's frame without its pillars: start at the origin, goal 70 m north.
SceneConfig open_course() {
  SceneConfig s;
  s.bounds_min = {-100, -100, 0};
  s.bounds_max = {100, 150, 30};
  return s;
}

SceneConfig generated(const WorldGenConfig& g, std::uint64_t seed = 7) {
  SceneConfig s = open_course();
  generate_world(g, seed, s);
  return s;
}

std::string error_of(const std::string& yaml) {
  try {
    auto doc = YamlDocument::parse(yaml, "w.yaml");
    doc.guard([&] {
      SceneConfig s;
      load(doc.section("scene"), s);
      s.validate();
    });
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

bool same_world(const SceneConfig& a, const SceneConfig& b) {
  if (a.cylinders.size() != b.cylinders.size() || a.boxes.size() != b.boxes.size()) return false;
  for (std::size_t k = 0; k < a.cylinders.size(); ++k)
    if (a.cylinders[k].center_xy != b.cylinders[k].center_xy ||
        a.cylinders[k].radius_m != b.cylinders[k].radius_m)
      return false;
  for (std::size_t k = 0; k < a.boxes.size(); ++k)
    if (a.boxes[k].center != b.boxes[k].center || a.boxes[k].size != b.boxes[k].size) return false;
  return true;
}

WorldGenConfig a_forest(double density) {
  WorldGenConfig g;
  g.forest.density_per_100m2 = density;
  return g;
}

}  // namespace

TEST(WorldGen, ASeedIsAWorld) {
  WorldGenConfig g = a_forest(1.0);
  g.walls.count = 2;
  g.urban.block_m = 10;
  g.urban.area_min = {-60, 80};
  g.urban.area_max = {60, 120};
  EXPECT_TRUE(same_world(generated(g, 7), generated(g, 7)));
  EXPECT_FALSE(same_world(generated(g, 7), generated(g, 8)));
  g.seed = 99;  // the world's own seed wins over the scenario's
  EXPECT_TRUE(same_world(generated(g, 7), generated(g, 8)));
}

TEST(WorldGen, AForestHasTheDensityAskedForItsSpacingAndItsKeepOuts) {
  const WorldGenConfig g = a_forest(1.5);
  const SceneConfig s = generated(g);
  const double area = 80.0 * 45.0;  // the default area, 80 m by 45 m
  const double wanted = 1.5 * area / 100;
  ASSERT_NEAR(static_cast<double>(s.cylinders.size()), wanted, 0.5) << "54 pillars fit easily";
  for (std::size_t i = 0; i < s.cylinders.size(); ++i) {
    const auto& a = s.cylinders[i];
    EXPECT_GE(a.radius_m, g.forest.radius_m.x());
    EXPECT_LE(a.radius_m, g.forest.radius_m.y());
    EXPECT_GE(a.height_m, g.forest.height_m.x());
    EXPECT_LE(a.height_m, g.forest.height_m.y());
    EXPECT_GE((a.center_xy - s.start.center_xy).norm(), g.forest.keep_out_m + a.radius_m);
    EXPECT_GE((a.center_xy - s.goal_xy).norm(), g.forest.keep_out_m + a.radius_m);
    for (std::size_t j = i + 1; j < s.cylinders.size(); ++j) {
      const auto& b = s.cylinders[j];
      EXPECT_GE((a.center_xy - b.center_xy).norm(),
                a.radius_m + b.radius_m + g.forest.min_gap_m - 1e-9);
    }
  }
  // A full area stops at what fits, and says so.
  SceneConfig full = open_course();
  const WorldGenReport r = generate_world(a_forest(50), 7, full);
  EXPECT_LT(r.pillars, r.pillars_wanted);
  EXPECT_GT(r.pillars, 100);
  EXPECT_NE(r.summary().find("of 1800 wanted"), std::string::npos) << r.summary();
}

TEST(WorldGen, AForestKeepsClearOfTheOtherObstacles) {
  WorldGenConfig g = a_forest(2.0);
  g.walls.count = 3;
  const SceneConfig s = generated(g);
  SceneConfig walls_only = open_course();
  WorldGenConfig w;
  w.walls = g.walls;
  generate_world(w, 7, walls_only);
  for (const auto& c : s.cylinders)
    EXPECT_GE(walls_only.clearance(Vector3d(c.center_xy.x(), c.center_xy.y(), 0.5)),
              c.radius_m + g.forest.min_gap_m);
}

TEST(WorldGen, WallsCrossTheCourseWithTheirGaps) {
  WorldGenConfig g;
  g.walls.count = 3;
  g.walls.openings = 2;
  g.walls.opening_width_m = 4;
  const SceneConfig s = generated(g);
  const Vector2d along = s.task_direction();
  for (int k = 0; k < 3; ++k) {
    const double y = g.walls.first_at_m + k * g.walls.spacing_m;  // the course runs north
    ASSERT_NEAR(along.y(), 1.0, 1e-12);
    // Walk along the wall at 2 m: free stretches are the gaps.
    int gaps = 0;
    double run = 0, widest_blocked_run = 0;
    bool in_gap = false;
    for (double x = -30; x <= 30; x += 0.05) {
      const bool free = s.clearance(Vector3d(x, y, 2.0)) > 0;
      if (free && !in_gap) ++gaps;
      in_gap = free;
      run = free ? 0 : run + 0.05;
      widest_blocked_run = std::max(widest_blocked_run, run);
      // Above the wall, nothing.
      EXPECT_GT(s.clearance(Vector3d(x, y, g.walls.height_m + 0.5)), 0);
    }
    EXPECT_EQ(gaps, 2) << "wall " << k;
    EXPECT_GT(widest_blocked_run, 5) << "a wall, not a fence";
  }
}

TEST(WorldGen, WindowsOpenOnlyBetweenSillAndLintel) {
  WorldGenConfig g;
  g.walls.count = 1;
  g.walls.openings = 1;
  g.walls.window_height_m = 2.5;
  g.walls.window_bottom_m = 1.5;
  const SceneConfig s = generated(g);
  const double y = g.walls.first_at_m;
  // Find the window: free at its middle height, somewhere along the wall.
  double window_x = NAN;
  for (double x = -29; x <= 29 && std::isnan(window_x); x += 0.05)
    if (s.clearance(Vector3d(x, y, 2.75)) > 0.5) window_x = x;
  ASSERT_FALSE(std::isnan(window_x)) << "no window found";
  EXPECT_LT(s.clearance(Vector3d(window_x, y, 0.7)), 0) << "below the sill: wall";
  EXPECT_LT(s.clearance(Vector3d(window_x, y, 5.0)), 0) << "above the lintel: wall";
  // Flying low through the wall is closed everywhere but past its ends.
  for (double x = -29; x <= 29; x += 0.1) EXPECT_LT(s.clearance(Vector3d(x, y, 1.0)), 0.5) << x;
}

TEST(WorldGen, ACorridorLeavesItsWidthFreeAlongItsCentreLine) {
  WorldGenConfig g;
  g.corridor.length_m = 50;
  g.corridor.width_m = 6;
  g.corridor.bends = 3;
  g.corridor.bend_deg = 20;
  const SceneConfig s = generated(g);
  ASSERT_EQ(s.boxes.size(), 8u) << "4 legs, 2 walls each";
  // Follow the free channel: at each step along the course, the middle of
  // the free stretch across it is at least width/2 from every wall, and the
  // walls close it in on both sides.
  for (double y = g.corridor.start_at_m + 2; y < g.corridor.start_at_m + g.corridor.length_m - 2;
       y += 0.5) {
    double lo = NAN, hi = NAN;
    for (double x = -20; x <= 20; x += 0.02) {
      const bool free = s.clearance(Vector3d(x, y, 2.0)) > 0;
      if (free && std::isnan(lo) && x > -19) {
        // the stretch that holds the channel: bounded on its left by a wall
        if (s.clearance(Vector3d(x - 0.05, y, 2.0)) <= 0) lo = x;
      }
      if (!std::isnan(lo) && std::isnan(hi) && !free) hi = x;
    }
    ASSERT_FALSE(std::isnan(lo) || std::isnan(hi)) << "no channel at y = " << y;
    EXPECT_GT(hi - lo, g.corridor.width_m * std::cos(20 * M_PI / 180) - 0.2) << y;
    EXPECT_GT(s.clearance(Vector3d(0.5 * (lo + hi), y, 2.0)), 0.5 * g.corridor.width_m * 0.85) << y;
  }
}

TEST(WorldGen, ACityHasItsStreetsFree) {
  WorldGenConfig g;
  g.urban.block_m = 12;
  g.urban.street_m = 6;
  g.urban.area_min = {-40, 10};
  g.urban.area_max = {40, 60};
  const SceneConfig s = generated(g);
  ASSERT_GT(s.boxes.size(), 6u);
  for (const auto& b : s.boxes) {
    EXPECT_GE(b.size.z(), g.urban.height_m.x());
    EXPECT_LE(b.size.z(), g.urban.height_m.y());
    EXPECT_LE(b.size.x(), g.urban.block_m + 1e-9);
    EXPECT_GE(b.size.x(), g.urban.fill_min * g.urban.block_m - 1e-9);
  }
  // The streets between the blocks: a line along the middle of each is clear
  // by half a street at least.
  const double pitch = g.urban.block_m + g.urban.street_m;
  int streets = 0;
  for (double x =
           g.urban.area_min.x() + 0.5 * g.urban.street_m + g.urban.block_m + 0.5 * g.urban.street_m;
       x + 0.5 * g.urban.street_m < g.urban.area_max.x(); x += pitch, ++streets)
    for (double y = 10; y < 60; y += 0.5)
      EXPECT_GE(s.clearance(Vector3d(x, y, 1.0)), 0.5 * g.urban.street_m - 1e-9) << x << " " << y;
  EXPECT_GE(streets, 3);
}

TEST(WorldGen, BadInputNamesFieldAndValue) {
  EXPECT_EQ(error_of("scene:\n  generate:\n    forest:\n      density_per_100m2: -1\n"),
            "w.yaml:4: scene.generate.forest.density_per_100m2 = -1: must be >= 0");
  EXPECT_EQ(error_of("scene:\n  generate:\n    forest:\n      density_per_100m2: 1\n      "
                     "radius_m: [0.8, 0.3]\n"),
            "w.yaml:5: scene.generate.forest.radius_m = [0.8, 0.3]: must be [min, max] with 0 < "
            "min <= max");
  EXPECT_EQ(
      error_of(
          "scene:\n  generate:\n    walls:\n      count: 2\n      length_m: 10\n      openings: 2\n"
          "      opening_width_m: 6\n"),
      "w.yaml:7: scene.generate.walls.opening_width_m = 6: 2 openings this wide do not fit in a "
      "wall 10 m long");
  EXPECT_EQ(
      error_of("scene:\n  generate:\n    walls:\n      count: 1\n      window_height_m: 5.5\n"),
      "w.yaml:5: scene.generate.walls.window_height_m = 5.5: a window from 1 m up this tall does "
      "not fit in a "
      "wall 6 m high");
  EXPECT_NE(error_of("scene:\n  generate:\n    forests: {}\n").find("forests"), std::string::npos)
      << "unknown key";
  EXPECT_EQ(
      error_of("scene:\n  generate:\n    corridor:\n      length_m: 40\n      bend_deg: 80\n"),
      "w.yaml:5: scene.generate.corridor.bend_deg = 80: must be in [0, 60]");
}

TEST(WorldGen, TheReferenceDescribesEveryField) {
  std::vector<FieldRow> rows;
  for (const auto& r : field_rows<SceneConfig>())
    if (r.key.rfind("generate.", 0) == 0) rows.push_back(r);
  ASSERT_GT(rows.size(), 20u);
  EXPECT_EQ(reference_mismatches(configuration_reference(), "(`scene.generate`)", rows),
            std::vector<std::string>{});
}
