#pragma once
// The world the swarm flies in: ground, obstacles, bounds, finish line, goal
// and start positions. World frame ENU (x east, y north, z up), metres.
//
// Loaded from the scenario's `scene:` section by the server, published on the
// transient-local Scene topic, and read back from there by every other process.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "common/config_fields.hpp"
#include "common/world_gen.hpp"
#include "common/yaml_section.hpp"

namespace ddswarm {

/// A vertical cylinder standing on the ground (the thesis's pillars).
struct Cylinder {
  Eigen::Vector2d center_xy{0, 0};
  double radius_m = 1.0;
  double height_m = 10.0;

  template <class Self, class V>
  static void fields(Self& c, V& v) {
    v.field("center_xy", c.center_xy, {"m", any(), "centre"});
    v.field("radius_m", c.radius_m, {"m", positive(), "radius"});
    v.field("height_m", c.height_m, {"m", positive(), "height above the ground"});
  }
};

/// A box standing on the ground, rotated about z by yaw.
struct Box {
  Eigen::Vector3d center{0, 0, 1};
  Eigen::Vector3d size{1, 1, 2};  ///< each > 0 (SceneConfig::validate)
  double yaw_rad = 0.0;

  template <class Self, class V>
  static void fields(Self& c, V& v) {
    v.field("center", c.center,
            {"m", any(), "centre (absolute: a box on the ground has z = size.z / 2)"});
    v.field("size", c.size, {"m", any(), "full extents along the box's own axes"});
    v.field("yaw_rad", c.yaw_rad, {"rad", any(), "rotation about +z"});
  }
};

/// Triangles in the world frame (m, ENU), as the server simulates a mesh.
struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;  ///< indices into vertices
};

/// A static obstacle made of a mesh file's triangles (OBJ, STL, glTF),
/// scaled, then rotated (rotation_deg: roll about x, pitch about y, yaw
/// about z, applied in that order, then yaw_deg about z), then moved to
/// position. The file is read by the server only (common/mesh_loader.hpp);
/// the Scene carries the entry and what loading found, never the triangles.
struct MeshObstacle {
  std::string file;  ///< relative to the scenario file's folder (or absolute)
  Eigen::Vector3d position{0, 0, 0};
  double yaw_deg = 0.0;
  Eigen::Vector3d rotation_deg{0, 0, 0};
  double scale = 1.0;

  // What loading the file found (or what a Scene sample says it found).
  std::uint32_t triangle_count = 0;                          ///< 0 until loaded
  std::uint64_t content_hash = 0;                            ///< FNV-1a 64 of the file's bytes
  Eigen::Vector3d bounds_min{0, 0, 0}, bounds_max{0, 0, 0};  ///< m, world AABB of the triangles
  /// The triangles in the world frame: the server's only (null from the wire).
  std::shared_ptr<const TriangleMesh> world;

  /// World from file coordinates, without the scale: Rz(yaw_deg) Rz Ry Rx.
  Eigen::Matrix3d rotation() const;

  template <class Self, class V>
  static void fields(Self& c, V& v) {
    v.field("file", c.file,
            {"", any(), "an .obj, .stl, .gltf or .glb file, relative to the scenario file"});
    v.field("position", c.position, {"m", any(), "where the file's origin goes"});
    v.field("yaw_deg", c.yaw_deg, {"deg", any(), "rotation about +z, after rotation_deg"});
    v.field("rotation_deg", c.rotation_deg,
            {"deg", any(), "[roll, pitch, yaw] about x, y, z (e.g. [90, 0, 0]: a y-up file)"});
    v.field("scale", c.scale, {"", positive(), "multiplies the file's coordinates (to metres)"});
  }
};

enum class Formation { kCluster, kGrid, kRandom, kExplicit };

/// Where drones start. kCluster packs drones on a hexagonal lattice around
/// center; kGrid lays rows; kRandom scatters them (seeded) in a disc with a
/// minimum spacing; kExplicit uses positions as listed.
struct StartConfig {
  Formation formation = Formation::kCluster;
  Eigen::Vector2d center_xy{0, 0};         ///< m
  double spacing_m = 2.0;                  ///< m between neighbours, >= 0.7
  double radius_m = 8.0;                   ///< m, disc radius for kRandom
  double yaw_rad = 0.0;                    ///< initial heading of every drone
  std::vector<Eigen::Vector3d> positions;  ///< kExplicit: one per drone (z = 0 on ground)
};

