#include "common/scene.hpp"
#include "common/config_reference.hpp"
#include "common/scenario.hpp"

#include <gtest/gtest.h>

using namespace ddswarm;

TEST(Scene, PastFinishIsTheGoalSide) {
  SceneConfig s;
  s.finish_a = {-10, 50};
  s.finish_b = {10, 50};
  s.goal_xy = {0, 60};
  EXPECT_TRUE(s.past_finish({3, 51}));
  EXPECT_FALSE(s.past_finish({3, 49}));
}

TEST(Scene, ClearanceToCylinderAndBox) {
  SceneConfig s;
  s.cylinders.push_back({{0, 0}, 1.0, 10.0});
  EXPECT_NEAR(s.clearance({3, 0, 2}), 2.0, 1e-12);
  EXPECT_GT(s.clearance({3, 0, 12}), 1e9);  // above the pillar
  s.cylinders.clear();
  s.boxes.push_back({{0, 0, 1}, {2, 2, 2}, 0.0});
  EXPECT_NEAR(s.clearance({4, 0, 1}), 3.0, 1e-12);
}

TEST(Scene, StartFormationsHaveSpacingAndAreSeeded) {
  SceneConfig s;
  for (auto f : {Formation::kCluster, Formation::kGrid, Formation::kRandom}) {
    s.start.formation = f;
    auto p = s.start_positions(12, 7);
    ASSERT_EQ(p.size(), 12u);
    for (size_t i = 0; i < p.size(); ++i)
      for (size_t j = i + 1; j < p.size(); ++j)
        EXPECT_GE((p[i] - p[j]).norm(), s.start.spacing_m - 1e-9);
  }
  s.start.formation = Formation::kRandom;
  EXPECT_EQ(s.start_positions(6, 1), s.start_positions(6, 1));
  EXPECT_NE(s.start_positions(6, 1), s.start_positions(6, 2));
}

TEST(Scene, StartInsideObstacleIsRejected) {
  SceneConfig s;
  s.cylinders.push_back({{0, 0}, 3.0, 10.0});
  EXPECT_THROW(s.start_positions(3, 1), FieldError);
}

TEST(Reference, TheScenarioAndSceneSectionsDescribeEveryFieldAsTheCodeDeclaresIt) {
  const std::string doc = configuration_reference();
  using Mismatches = std::vector<std::string>;
  EXPECT_EQ(reference_mismatches(doc, "### `scenario:`", field_rows<ScenarioConfig>()),
            Mismatches{});
  std::vector<FieldRow> scene;  // scene.generate has its own table (world_gen_test)
  for (const auto& r : field_rows<SceneConfig>())
    if (r.key.rfind("generate.", 0) != 0) scene.push_back(r);
  EXPECT_EQ(reference_mismatches(doc, "### `scene:`", scene), Mismatches{});
}

// A scenario written elsewhere (ddswarm-launch --set, an experiment's runs)
// still names the mesh files its original names.
TEST(Scene, AnchoredMeshFilesAreAbsoluteAgainstTheScenariosFolder) {
  YAML::Node root = YAML::Load(
      "scene:\n  meshes:\n    - {file: meshes/town.obj}\n    - {file: /abs/bridge.stl}\n"
      "    - {file: ../up.stl, scale: 2}\n");
  anchor_mesh_files(root, "/work/config");
  EXPECT_EQ(root["scene"]["meshes"][0]["file"].as<std::string>(), "/work/config/meshes/town.obj");
  EXPECT_EQ(root["scene"]["meshes"][1]["file"].as<std::string>(), "/abs/bridge.stl");
  EXPECT_EQ(root["scene"]["meshes"][2]["file"].as<std::string>(), "/work/up.stl");
  EXPECT_EQ(root["scene"]["meshes"][2]["scale"].as<double>(), 2);
  YAML::Node none = YAML::Load("scene: {cylinders: []}");
  anchor_mesh_files(none, "/x");
  EXPECT_FALSE(none["scene"]["meshes"]);
}
