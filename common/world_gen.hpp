#pragma once
// Generated worlds: YAML `scene.generate`. From a seed, the server adds
// obstacles to the scene before it publishes it, so agents, tools and
// recordings see exactly the world it simulates:
//   - forest:   Poisson-disc pillars (density, radius and height ranges) in an
//               area, none within keep_out_m of the start centre or the goal;
//   - walls:    walls across the course (perpendicular to the start-to-goal
//               axis) with openings: gaps from the ground up, or windows
//               (window_height_m > 0) a swarm must climb to;
//   - corridor: a canyon along the axis, zig-zagging at its bends;
//   - urban:    boxes of random footprint and height on a street grid.
// Everything is made of the scene's cylinders and boxes. World frame ENU, metres.
#include <Eigen/Core>
#include <cstdint>
#include <string>

#include "common/config_fields.hpp"

namespace ddswarm {

struct SceneConfig;

struct ForestConfig {
  double density_per_100m2 = 0;  ///< 0 = no forest
  Eigen::Vector2d radius_m{0.3, 0.6};
  Eigen::Vector2d height_m{8, 15};
  Eigen::Vector2d area_min{-40, 10};
  Eigen::Vector2d area_max{40, 55};
  double min_gap_m = 1.5;
  double keep_out_m = 8;

  template <class Self, class V>
  static void fields(Self& c, V& v) {
    v.field("density_per_100m2", c.density_per_100m2,
            {"1/(100 m²)", non_negative(), "pillars per 100 m²; 0 = none"});
    v.field("radius_m", c.radius_m, {"m", any(), "[min, max] radius, 0 < min <= max"});
    v.field("height_m", c.height_m, {"m", any(), "[min, max] height, 0 < min <= max"});
    v.field("area_min", c.area_min, {"m", any(), "the forest's corner (xy)"});
    v.field("area_max", c.area_max,
            {"m", any(), "the opposite corner, above area_min on both axes"});
    v.field("min_gap_m", c.min_gap_m,
            {"m", non_negative(), "free space between two pillars at least"});
    v.field("keep_out_m", c.keep_out_m,
            {"m", non_negative(), "no pillar this close to the start centre or the goal"});
  }
};

struct WallsConfig {
  int count = 0;  ///< 0 = no walls
  double first_at_m = 20;
  double spacing_m = 12;
  double length_m = 60;
  double height_m = 6;
  double thickness_m = 0.3;
  int openings = 1;
  double opening_width_m = 4;
  double window_height_m = 0;
  double window_bottom_m = 1;

  template <class Self, class V>
  static void fields(Self& c, V& v) {
    v.field("count", c.count, {"", in(0, 100), "walls across the course; 0 = none"});
    v.field("first_at_m", c.first_at_m,
            {"m", positive(), "the first wall's distance from the start centre along the course"});
    v.field("spacing_m", c.spacing_m, {"m", positive(), "between two walls along the course"});
    v.field("length_m", c.length_m,
            {"m", positive(), "each wall's length, centred on the course's axis"});
    v.field("height_m", c.height_m, {"m", positive(), "each wall's height"});
    v.field("thickness_m", c.thickness_m, {"m", positive(), "each wall's thickness"});
    v.field("openings", c.openings, {"", in(1, 20), "openings per wall, at seeded places"});
    v.field("opening_width_m", c.opening_width_m, {"m", positive(), "each opening's width"});
    v.field("window_height_m", c.window_height_m,
            {"m", non_negative(),
             "0: the openings are gaps from the ground up; else windows this tall"});
    v.field("window_bottom_m", c.window_bottom_m,
            {"m", non_negative(), "a window's sill above the ground"});
  }
};

struct CorridorConfig {
  double length_m = 0;  ///< 0 = no corridor
  double start_at_m = 10;
  double width_m = 8;
  int bends = 0;
  double bend_deg = 25;
  double wall_height_m = 8;
  double thickness_m = 0.3;

  template <class Self, class V>
  static void fields(Self& c, V& v) {
    v.field("length_m", c.length_m,
            {"m", non_negative(), "the corridor's length along the course; 0 = none"});
    v.field("start_at_m", c.start_at_m,
            {"m", non_negative(), "its entrance's distance from the start centre"});
    v.field("width_m", c.width_m, {"m", positive(), "free width between its walls"});
    v.field("bends", c.bends, {"", in(0, 20), "turns, alternating left and right"});
    v.field("bend_deg", c.bend_deg, {"deg", in(0, 60), "each leg's angle to the course's axis"});
    v.field("wall_height_m", c.wall_height_m, {"m", positive(), "its walls' height"});
    v.field("thickness_m", c.thickness_m, {"m", positive(), "its walls' thickness"});
  }
};

struct UrbanConfig {
  double block_m = 0;  ///< 0 = no city
  double street_m = 8;
  double fill_min = 0.5;
  Eigen::Vector2d height_m{6, 20};
  Eigen::Vector2d area_min{-40, 10};
  Eigen::Vector2d area_max{40, 55};
  double keep_out_m = 8;

  template <class Self, class V>
  static void fields(Self& c, V& v) {
    v.field("block_m", c.block_m, {"m", non_negative(), "a block's side; 0 = none"});
    v.field("street_m", c.street_m, {"m", positive(), "a street's width"});
    v.field("fill_min", c.fill_min,
            {"", in(0.05, 1), "a building's footprint side is [fill_min, 1] of the block's"});
    v.field("height_m", c.height_m, {"m", any(), "[min, max] building height, 0 < min <= max"});
    v.field("area_min", c.area_min, {"m", any(), "the city's corner (xy)"});
    v.field("area_max", c.area_max,
            {"m", any(), "the opposite corner, above area_min on both axes"});
    v.field("keep_out_m", c.keep_out_m,
            {"m", non_negative(), "no building this close to the start centre or the goal"});
  }
};

/// YAML `scene.generate`.
struct WorldGenConfig {
  std::uint64_t seed = 0;  ///< 0 = scenario.seed
  ForestConfig forest;
  WallsConfig walls;
  CorridorConfig corridor;
  UrbanConfig urban;

  template <class Self, class V>
  static void fields(Self& c, V& v) {
    v.field("seed", c.seed, {"", any(), "the world's seed; 0 = scenario.seed"});
    v.section("forest", [&](auto& w) { ForestConfig::fields(c.forest, w); });
    v.section("walls", [&](auto& w) { WallsConfig::fields(c.walls, w); });
    v.section("corridor", [&](auto& w) { CorridorConfig::fields(c.corridor, w); });
    v.section("urban", [&](auto& w) { UrbanConfig::fields(c.urban, w); });
  }

  /// True when something is to be generated.
  bool enabled() const {
    return forest.density_per_100m2 > 0 || walls.count > 0 || corridor.length_m > 0 ||
           urban.block_m > 0;
  }
  /// Throws FieldError("scene.generate.…") for what the field list cannot
  /// check: ranges whose ends are ordered, openings that fit their wall.
  void validate() const;
};

/// What generate_world added.
struct WorldGenReport {
  int pillars = 0, pillars_wanted = 0;  ///< the forest (fewer when the area is full)
  int wall_boxes = 0, corridor_boxes = 0, buildings = 0;
  std::string summary() const;  ///< "forest 120 pillars (of 120), 3 walls (9 boxes), ..."
};

/// Adds the obstacles g describes to scene, drawn from seed (g.seed, or
/// scenario_seed when it is 0): the same seed gives the same world.
WorldGenReport generate_world(const WorldGenConfig& g, std::uint64_t scenario_seed,
                              SceneConfig& scene);

}  // namespace ddswarm
