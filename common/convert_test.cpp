#include "common/convert.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace ddswarm;

TEST(Convert, ASceneKeepsItsWorldThroughTheWire) {
  SceneConfig c;
  c.ground_z_m = -0.5;
  c.cylinders = {{{3, -4}, 0.6, 9}, {{-12.5, 40}, 1.25, 15}};
  c.boxes = {{{5, 6, 1.5}, {2, 3, 3}, 0.4}};
  MeshObstacle m;
  m.file = "meshes/town.obj";
  m.position = {4, 30, 0};
  m.rotation_deg = {90, 0, 5};
  m.yaw_deg = -30;
  m.scale = 0.01;
  m.bounds_min = {-6, 24, 0};
  m.bounds_max = {14, 38, 12.5};
  m.triangle_count = 372;
  m.content_hash = 0xfeedfacecafebeefULL;
  c.meshes = {m};
  c.bounds_min = {-80, -20, -0.5};
  c.bounds_max = {90, 120, 30};
  c.finish_a = {-40, 55};
  c.finish_b = {45, 58};
  c.goal_xy = {2, 66};
  c.start.center_xy = {1.5, -3};
  const SceneConfig back = from_msg(to_msg(c));
  EXPECT_EQ(back.ground_z_m, c.ground_z_m);
  ASSERT_EQ(back.cylinders.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(back.cylinders[k].center_xy, c.cylinders[k].center_xy);
    EXPECT_EQ(back.cylinders[k].radius_m, c.cylinders[k].radius_m);
    EXPECT_EQ(back.cylinders[k].height_m, c.cylinders[k].height_m);
  }
  ASSERT_EQ(back.boxes.size(), 1u);
  EXPECT_EQ(back.boxes[0].center, c.boxes[0].center);
  EXPECT_EQ(back.boxes[0].size, c.boxes[0].size);
  EXPECT_EQ(back.boxes[0].yaw_rad, c.boxes[0].yaw_rad);
  ASSERT_EQ(back.meshes.size(), 1u);
  EXPECT_EQ(back.meshes[0].file, m.file);
  EXPECT_EQ(back.meshes[0].position, m.position);
  EXPECT_EQ(back.meshes[0].rotation_deg, m.rotation_deg);
  EXPECT_EQ(back.meshes[0].yaw_deg, m.yaw_deg);
  EXPECT_EQ(back.meshes[0].scale, m.scale);
  EXPECT_EQ(back.meshes[0].bounds_min, m.bounds_min);
  EXPECT_EQ(back.meshes[0].bounds_max, m.bounds_max);
  EXPECT_EQ(back.meshes[0].triangle_count, m.triangle_count);
  EXPECT_EQ(back.meshes[0].content_hash, m.content_hash);
  EXPECT_FALSE(back.meshes[0].world);  // the triangles stay with the server
  EXPECT_EQ(back.bounds_min, c.bounds_min);
  EXPECT_EQ(back.bounds_max, c.bounds_max);
  EXPECT_EQ(back.finish_a, c.finish_a);
  EXPECT_EQ(back.finish_b, c.finish_b);
  EXPECT_EQ(back.goal_xy, c.goal_xy);
  EXPECT_EQ(back.start.center_xy, c.start.center_xy);
  EXPECT_NO_THROW(back.validate());
  // What the wire leaves to the server stays unset.
  EXPECT_TRUE(to_msg(c).name().to_string().empty());
  EXPECT_EQ(to_msg(c).num_drones(), 0);
}

