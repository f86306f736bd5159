#include "common/mesh_loader.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "common/yaml_section.hpp"

using namespace ddswarm;
namespace fs = std::filesystem;

namespace {

/// A fresh folder per test, removed after it.
class MeshFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("ddswarm_mesh_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name, std::ios::binary) << text;
    return dir_ / name;
  }
  std::string reason(const fs::path& file) {
    try {
      read_mesh_file(file);
    } catch (const MeshError& e) {
      return e.what();
    }
    return "(read)";
  }
  fs::path dir_;
};

// A 2 m cube from (0,0,0) to (2,2,2): six quads, twelve triangles once triangulated.
const char* kCubeObj =
    "# a cube\n"
    "v 0 0 0\nv 2 0 0\nv 2 2 0\nv 0 2 0\nv 0 0 2\nv 2 0 2\nv 2 2 2\nv 0 2 2\n"
    "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";

// A 4 m x 3 m wall in the x-z plane at y = 0, two facets.
const char* kWallStl =
    "solid wall\n"
    " facet normal 0 -1 0\n  outer loop\n   vertex 0 0 0\n   vertex 4 0 0\n   vertex 4 0 3\n"
    "  endloop\n endfacet\n"
    " facet normal 0 -1 0\n  outer loop\n   vertex 0 0 0\n   vertex 4 0 3\n   vertex 0 0 3\n"
    "  endloop\n endfacet\n"
    "endsolid wall\n";

}  // namespace

TEST_F(MeshFiles, AnObjCubeIsTwelveTriangles) {
  const TriangleMesh m = read_mesh_file(write("cube.obj", kCubeObj));
  EXPECT_EQ(m.triangles.size(), 12u);
  EXPECT_EQ(m.vertices.size(), 8u);  // shared corners joined
  for (const auto& t : m.triangles)
    for (auto k : t) ASSERT_LT(k, m.vertices.size());
}

TEST_F(MeshFiles, AnStlWallIsItsFacets) {
  const TriangleMesh m = read_mesh_file(write("wall.STL", kWallStl));
  ASSERT_EQ(m.triangles.size(), 2u);
  Eigen::Vector3f hi = Eigen::Vector3f::Constant(-1e9f);
  for (const auto& v : m.vertices) hi = hi.cwiseMax(v);
  EXPECT_EQ(hi, Eigen::Vector3f(4, 0, 3));
}

