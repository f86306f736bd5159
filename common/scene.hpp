#pragma once
// The world the swarm flies in: ground, obstacles, bounds, finish line, goal
// and start positions. World frame ENU (x east, y north, z up), metres.
//
// Loaded from the scenario's `scene:` section by the server, published on the
// transient-local Scene topic, and read back from there by every other process.
#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "common/yaml_section.hpp"

namespace ddswarm {

/// A vertical cylinder standing on the ground (the thesis's pillars).
struct Cylinder {
  Eigen::Vector2d center_xy{0, 0};  ///< m, ENU
  double radius_m = 1.0;            ///< m, > 0
  double height_m = 10.0;           ///< m, > 0
};

/// A box standing on the ground, rotated about z by yaw.
struct Box {
  Eigen::Vector3d center{0, 0, 1};  ///< m, ENU
  Eigen::Vector3d size{1, 1, 2};    ///< full extents x, y, z in m, each > 0
  double yaw_rad = 0.0;             ///< rad, rotation about +z
};

enum class Formation { kCluster, kGrid, kRandom, kExplicit };

/// Where drones start. kCluster packs drones on a hexagonal lattice around
/// center; kGrid lays rows; kRandom scatters them (seeded) in a disc with a
/// minimum spacing; kExplicit uses positions as listed.
struct StartConfig {
  Formation formation = Formation::kCluster;
  Eigen::Vector2d center_xy{0, 0};           ///< m
  double spacing_m = 2.0;                    ///< m between neighbours, >= 0.7
  double radius_m = 8.0;                     ///< m, disc radius for kRandom
  double yaw_rad = 0.0;                      ///< initial heading of every drone
  std::vector<Eigen::Vector3d> positions;    ///< kExplicit: one per drone (z = 0 on ground)
};

/// The control rates a server flies (sim.control_rate_hz), and an agent
/// accepts in a scene: one tick per control period.
constexpr double kMinControlRateHz = 1.0;
constexpr double kMaxControlRateHz = 1000.0;

struct SceneConfig {
  double ground_z_m = 0.0;                   ///< m, height of the ground plane
  std::vector<Cylinder> cylinders;
  std::vector<Box> boxes;
  Eigen::Vector3d bounds_min{-100, -100, 0};  ///< m, world bounds (leaving them is reported)
  Eigen::Vector3d bounds_max{100, 100, 50};
  Eigen::Vector2d finish_a{-50, 60};  ///< m, one end of the finish line (xy)
  Eigen::Vector2d finish_b{50, 60};   ///< m, other end
  Eigen::Vector2d goal_xy{0, 70};     ///< m, a point past the finish line the task flies to
  StartConfig start;

  void validate() const;  ///< throws FieldError("scene.…")

  /// Unit vector (xy) from the start centre toward the goal.
  Eigen::Vector2d task_direction() const;
  /// True when p is on the goal's side of the finish line.
  bool past_finish(const Eigen::Vector2d& p) const;
  /// Horizontal clearance from p (at height z) to the nearest obstacle surface
  /// (negative inside); +inf when there are no obstacles.
  double clearance(const Eigen::Vector3d& p) const;
  /// Start positions for n drones (z = ground). Throws FieldError if they do
  /// not fit (overlap an obstacle, or explicit list shorter than n).
  std::vector<Eigen::Vector3d> start_positions(int n, std::uint64_t seed) const;
};

void load(YamlSection s, SceneConfig& c);

}  // namespace ddswarm