// A hostile or broken Scene sample's mesh is refused by the checks every
// receiver runs on a Scene (SceneConfig::validate on from_msg).
TEST(Convert, AHostileMeshInASceneSampleIsRefused) {
  SceneConfig c;
  MeshObstacle m;
  m.file = "meshes/town.obj";
  m.bounds_min = {0, 0, 0};
  m.bounds_max = {1, 1, 1};
  m.triangle_count = 12;
  c.meshes = {m};
  EXPECT_NO_THROW(from_msg(to_msg(c)).validate());
  const auto refused = [&](auto&& spoil, const std::string& field) {
    msg::Scene s = to_msg(c);
    spoil(s.meshes()[0]);
    try {
      from_msg(s).validate();
    } catch (const FieldError& e) {
      EXPECT_EQ(e.field(), field);
      return;
    }
    ADD_FAILURE() << field << " accepted";
  };
  const double nan = std::nan("");
  refused([&](msg::Mesh& x) { x.scale(0); }, "scene.meshes[0].scale");
  refused([&](msg::Mesh& x) { x.scale(nan); }, "scene.meshes[0].scale");
  refused([&](msg::Mesh& x) { x.position().y(nan); }, "scene.meshes[0].position");
  refused([&](msg::Mesh& x) { x.rotation_deg().x(INFINITY); }, "scene.meshes[0].rotation_deg");
  refused([&](msg::Mesh& x) { x.yaw_deg(nan); }, "scene.meshes[0].yaw_deg");
  refused([&](msg::Mesh& x) { x.file(""); }, "scene.meshes[0].file");
  refused([&](msg::Mesh& x) { x.file("a\nb.obj"); }, "scene.meshes[0].file");
  refused([&](msg::Mesh& x) { x.bounds_max().z(-1); }, "scene.meshes[0].bounds_max");
  refused([&](msg::Mesh& x) { x.bounds_min().x(nan); }, "scene.meshes[0].bounds_max");
}

TEST(Convert, AMissionCommandAndItsAckKeepEveryField) {
  MissionCommand c;
  c.seq = 42;
  c.type = MissionType::kMove;
  c.target = 3;
  c.velocity = {1.5, -0.25, 0.5};
  c.duration_s = 7.5;
  c.value = 0.8;
  c.leader_id = 2;
  c.epsilon_m = 9;
  c.issuer = "gs-lab";
  const msg::MissionCommand m = to_msg(c);
  EXPECT_EQ(mission_problem(m), "");
  const MissionCommand back = from_msg(m);
  EXPECT_EQ(back.seq, c.seq);
  EXPECT_EQ(back.type, c.type);
  EXPECT_EQ(back.target, c.target);
  EXPECT_EQ(back.velocity, c.velocity);
  EXPECT_EQ(back.duration_s, c.duration_s);
  EXPECT_EQ(back.value, c.value);
  EXPECT_EQ(back.leader_id, c.leader_id);
  EXPECT_EQ(back.epsilon_m, c.epsilon_m);
  EXPECT_EQ(back.issuer, c.issuer);

  const msg::MissionAck a =
      to_msg(MissionAck{3, 42, false, "not airborne", Phase::kIdle, 900}, 0xabc);
  EXPECT_EQ(a.drone_id(), 3);
  EXPECT_EQ(a.seq(), 42u);
  EXPECT_FALSE(a.accepted());
  EXPECT_EQ(a.reason().to_string(), "not airborne");
  EXPECT_EQ(a.phase(), static_cast<std::uint8_t>(Phase::kIdle));
  EXPECT_EQ(a.tick(), 900u);
  EXPECT_EQ(a.issuer_instance(), 0xabcu);
}

TEST(Convert, VectorsAndAttitudesRoundTripExactly) {
  const Eigen::Vector3d v(0.1, -2e9, 3.25);
  EXPECT_EQ(from_msg(to_msg(v)), v);
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()));
  EXPECT_EQ(from_msg(to_msg(q)).coeffs(), q.coeffs());
}

TEST(Convert, AMalformedScanIsNamed) {
  msg::DistanceScan sc;
  for (int k = 0; k < 4; ++k) {
    sc.angle_body_rad().push_back(0);
    sc.elevation_body_rad().push_back(0);
    sc.range_m().push_back(1);
    sc.hit().push_back(1);
  }
  EXPECT_EQ(scan_problem(sc), "");
  msg::DistanceScan short_elevation = sc;
  short_elevation.elevation_body_rad().pop_back();
  EXPECT_EQ(scan_problem(short_elevation),
            "its sequences differ in length (yaw 4, elevation 3, range 4, hit 4)");
  msg::DistanceScan nan_elevation = sc;
  nan_elevation.elevation_body_rad()[2] = NAN;
  EXPECT_EQ(scan_problem(nan_elevation), "ray 2's direction is not finite");
}