// One triangle in a glTF file, its buffer inline, under a node raised 5 m.
const char* kRaisedTriangleGltf = R"({"asset": {"version": "2.0"}, "scene": 0,
  "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0, "translation": [0, 0, 5]}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
  "buffers": [{"byteLength": 36,
    "uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                 "min": [0, 0, 0], "max": [1, 1, 0]}]})";

TEST_F(MeshFiles, AGltfTriangleKeepsItsNodesTransform) {
  const TriangleMesh m = read_mesh_file(write("raised.gltf", kRaisedTriangleGltf));
  ASSERT_EQ(m.triangles.size(), 1u);
  for (const auto& v : m.vertices) EXPECT_EQ(v.z(), 5.0f);
}

TEST_F(MeshFiles, EachBadFileNamesItsReason) {
  EXPECT_EQ(reason(dir_ / "absent.obj"), "no such file");
  EXPECT_EQ(reason(write("empty.obj", "")), "the file is empty");
  EXPECT_EQ(reason(write("points.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n")), "has no triangles");
  EXPECT_NE(reason(write("garbage.stl", "this is not\x01\x02 an stl")).find("cannot be read"),
            std::string::npos);
  EXPECT_EQ(reason(write("model.ply", kCubeObj)),
            "unsupported format '.ply' (ddswarm reads .obj, .stl, .gltf and .glb)");
  fs::create_directories(dir_ / "folder.obj");
  EXPECT_EQ(reason(dir_ / "folder.obj"), "not a regular file");
}

TEST_F(MeshFiles, AMeshIsScaledTurnedAndMovedIntoTheWorld) {
  write("cube.obj", kCubeObj);
  SceneConfig s;
  MeshObstacle m;
  m.file = "cube.obj";
  m.scale = 1.5;   // 3 m cube
  m.yaw_deg = 90;  // x -> y, y -> -x
  m.position = {10, 20, 0};
  s.meshes.push_back(m);
  load_meshes(s, dir_);
  const MeshObstacle& w = s.meshes[0];
  EXPECT_EQ(w.triangle_count, 12u);
  ASSERT_TRUE(w.world);
  EXPECT_NEAR((w.bounds_min - Eigen::Vector3d(7, 20, 0)).norm(), 0, 1e-5);
  EXPECT_NEAR((w.bounds_max - Eigen::Vector3d(10, 23, 3)).norm(), 0, 1e-5);
  EXPECT_EQ(w.content_hash, file_hash(dir_ / "cube.obj"));
  EXPECT_NE(w.content_hash, file_hash(write("other.obj", std::string(kCubeObj) + "\n")));
  EXPECT_NO_THROW(s.validate());
  // A y-up file stands up with a roll of 90 degrees: its +y becomes +z.
  s.meshes[0] = MeshObstacle{};
  s.meshes[0].file = "wall.stl";
  write("wall.stl", kWallStl);
  s.meshes[0].rotation_deg = {90, 0, 0};
  load_meshes(s, dir_);
  EXPECT_NEAR((s.meshes[0].bounds_min - Eigen::Vector3d(0, -3, 0)).norm(), 0, 1e-5);
  EXPECT_NEAR((s.meshes[0].bounds_max - Eigen::Vector3d(4, 0, 0)).norm(), 0, 1e-5);
}

TEST_F(MeshFiles, ClearanceIsTheDistanceToTheNearestTriangle) {
  write("wall.stl", kWallStl);
  SceneConfig s;
  MeshObstacle m;
  m.file = "wall.stl";
  s.meshes.push_back(m);
  load_meshes(s, dir_);
  EXPECT_NEAR(s.clearance({2, -5, 1.5}), 5.0, 1e-6);  // in front of the wall's face
  EXPECT_NEAR(s.clearance({7, 0, 1.5}), 3.0, 1e-6);   // beside its edge
  EXPECT_NEAR(s.clearance({2, 0, 7}), 4.0, 1e-6);     // above its top
  s.meshes[0].world.reset();                          // as a Scene sample has it
  EXPECT_NEAR(s.clearance({2, -5, 1.5}), 5.0, 1e-6);  // its bounds
}

TEST_F(MeshFiles, AScenarioEntryWithABadFileIsOneLineWithFileAndLine) {
  write("empty.stl", "");
  write("cube.obj", kCubeObj);
  const auto error = [&](const std::string& meshes) {
    const std::string file = (dir_ / "world.yaml").string();
    const auto doc = YamlDocument::parse("scene:\n  meshes:\n" + meshes, file);
    try {
      doc.guard([&] {
        SceneConfig s;
        load(doc.section("scene"), s);
        s.validate();
        load_meshes(s, dir_);
      });
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("(loaded)");
  };
  const std::string f = (dir_ / "world.yaml").string() + ":";
  EXPECT_EQ(error("    - {file: cube.obj}\n    - {file: town.obj}\n"),
            f + "4: scene.meshes[1].file = " + (dir_ / "town.obj").string() + ": no such file");
  EXPECT_EQ(
      error("    - {file: empty.stl}\n"),
      f + "3: scene.meshes[0].file = " + (dir_ / "empty.stl").string() + ": the file is empty");
  EXPECT_EQ(error("    - {file: cube.obj, scale: 0}\n"),
            f + "3: scene.meshes[0].scale = 0: must be > 0");
  EXPECT_EQ(error("    - {file: cube.obj, scale: -2}\n"),
            f + "3: scene.meshes[0].scale = -2: must be > 0");
  EXPECT_EQ(error("    - {file: cube.obj, pose: [1, 2, 3]}\n"),
            f + "3: scene.meshes[0].pose: unknown key");
  EXPECT_EQ(error("    - {file: \"\"}\n"),
            f + "3: scene.meshes[0].file = \"\": must name a mesh file");
  EXPECT_EQ(error("    - {file: cube.obj}\n"), "(loaded)");
}