/// The control rates a server flies (sim.control_rate_hz), and an agent
/// accepts in a scene: one tick per control period.
constexpr double kMinControlRateHz = 1.0;
constexpr double kMaxControlRateHz = 1000.0;

struct SceneConfig {
  double ground_z_m = 0.0;
  std::vector<Cylinder> cylinders;
  std::vector<Box> boxes;
  /// Mesh obstacles; their triangles once the server loads them (load_meshes).
  std::vector<MeshObstacle> meshes;
  Eigen::Vector3d bounds_min{-100, -100, 0};
  Eigen::Vector3d bounds_max{100, 100, 50};
  Eigen::Vector2d finish_a{-50, 60};
  Eigen::Vector2d finish_b{50, 60};
  Eigen::Vector2d goal_xy{0, 70};
  StartConfig start;
  /// Obstacles the server adds from a seed (common/world_gen.hpp).
  WorldGenConfig generate;

  /// Every field once (common/config_fields.hpp); validate() adds the checks
  /// that relate fields.
  template <class Self, class V>
  static void fields(Self& c, V& v) {
    static const Choices<Formation> kFormations{{"cluster", Formation::kCluster},
                                                {"grid", Formation::kGrid},
                                                {"random", Formation::kRandom},
                                                {"explicit", Formation::kExplicit}};
    v.field("ground_z_m", c.ground_z_m, {"m", any(), "height of the ground plane"});
    v.list("cylinders", c.cylinders, "vertical pillars standing on the ground");
    v.list("boxes", c.boxes, "boxes");
    v.list("meshes", c.meshes,
           "static obstacles from mesh files: file, position, yaw_deg, rotation_deg, scale");
    v.field("bounds_min", c.bounds_min,
            {"m", any(), "world bounds: leaving them is flagged, not prevented"});
    v.field("bounds_max", c.bounds_max,
            {"m", any(), "world bounds; above bounds_min and the ground"});
    v.section("finish_line", [&](auto& w) {
      w.field("a", c.finish_a, {"m", any(), "one end of the finish line"});
      w.field("b", c.finish_b, {"m", any(), "other end; != a"});
    });
    v.field("goal_xy", c.goal_xy,
            {"m", any(), "the point the task flies toward and gathers around"});
    v.section("start", [&](auto& w) {
      w.choice("formation", c.start.formation, kFormations,
               {"", any(), "how start positions are made"});
      w.field("center_xy", c.start.center_xy, {"m", any(), "centre of the formation"});
      w.field("spacing_m", c.start.spacing_m, {"m", any(), "distance between neighbours; >= 0.7"});
      w.field("radius_m", c.start.radius_m, {"m", positive(), "disc radius for random"});
      w.field("yaw_rad", c.start.yaw_rad, {"rad", any(), "initial heading of every drone"});
      w.field("positions", c.start.positions, {"m", any(), "explicit: one per drone"});
    });
    v.section("generate", [&](auto& w) { WorldGenConfig::fields(c.generate, w); });
  }

  void validate() const;  ///< throws FieldError("scene.…")

  /// Unit vector (xy) from the start centre toward the goal.
  Eigen::Vector2d task_direction() const;
  /// True when p is on the goal's side of the finish line.
  bool past_finish(const Eigen::Vector2d& p) const;
  /// Horizontal clearance from p (at height z) to the nearest obstacle surface
  /// (negative inside); +inf when there are no obstacles. A mesh counts with
  /// the distance from p to its nearest triangle (a surface has no inside),
  /// or to its bounds when its triangles are not loaded (from the wire).
  double clearance(const Eigen::Vector3d& p) const;
  /// Start positions for n drones (z = ground). Throws FieldError if they do
  /// not fit (overlap an obstacle, or explicit list shorter than n).
  std::vector<Eigen::Vector3d> start_positions(int n, std::uint64_t seed) const;
};

void load(YamlSection s, SceneConfig& c);

/// Makes every relative scene.meshes[].file of a scenario document absolute,
/// against scenario_dir (the folder of the file it was read from), so a copy
/// written elsewhere (ddswarm-launch --set, an experiment's runs) names the
/// same mesh files. Leaves anything it does not recognise as it is.
void anchor_mesh_files(YAML::Node& root, const std::string& scenario_dir);

}  // namespace ddswarm
