// The Bullet world: forces act as the vehicle model says, sensors measure the
// right distances, and contacts are reported once per contact.
#include "sim_server/physics_world.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "sim_server/flight_controller.hpp"

namespace ddswarm::sim {
namespace {

constexpr double kDt = 0.001;
constexpr double kPi = std::numbers::pi;

SceneConfig empty_scene() { return SceneConfig{}; }

SceneConfig scene_with(std::vector<Cylinder> cylinders, std::vector<Box> boxes = {}) {
  SceneConfig s;
  s.cylinders = std::move(cylinders);
  s.boxes = std::move(boxes);
  return s;
}

/// A mesh obstacle as the server holds it once loaded: a wall of two
/// triangles in the plane x = x0, from y = -half_y to half_y, z = 0 to height.
MeshObstacle mesh_wall(double x0, double half_y, double height) {
  auto t = std::make_shared<TriangleMesh>();
  const auto f = [](double x, double y, double z) {
    return Eigen::Vector3f(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
  };
  t->vertices = {f(x0, -half_y, 0), f(x0, half_y, 0), f(x0, half_y, height),
                 f(x0, -half_y, height)};
  t->triangles = {{0, 1, 2}, {0, 2, 3}};
  MeshObstacle m;
  m.file = "wall.obj";
  m.triangle_count = 2;
  m.bounds_min = {x0, -half_y, 0};
  m.bounds_max = {x0, half_y, height};
  m.world = t;
  return m;
}

void step_for(PhysicsWorld& w, double seconds, double dt = kDt) {
  const int n = static_cast<int>(std::lround(seconds / dt));
  for (int i = 0; i < n; ++i) w.step(dt);
}

/// Drones under closed-loop control, all in one world.
class Swarm {
 public:
  Swarm(const SceneConfig& scene, const std::vector<Eigen::Vector3d>& starts, double yaw = 0.0,
        BulletPath path = BulletPath::kShortcuts)
      : world(scene, QuadrotorParams{}, starts, yaw, path), sp(starts.size()) {
    for (std::size_t i = 0; i < starts.size(); ++i) {
      fc.emplace_back(QuadrotorParams{}, ControllerConfig{});
      fc.back().reset(yaw);
      sp[i].motors_on = true;
    }
  }
  void run(double seconds) {
    const int n = static_cast<int>(std::lround(seconds / kDt));
    for (int k = 0; k < n; ++k) step();
  }
  void step() {
    for (int i = 0; i < world.size(); ++i)
      world.set_rotor_commands(i, fc[i].update(world.state(i), sp[i], kDt));
    world.step(kDt);
  }
  /// Climbs all drones for `seconds` at 1 m/s, then settles 2 s.
  void take_off(double seconds) {
    for (auto& s : sp) s.v_world = {0, 0, 1};
    run(seconds);
    for (auto& s : sp) s.v_world.setZero();
    run(2.0);
  }

  PhysicsWorld world;
  std::vector<FlightController> fc;
  std::vector<VelocitySetpoint> sp;
};

// ---------------------------------------------------------------- forces

TEST(PhysicsWorld, DronesStartRestingOnTheGround) {
  PhysicsWorld w(empty_scene(), QuadrotorParams{}, {{0, 0, 0}, {3, 0, 0}}, 0.4);
  ASSERT_EQ(w.size(), 2);
  const RigidState s = w.state(1);
  EXPECT_NEAR(s.p_world.z(), QuadrotorParams{}.collision_half_height_m, 1e-6);
  EXPECT_NEAR(s.p_world.x(), 3.0, 1e-6);
  EXPECT_NEAR(yaw_of(s.q_world_body), 0.4, 1e-6);
  EXPECT_TRUE(w.touching_ground(0));
  step_for(w, 1.0);
  EXPECT_NEAR((w.state(1).p_world - s.p_world).norm(), 0.0, 1e-3);  // resting stays put
  EXPECT_TRUE(w.take_contact_events().empty());  // resting at start is not a new contact
}

TEST(PhysicsWorld, HoverSpeedCarriesTheWeight) {
  QuadrotorParams q;
  PhysicsWorld w(empty_scene(), q, {{0, 0, 0}}, 0.0);
  w.reset_drone(0, {0, 0, 10}, 0.0);
  const double h = q.hover_omega();
  w.set_rotor_commands(0, {h, h, h, h});
  step_for(w, 0.1);  // motors spin up (5 ms lag)
  const RigidState a = w.state(0);
  step_for(w, 1.0);
  const RigidState b = w.state(0);
  // Net vertical acceleration below 1 % of g: thrust equals weight within 1 %.
  EXPECT_LT(std::abs(b.v_world.z() - a.v_world.z()), 0.01 * kGravityMps2);
  EXPECT_LT(b.w_body.norm(), 1e-3);  // balanced rotors: no rotation
  for (double r : w.rotor_speeds(0)) EXPECT_NEAR(r, h, 1e-6);
}

TEST(PhysicsWorld, FreeFallMatchesGravity) {
  QuadrotorParams q;
  q.drag_quadratic_body.setZero();
  PhysicsWorld w(empty_scene(), q, {{0, 0, 0}}, 0.0);
  w.reset_drone(0, {0, 0, 20}, 0.0);
  const double z0 = w.state(0).p_world.z();
  step_for(w, 1.0);
  const double drop = z0 - w.state(0).p_world.z();
  EXPECT_NEAR(drop, 0.5 * kGravityMps2, 0.01 * 0.5 * kGravityMps2);
  EXPECT_NEAR(w.state(0).v_world.z(), -kGravityMps2, 0.01 * kGravityMps2);
}

TEST(PhysicsWorld, VerticalDragGivesTerminalVelocity) {
  QuadrotorParams q;
  PhysicsWorld w(empty_scene(), q, {{0, 0, 0}}, 0.0);
  w.reset_drone(0, {0, 0, 500}, 0.0);
  step_for(w, 8.0);
  const double terminal = std::sqrt(q.mass_kg * kGravityMps2 / q.drag_quadratic_body.z());
  EXPECT_NEAR(-w.state(0).v_world.z(), terminal, 0.02 * terminal);
}

TEST(PhysicsWorld, ADroneAdriftInTheWindReachesItsSpeed) {
  // Thrust carries the weight; drag on the airspeed pushes the drone until
  // it moves with the air.
  QuadrotorParams q;
  PhysicsWorld w(empty_scene(), q, {{0, 0, 0}}, 0.0);
  w.reset_drone(0, {0, 0, 50}, 0.0);
  const double h = q.hover_omega();
  w.set_rotor_commands(0, {h, h, h, h});
  w.set_air_velocity(0, {5, 0, 0});
  step_for(w, 0.1);
  // Early on: the drag force c v^2 + c_lin v at 5 m/s of airspeed.
  const double v0 = w.state(0).v_world.x();
  step_for(w, 0.1);
  const double force = q.drag_quadratic_body.x() * 25 + q.drag_linear_n_per_mps * 5;
  EXPECT_NEAR((w.state(0).v_world.x() - v0) / 0.1 * q.mass_kg, force, 0.05 * force);
  // Then the airspeed decays as quadratic drag says: dv/dt = -(c/m) v^2, so
  // v(T) = v(0) / (1 + (c/m) v(0) T): the drone tends to the wind's speed.
  ASSERT_EQ(q.drag_linear_n_per_mps, 0.0);
  const double rel0 = 5.0 - w.state(0).v_world.x();
  step_for(w, 60.0);
  const double rel = rel0 / (1 + q.drag_quadratic_body.x() / q.mass_kg * rel0 * 60.0);
  EXPECT_NEAR(5.0 - w.state(0).v_world.x(), rel, 0.02 * rel);
  EXPECT_NEAR(w.state(0).v_world.y(), 0.0, 1e-6);
}

TEST(PhysicsWorld, AHoveringDroneHoldsItsPlaceInASteadyWind) {
  // The velocity controller's integrator takes the drag: after settling, a
  // drone asked to stay (zero velocity) in 5 m/s of wind holds its place.
  Swarm s(empty_scene(), {{0, 0, 0}});
  s.take_off(2.0);
  s.world.set_air_velocity(0, {5, 0, 0});
  s.run(10.0);  // the integrator settles
  const Eigen::Vector3d p = s.world.state(0).p_world;
  s.run(20.0);
  EXPECT_LT((s.world.state(0).p_world - p).norm(), 0.10) << "drift over 20 s after settling";
  EXPECT_LT(s.world.state(0).v_world.norm(), 0.02);
}

TEST(PhysicsWorld, GroundEffectLiftsAHoverNearTheGroundAsCheesemanAndBennettSay) {
  // Hub one rotor radius above the ground: thrust 16/15 of the hover's, so
  // the drone accelerates up at g / 15.
  QuadrotorParams q;
  const double r = 0.5 * q.prop_diameter_m;
  PhysicsWorld w(empty_scene(), q, {{0, 0, 0}}, 0.0);
  AeroConfig a;
  a.ground_effect = true;
  w.set_aero(a);
  w.reset_drone(0, {0, 0, 20}, 0.0);  // spin up far from the ground first
  const double h = q.hover_omega();
  w.set_rotor_commands(0, {h, h, h, h});
  step_for(w, 0.1);
  w.reset_drone(0, {0, 0, r - q.collision_half_height_m},
                0.0);  // the body centre (the rotor plane) at z = R
  w.set_rotor_commands(0, {h, h, h, h});
  step_for(w, 0.05);  // the motors spin up again (5 ms lag)
  const double v0 = w.state(0).v_world.z();
  step_for(w, 0.01);
  EXPECT_NEAR((w.state(0).v_world.z() - v0) / 0.01, kGravityMps2 / 15, 0.1 * kGravityMps2 / 15);
}

/// The downward push on the lower drone of each (top, low) pair, measured
/// against the top one (N, from their vertical accelerations over 5 ms), and
/// the model's force. Every drone of w was just reset: the rotors spin up to
/// hover for 20 ms first, all alike, so only the downwash tells them apart.
struct Push {
  double measured_n, model_n;
};
std::vector<Push> downwash_pushes(PhysicsWorld& w, const AeroConfig& a,
                                  const std::vector<std::pair<int, int>>& pairs) {
  const QuadrotorParams& q = w.params();
  const double h = q.hover_omega();
  const int n = static_cast<int>(pairs.size()) * 2;
  for (int i = 0; i < n; ++i) w.set_rotor_commands(i, {h, h, h, h});
  step_for(w, 0.02);
  std::vector<double> v0;
  for (int i = 0; i < n; ++i) v0.push_back(w.state(i).v_world.z());
  step_for(w, 0.005);
  std::vector<Push> out;
  for (const auto& [top, low] : pairs) {
    const double a_top = (w.state(top).v_world.z() - v0[top]) / 0.005;
    const double a_low = (w.state(low).v_world.z() - v0[low]) / 0.005;
    out.push_back(
        {(a_top - a_low) * q.mass_kg,
         downwash_force(a, w.state(top).p_world, w.state(low).p_world, 0.5 * q.prop_diameter_m)});
  }
  return out;
}

AeroConfig downwash_only() {
  AeroConfig a;
  a.downwash = true;
  return a;
}

TEST(PhysicsWorld, DownwashPushesADroneHalfAMetreBelowAnotherAsTheModelSays) {
  PhysicsWorld w(empty_scene(), QuadrotorParams{}, {{0, 0, 0}, {3, 0, 0}}, 0.0);
  const AeroConfig a = downwash_only();
  w.set_aero(a);
  w.reset_drone(0, {0, 0, 20.5}, 0.0);
  w.reset_drone(1, {0, 0, 20.0}, 0.0);
  const Push p = downwash_pushes(w, a, {{0, 1}})[0];
  EXPECT_GT(p.model_n, 1.0);
  // Against the drone above, which feels nothing.
  EXPECT_NEAR(p.measured_n, p.model_n, 0.05 * p.model_n);
}

TEST(PhysicsWorld, DownwashReachesADroneAcrossTheNeighbourGridsCellLines) {
  // The server finds who is above whom on a grid of 12 m cells; a pair 2 cm
  // apart sideways across a cell line (at x = 12, at y = -12, at the
  // origin's corner) is pushed as one within a cell is.
  const std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> places = {
      {{5, 5, 20.5}, {5.02, 5, 20}},           // one cell
      {{11.99, 100, 20.5}, {12.01, 100, 20}},  // across x = 12
      {{100, -11.99, 20.5}, {100, -12.01, 20}},
      {{-108.01, -0.01, 20.5}, {-107.99, 0.01, 20}}};  // across x = -108 and y = 0
  std::vector<Eigen::Vector3d> starts;
  std::vector<std::pair<int, int>> pairs;
  for (const auto& [top, low] : places) {
    pairs.push_back({static_cast<int>(starts.size()), static_cast<int>(starts.size()) + 1});
    starts.insert(starts.end(), {top, low});
  }
  PhysicsWorld w(empty_scene(), QuadrotorParams{}, starts, 0.0);
  const AeroConfig a = downwash_only();
  w.set_aero(a);
  for (std::size_t i = 0; i < starts.size(); ++i)
    w.reset_drone(static_cast<int>(i), starts[i], 0.0);
  const std::vector<Push> pushed = downwash_pushes(w, a, pairs);
  for (std::size_t k = 0; k < pushed.size(); ++k)
    EXPECT_NEAR(pushed[k].measured_n, pushed[k].model_n, 0.05 * pushed[k].model_n) << "pair " << k;
  EXPECT_GT(pushed[0].measured_n, 1.0);
}

TEST(PhysicsWorld, DownwashFindsADroneThatCameUnderAnotherAFewCentimetresAStep) {
  // Who may push whom is found again only once a drone has moved a metre; a
  // drone that comes 13 m sideways under another, 0.6 m between steps, is
  // pushed as the model says once below it.
  PhysicsWorld w(empty_scene(), QuadrotorParams{}, {{0, 0, 0}, {13, 0, 0}}, 0.0);
  const AeroConfig a = downwash_only();
  w.set_aero(a);
  for (double x = 13.0; x > 0.0; x -= 0.6) {
    w.reset_drone(0, {0, 0, 20.5}, 0.0);
    w.reset_drone(1, {x, 0, 20.0}, 0.0);
    w.step(0.001);
  }
  w.reset_drone(0, {0, 0, 20.5}, 0.0);
  w.reset_drone(1, {0.02, 0, 20.0}, 0.0);
  const Push p = downwash_pushes(w, a, {{0, 1}})[0];
  EXPECT_GT(p.model_n, 1.0);
  EXPECT_NEAR(p.measured_n, p.model_n, 0.05 * p.model_n);
}

TEST(PhysicsWorld, RotorTorquesTurnTheBodyTheWayTheModelSays) {
  QuadrotorParams q;
  const double h = q.hover_omega();
  struct Case {
    std::array<double, 4> omega;
    int axis;
  };
  // Left rotors (1, 2) faster: +roll; front rotors (0, 2) faster: -pitch
  // (nose up); CW rotors (2, 3) faster: +yaw.
  for (const Case& c : {Case{{h, h + 30, h + 30, h}, 0}, Case{{h + 30, h, h + 30, h}, 1},
                        Case{{h, h, h + 30, h + 30}, 2}}) {
    PhysicsWorld w(empty_scene(), q, {{0, 0, 0}}, 0.0);
    w.reset_drone(0, {0, 0, 10}, 0.0);
    w.set_rotor_commands(0, c.omega);
    step_for(w, 0.05);
    const Eigen::Vector3d rate = w.state(0).w_body;
    const Eigen::Vector3d want = q.rotor_wrench(c.omega).torque_body_nm.cwiseQuotient(q.inertia());
    EXPECT_GT(rate[c.axis] * want[c.axis], 0) << "axis " << c.axis;
    // Rate after 0.05 s is about the model's angular acceleration times 0.05 s.
    EXPECT_NEAR(rate[c.axis], want[c.axis] * 0.05, 0.15 * std::abs(want[c.axis] * 0.05));
  }
}

TEST(PhysicsWorld, MotorLagIsFirstOrder) {
  QuadrotorParams q;
  PhysicsWorld w(empty_scene(), q, {{0, 0, 0}}, 0.0);
  w.reset_drone(0, {0, 0, 10}, 0.0);
  w.set_rotor_commands(0, {400, 400, 400, 400});
  step_for(w, q.motor_tau_s);
  EXPECT_NEAR(w.rotor_speeds(0)[0], 400 * (1 - std::exp(-1.0)), 1.0);
  w.set_rotor_commands(0, {5000, -3, 400, 400});  // clamped to the limits
  step_for(w, 0.1);
  EXPECT_NEAR(w.rotor_speeds(0)[0], q.omega_max_rad_s(), 1e-3);
  EXPECT_NEAR(w.rotor_speeds(0)[1], 0.0, 1e-3);
}

TEST(PhysicsWorld, ResetPlacesADroneAtRest) {
  PhysicsWorld w(empty_scene(), QuadrotorParams{}, {{0, 0, 0}}, 0.0);
  w.set_rotor_commands(0, {600, 600, 600, 600});
  step_for(w, 0.5);
  w.reset_drone(0, {4, 5, 2}, 1.0);
  const RigidState s = w.state(0);
  EXPECT_TRUE(s.p_world.isApprox(Eigen::Vector3d(4, 5, 2.05), 1e-6));
  EXPECT_EQ(s.v_world.norm(), 0.0);
  EXPECT_NEAR(yaw_of(s.q_world_body), 1.0, 1e-6);
  for (double r : w.rotor_speeds(0)) EXPECT_EQ(r, 0.0);
  step_for(w, 0.1);  // commands were cleared: it falls
  EXPECT_LT(w.state(0).v_world.z(), -0.9);
}

// ---------------------------------------------------------------- sensors

SensorConfig exact_sensors() {
  SensorConfig c;
  c.noise_sigma_m = 0.0;
  return c;
}

TEST(RaySensors, MeasureTheDistanceToAPillar) {
  // Pillar of radius 0.5 whose surface is 1.5 m ahead of the drone centre.
  PhysicsWorld w(scene_with({Cylinder{{2, 0}, 0.5, 6}}), QuadrotorParams{}, {{0, 0, 0}}, 0.0);
  w.reset_drone(0, {0, 0, 1}, 0.0);
  std::mt19937_64 rng(1);
  std::vector<float> range;
  std::vector<std::uint8_t> hit;
  w.cast_rays(0, exact_sensors(), rng, range, hit);
  ASSERT_EQ(range.size(), 8u);
  ASSERT_EQ(hit.size(), 8u);
  EXPECT_EQ(hit[0], 1);
  EXPECT_NEAR(range[0], 1.5, 1e-4);  // exact geometry (float output)
  // 45 deg off: the ray passes the pillar at 2 sin45 = 1.41 m from its axis: miss.
  for (int k = 1; k < 8; ++k) {
    EXPECT_EQ(hit[k], 0) << k;
    EXPECT_EQ(range[k], 4.0f) << k;
  }
}

TEST(RaySensors, MeasureTheDistanceToRotatedBoxes) {
  // Box 2 x 1 (x by y) centred 3 m east; turned 90 deg its x face is 2.5 m away.
  SceneConfig scene =
      scene_with({}, {Box{{3, 0, 1}, {2, 1, 2}, 0.0}, Box{{0, 3, 1}, {2, 1, 2}, kPi / 2}});
  PhysicsWorld w(scene, QuadrotorParams{}, {{0, 0, 0}}, 0.0);
  w.reset_drone(0, {0, 0, 1}, 0.0);
  std::mt19937_64 rng(1);
  std::vector<float> range;
  std::vector<std::uint8_t> hit;
  w.cast_rays(0, exact_sensors(), rng, range, hit);
  EXPECT_EQ(hit[0], 1);
  EXPECT_NEAR(range[0], 2.0, 1e-4);  // east: face at x = 3 - 1
  EXPECT_EQ(hit[2], 1);
  EXPECT_NEAR(range[2], 2.0, 1e-4);  // north: the turned box's long side is along y
  // A box yawed by 30 deg: the ray along its face normal meets the face at 1.5 m.
  const double yaw = kPi / 6;
  PhysicsWorld w2(scene_with({}, {Box{{2 * std::cos(yaw), 2 * std::sin(yaw), 1}, {1, 3, 2}, yaw}}),
                  QuadrotorParams{}, {{0, 0, 0}}, 0.0);
  w2.reset_drone(0, {0, 0, 1}, yaw);
  w2.cast_rays(0, exact_sensors(), rng, range, hit);
  EXPECT_NEAR(range[0], 1.5, 1e-4);
  EXPECT_EQ(hit[0], 1);
}

TEST(RaySensors, MeasureTheDistanceToAMeshWallFromEitherSide) {
  SceneConfig scene;
  scene.meshes = {mesh_wall(3, 5, 4)};
  PhysicsWorld w(scene, QuadrotorParams{}, {{0, 0, 0}}, 0.0);
  w.reset_drone(0, {0, 0, 1}, 0.0);
  std::mt19937_64 rng(1);
  std::vector<float> range;
  std::vector<std::uint8_t> hit;
  SensorConfig c = exact_sensors();
  c.max_range_m = 10;
  for (auto mode : {RayCastMode::kCulled, RayCastMode::kBruteForce, RayCastMode::kWorldRayTest}) {
    w.set_ray_cast_mode(mode);
    w.cast_rays(0, c, rng, range, hit);
    EXPECT_EQ(hit[0], 1);
    EXPECT_NEAR(range[0], 3.0, 1e-4);  // east, square on
    EXPECT_EQ(hit[1], 1);
    EXPECT_NEAR(range[1], 3.0 * std::sqrt(2.0), 1e-4);  // north-east, 45 degrees on
    EXPECT_EQ(hit[4], 0);                               // west: nothing
    EXPECT_EQ(hit[2], 0);                               // north: along the wall's plane
  }
  // From behind, the triangles' other face.
  w.set_ray_cast_mode(RayCastMode::kCulled);
  w.reset_drone(0, {5, 0, 1}, kPi);
  w.cast_rays(0, c, rng, range, hit);
  EXPECT_EQ(hit[0], 1);
  EXPECT_NEAR(range[0], 2.0, 1e-4);
  // Above the wall's top, the rays pass over it.
  w.reset_drone(0, {0, 0, 5}, 0.0);
  w.cast_rays(0, c, rng, range, hit);
  EXPECT_EQ(hit[0], 0);
}

TEST(RaySensors, RotateWithTheBody) {
  PhysicsWorld w(scene_with({Cylinder{{2, 0}, 0.5, 6}}), QuadrotorParams{}, {{0, 0, 0}}, 0.0);
  w.reset_drone(0, {0, 0, 1}, kPi / 2);  // facing +y: the pillar is on the right
  std::mt19937_64 rng(1);
  std::vector<float> range;
  std::vector<std::uint8_t> hit;
  w.cast_rays(0, exact_sensors(), rng, range, hit);
  EXPECT_EQ(hit[0], 0);
  EXPECT_EQ(hit[6], 1);  // ray 6 points at body yaw 270 deg = world east
  EXPECT_NEAR(range[6], 1.5, 1e-4);
  SensorConfig offset = exact_sensors();
  offset.yaw_offset_rad = -kPi / 2;  // now ray 0 points at body -90 deg
  w.cast_rays(0, offset, rng, range, hit);
  EXPECT_EQ(hit[0], 1);
  EXPECT_NEAR(range[0], 1.5, 1e-4);
}

// A wall 3 m east (x = 3 to 3.3, y = -5 to 5, 6 m tall) with a window 4 m
// wide from 1.5 m to 2.5 m: the boxes on either side, below and above it.
SceneConfig window_wall() {
  return scene_with(
      {}, {Box{{3.15, -3.5, 3}, {0.3, 3, 6}, 0.0}, Box{{3.15, 3.5, 3}, {0.3, 3, 6}, 0.0},
           Box{{3.15, 0, 0.75}, {0.3, 4, 1.5}, 0.0}, Box{{3.15, 0, 4.25}, {0.3, 4, 3.5}, 0.0}});
}

TEST(RaySensors, ThreeRowsSeeTheWallAboveAndBelowAWindowTheMiddleRowPassesThrough) {
  PhysicsWorld w(window_wall(), QuadrotorParams{}, {{0, 0, 0}}, 0.0);
  w.reset_drone(0, {0, 0, 2}, 0.0);  // level with the window's middle, facing it
  std::mt19937_64 rng(1);
  std::vector<float> range;
  std::vector<std::uint8_t> hit;
  SensorConfig c = exact_sensors();
  c.rows = 3;
  c.vertical_fov_deg = 40;  // rows at -20, 0, +20 deg
  for (auto mode : {RayCastMode::kCulled, RayCastMode::kBruteForce, RayCastMode::kWorldRayTest}) {
    w.set_ray_cast_mode(mode);
    w.cast_rays(0, c, rng, range, hit);
    ASSERT_EQ(range.size(), 24u);
    // Column 0 (east) of each row: ray 0 (down 20 deg) meets the sill's face
    // at z = 2 - 3 tan 20 = 0.91 m, ray 8 (level) flies through the window,
    // ray 16 (up 20 deg) meets the lintel's face at z = 3.09 m; both 3/cos 20 away.
    EXPECT_EQ(hit[0], 1);
    EXPECT_NEAR(range[0], 3 / std::cos(20 * kPi / 180), 1e-4);
    EXPECT_EQ(hit[8], 0);
    EXPECT_EQ(range[8], 4.0f);
    EXPECT_EQ(hit[16], 1);
    EXPECT_NEAR(range[16], 3 / std::cos(20 * kPi / 180), 1e-4);
  }
  // The ring alone (one row, level) sees no wall at all.
  w.set_ray_cast_mode(RayCastMode::kCulled);
  w.cast_rays(0, exact_sensors(), rng, range, hit);
  EXPECT_EQ(hit[0], 0);
  // Turned to face north, the rows turn with the body: column 6 (body -90
  // deg) now looks east, its middle ray (14) through the window.
  w.reset_drone(0, {0, 0, 2}, kPi / 2);
  w.cast_rays(0, c, rng, range, hit);
  EXPECT_EQ(hit[6], 1);
  EXPECT_EQ(hit[14], 0);
  EXPECT_EQ(hit[22], 1);
}

TEST(RaySensors, NothingBeyondMaxRange) {
  PhysicsWorld w(scene_with({Cylinder{{5, 0}, 0.5, 6}}), QuadrotorParams{}, {{0, 0, 0}}, 0.0);
  w.reset_drone(0, {0, 0, 1}, 0.0);
  std::mt19937_64 rng(1);
  std::vector<float> range;
  std::vector<std::uint8_t> hit;
  SensorConfig c = exact_sensors();  // max 4 m; the surface is 4.5 m away
  w.cast_rays(0, c, rng, range, hit);
  EXPECT_EQ(hit[0], 0);
  EXPECT_EQ(range[0], 4.0f);
  c.max_range_m = 5.0;
  w.cast_rays(0, c, rng, range, hit);
  EXPECT_EQ(hit[0], 1);
  EXPECT_NEAR(range[0], 4.5, 1e-4);
}

TEST(RaySensors, NeverSeeTheirOwnDroneButSeeOthers) {
  PhysicsWorld w(empty_scene(), QuadrotorParams{}, {{0, 0, 0}, {10, 0, 0}}, 0.0);
  w.reset_drone(0, {0, 0, 1}, 0.0);
  std::mt19937_64 rng(1);
  std::vector<float> range;
  std::vector<std::uint8_t> hit;
  SensorConfig c = exact_sensors();
  c.count = 64;
  w.cast_rays(0, c, rng, range, hit);
  for (int k = 0; k < 64; ++k) EXPECT_EQ(hit[k], 0) << k;
  // Another drone 1.5 m ahead: its 0.3 m collision cylinder is 1.2 m away.
  w.reset_drone(1, {1.5, 0, 1}, 0.3);
  c.count = 8;
  w.cast_rays(0, c, rng, range, hit);
  EXPECT_EQ(hit[0], 1);
  EXPECT_NEAR(range[0], 1.2, 1e-4);
  // And drone 1 sees drone 0 behind it (ray pointing at world -x).
  c.yaw_offset_rad = kPi - 0.3;
  w.cast_rays(1, c, rng, range, hit);
  EXPECT_EQ(hit[0], 1);
  EXPECT_NEAR(range[0], 1.2, 1e-4);
}

TEST(RaySensors, TiltedDroneSeesTheGround) {
  Swarm s(empty_scene(), {{0, 0, 0}});
  s.take_off(1.0);  // ~1 m up
  s.sp[0].v_world = {5, 0, 0};
  s.run(0.3);  // accelerating: pitched nose-down
  const RigidState st = s.world.state(0);
  const Eigen::Vector3d fwd = st.q_world_body * Eigen::Vector3d::UnitX();
  ASSERT_LT(fwd.z(), -0.3) << "expected a clear nose-down pitch";
  std::mt19937_64 rng(1);
  std::vector<float> range;
  std::vector<std::uint8_t> hit;
  s.world.cast_rays(0, exact_sensors(), rng, range, hit);
  const double expected = st.p_world.z() / -fwd.z();  // ray 0 to the plane z = 0
  ASSERT_LT(expected, 4.0);
  EXPECT_EQ(hit[0], 1);
  EXPECT_NEAR(range[0], expected, 1e-4);
  EXPECT_EQ(hit[4], 0);  // pointing up and back: nothing
}

TEST(RaySensors, NoiseIsGaussianAndClamped) {
  PhysicsWorld w(scene_with({Cylinder{{2, 0}, 0.5, 6}}), QuadrotorParams{}, {{0, 0, 0}}, 0.0);
  w.reset_drone(0, {0, 0, 1}, 0.0);
  SensorConfig c;
  c.noise_sigma_m = 0.05;
  std::mt19937_64 rng(42);
  std::vector<float> range;
  std::vector<std::uint8_t> hit;
  double sum = 0, sum2 = 0;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    w.cast_rays(0, c, rng, range, hit);
    sum += range[0];
    sum2 += range[0] * range[0];
    EXPECT_EQ(range[1], 4.0f);  // misses stay exactly at max range
  }
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, 1.5, 0.01);
  EXPECT_NEAR(sd, 0.05, 0.005);
  // Near the minimum the noise is clamped.
  c.noise_sigma_m = 1.0;
  c.min_range_m = 1.0;
  for (int i = 0; i < 200; ++i) {
    w.cast_rays(0, c, rng, range, hit);
    EXPECT_GE(range[0], 1.0f);
    EXPECT_LE(range[0], 4.0f);
    EXPECT_EQ(hit[0], 1);
  }
}

TEST(RaySensors, CullingGivesTheSameRangesAsCastingEveryRay) {
  // kCulled must equal kBruteForce bit for bit; Bullet's rayTest is an
  // independent check of the analytic shapes.
  // A pillar field, a few boxes and 48 drones flying about at mixed heights.
  SceneConfig scene;
  for (int i = -3; i <= 3; ++i)
    for (int j = 0; j < 5; ++j)
      scene.cylinders.push_back(
          Cylinder{{i * 4.0 + 2.0, j * 4.0 + 6.0}, 0.4 + 0.1 * (j % 3), 1.5 + j});
  scene.boxes.push_back(Box{{-6, 2, 1}, {2, 1, 2}, 0.5});
  scene.boxes.push_back(Box{{6, 2, 0.5}, {1, 3, 1}, -0.3});
  std::vector<Eigen::Vector3d> starts;
  for (int i = 0; i < 48; ++i) starts.emplace_back((i % 8) * 1.5 - 5.25, (i / 8) * 3.0 + 4.0, 0.0);
  Swarm s(scene, starts);
  std::mt19937_64 pick(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (auto& sp : s.sp) sp.v_world = {0, 0, 1.0 + 0.5 * u(pick)};
  s.run(1.5);
  for (auto& sp : s.sp) {
    sp.v_world = {2.0 * u(pick), 2.0 * u(pick), 0.3 * u(pick)};
    sp.yaw_rate_rad_s = u(pick);
  }
  SensorConfig c = exact_sensors();
  c.count = 12;
  std::vector<float> r_fast, r_ref, r_bullet;
  std::vector<std::uint8_t> h_fast, h_ref, h_bullet;
  int hits = 0, compared = 0, bullet_disagree = 0, bullet_close = 0, bullet_far = 0;
  for (int round = 0; round < 6; ++round) {
    s.run(0.25);
    for (int d = 0; d < s.world.size(); ++d) {
      std::mt19937_64 g1(d), g2(d), g3(d);
      s.world.set_ray_cast_mode(RayCastMode::kCulled);
      s.world.cast_rays(d, c, g1, r_fast, h_fast);
      s.world.set_ray_cast_mode(RayCastMode::kBruteForce);
      s.world.cast_rays(d, c, g2, r_ref, h_ref);
      s.world.set_ray_cast_mode(RayCastMode::kWorldRayTest);
      s.world.cast_rays(d, c, g3, r_bullet, h_bullet);
      ASSERT_EQ(r_fast, r_ref) << "drone " << d << " round " << round;
      ASSERT_EQ(h_fast, h_ref) << "drone " << d << " round " << round;
      for (int k = 0; k < c.count; ++k) {
        if (h_fast[k] != h_bullet[k]) {
          ++bullet_disagree;
        } else if (h_fast[k]) {
          const double diff = std::abs(double(r_fast[k]) - r_bullet[k]);
          bullet_far += diff > 0.02;
          bullet_close += diff < 0.005;
        }
        hits += h_fast[k];
      }
      compared += c.count;
    }
  }
  // The comparison means something only if there were hits and misses.
  EXPECT_GT(hits, compared / 20);
  EXPECT_LT(hits, compared - compared / 20);
  // Bullet's GJK ray cast is approximate on thin shapes at shallow incidence
  // (its hit points fall up to a few cm inside a drone's disc, and it misses
  // some grazing edge hits), so it only has to agree broadly: misplaced or
  // mis-rotated analytic shapes would break these bounds by far.
  EXPECT_LE(bullet_disagree, compared / 100);
  EXPECT_GT(bullet_close, hits * 85 / 100);
  EXPECT_LE(bullet_far, hits / 50);
}

// ---------------------------------------------------------------- contacts

TEST(Contacts, FlyingIntoAPillarIsOneEvent) {
  // Pillar 0 at x = 3 (r 0.5), a box (obstacle 1) out of the way.
  Swarm s(scene_with({Cylinder{{3, 0}, 0.5, 5}}, {Box{{0, 8, 1}, {1, 1, 2}, 0}}), {{0, 0, 0}});
  s.take_off(1.0);
  EXPECT_TRUE(s.world.take_contact_events().empty()) << "lifting off starts no contact";
  s.sp[0].v_world = {1, 0, 0};
  s.run(5.0);  // reaches the pillar after ~2 s and keeps pushing into it
  const auto events = s.world.take_contact_events();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].drone, 0);
  EXPECT_EQ(events[0].kind, ContactKind::kObstacle);
  EXPECT_EQ(events[0].other, 0);
  EXPECT_NEAR((events[0].where_world.head<2>() - Eigen::Vector2d(3, 0)).norm(), 0.5, 0.05);
  EXPECT_GT(s.world.state(0).p_world.x(), 2.0);  // stopped by the pillar,
  EXPECT_LT(s.world.state(0).p_world.x(), 2.3);  // not through it
  // Backing off and flying in again is a second contact.
  s.sp[0].v_world = {-1, 0, 0};
  s.run(1.5);
  s.sp[0].v_world = {1, 0, 0};
  s.run(2.5);
  EXPECT_EQ(s.world.take_contact_events().size(), 1u);
}

TEST(Contacts, BoxesAreNumberedAfterCylinders) {
  Swarm s(scene_with({Cylinder{{-10, 0}, 0.5, 5}, Cylinder{{-10, 5}, 0.5, 5}},
                     {Box{{3, 0, 2}, {1, 4, 4}, 0.2}}),
          {{0, 0, 0}});
  s.take_off(1.0);
  s.sp[0].v_world = {1, 0, 0};
  s.run(4.0);
  const auto events = s.world.take_contact_events();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, ContactKind::kObstacle);
  EXPECT_EQ(events[0].other, 2);
}

TEST(Contacts, FlyingIntoAMeshWallIsOneEventNumberedAfterTheBoxes) {
  // Obstacles: a pillar (0) and a box (1) out of the way, a mesh that is only
  // an entry (2, as from the wire: nothing to hit), the mesh wall (3).
  SceneConfig scene = scene_with({Cylinder{{-10, 0}, 0.5, 5}}, {Box{{-10, 8, 1}, {1, 1, 2}, 0}});
  MeshObstacle entry = mesh_wall(-20, 1, 1);
  entry.world.reset();
  scene.meshes = {entry, mesh_wall(3, 5, 4)};
  Swarm s(scene, {{0, 0, 0}});
  s.take_off(1.0);
  EXPECT_TRUE(s.world.take_contact_events().empty());
  s.sp[0].v_world = {1, 0, 0};
  s.run(5.0);
  const auto events = s.world.take_contact_events();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, ContactKind::kObstacle);
  EXPECT_EQ(events[0].other, 3);
  EXPECT_NEAR(events[0].where_world.x(), 3.0, 0.05);
  const double r = QuadrotorParams{}.collision_radius_m;
  EXPECT_GT(s.world.state(0).p_world.x(), 3.0 - r - 0.1);  // stopped by the wall,
  EXPECT_LT(s.world.state(0).p_world.x(), 3.0);            // not through it
}

TEST(Contacts, TwoDronesPushedTogetherAreOneEvent) {
  Swarm s(empty_scene(), {{0, 0, 0}, {1.2, 0, 0}});
  s.take_off(1.0);
  ASSERT_TRUE(s.world.take_contact_events().empty());
  s.sp[0].v_world = {0.5, 0, 0};
  s.sp[1].v_world = {-0.5, 0, 0};
  s.run(3.0);  // meet after ~0.6 s, then keep pushing
  const auto events = s.world.take_contact_events();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].drone, 0);
  EXPECT_EQ(events[0].kind, ContactKind::kDrone);
  EXPECT_EQ(events[0].other, 1);
  EXPECT_NEAR(events[0].where_world.x(), 0.6, 0.1);
}

TEST(Contacts, LandingIsOneGroundEventNotOnePerStep) {
  PhysicsWorld w(empty_scene(), QuadrotorParams{}, {{0, 0, 0}, {3, 0, 0}}, 0.0);
  w.reset_drone(0, {0, 0, 0.5}, 0.0);
  EXPECT_FALSE(w.touching_ground(0));
  step_for(w, 3.0);  // falls, touches down, rests
  const auto events = w.take_contact_events();
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].drone, 0);
  EXPECT_EQ(events[0].kind, ContactKind::kGround);
  EXPECT_EQ(events[0].other, -1);
  EXPECT_NEAR(events[0].where_world.z(), 0.0, 0.02);
  EXPECT_TRUE(w.touching_ground(0));
  EXPECT_TRUE(w.touching_ground(1));
  step_for(w, 1.0);
  EXPECT_TRUE(w.take_contact_events().empty());
  // Dropped again: a new touchdown.
  w.reset_drone(0, {0, 0, 0.3}, 0.0);
  EXPECT_FALSE(w.touching_ground(0));
  step_for(w, 1.0);
  EXPECT_EQ(w.take_contact_events().size(), 1u);
  // Placed on the ground elsewhere: resting there is not a new contact.
  w.reset_drone(0, {5, 5, 0}, 0.0);
  step_for(w, 0.5);
  EXPECT_TRUE(w.take_contact_events().empty());
  EXPECT_TRUE(w.touching_ground(0));
}

TEST(Contacts, ManyDronesRestingProduceNoEvents) {
  std::vector<Eigen::Vector3d> starts;
  for (int i = 0; i < 100; ++i) starts.emplace_back((i % 10) * 1.0, (i / 10) * 1.0, 0.0);
  PhysicsWorld w(empty_scene(), QuadrotorParams{}, starts, 0.0);
  step_for(w, 0.5);
  EXPECT_TRUE(w.take_contact_events().empty());
  for (int i = 0; i < w.size(); ++i) {
    EXPECT_TRUE(w.touching_ground(i));
    EXPECT_LT((w.state(i).p_world - starts[i]).head<2>().norm(), 1e-3);
  }
}

// ---------------------------------------------------------------- Bullet's path

/// The shortcuts past Bullet's stock pipeline must change nothing: the same
/// flight (take-off from the ground, a drone into a pillar, two drones pushed
/// together, one drone moved through the air, landing) in both worlds gives
/// the same state, bit for bit, at every step, and the same contact events.
TEST(BulletPath, ShortcutsGiveBulletsStockResultsBitForBit) {
  const SceneConfig scene =
      scene_with({Cylinder{{3, 0}, 0.5, 5}}, {Box{{-4, 4, 1}, {1, 1, 2}, 0.3}});
  const std::vector<Eigen::Vector3d> starts{{0, 0, 0}, {0, 3, 0}, {1.2, 3, 0}};
  Swarm fast(scene, starts, 0.2, BulletPath::kShortcuts);
  Swarm stock(scene, starts, 0.2, BulletPath::kStock);
  int steps = 0, events = 0;
  const auto both = [&](auto&& set_setpoints, double seconds) {
    set_setpoints(fast);
    set_setpoints(stock);
    for (int k = 0; k < static_cast<int>(std::lround(seconds / kDt)); ++k, ++steps) {
      fast.step();
      stock.step();
      for (int i = 0; i < fast.world.size(); ++i) {
        const RigidState a = fast.world.state(i), b = stock.world.state(i);
        ASSERT_EQ(a.p_world, b.p_world) << "drone " << i << " at step " << steps;
        ASSERT_EQ(a.v_world, b.v_world) << "drone " << i << " at step " << steps;
        ASSERT_EQ(a.q_world_body.coeffs(), b.q_world_body.coeffs())
            << "drone " << i << " at step " << steps;
        ASSERT_EQ(a.w_body, b.w_body) << "drone " << i << " at step " << steps;
        ASSERT_EQ(fast.world.touching_ground(i), stock.world.touching_ground(i)) << "drone " << i;
      }
      const auto ea = fast.world.take_contact_events(), eb = stock.world.take_contact_events();
      ASSERT_EQ(ea.size(), eb.size()) << "at step " << steps;
      for (std::size_t j = 0; j < ea.size(); ++j) {
        EXPECT_EQ(ea[j].drone, eb[j].drone);
        EXPECT_EQ(ea[j].kind, eb[j].kind);
        EXPECT_EQ(ea[j].other, eb[j].other);
        EXPECT_EQ(ea[j].where_world, eb[j].where_world);
      }
      events += static_cast<int>(ea.size());
    }
  };
  both(
      [](Swarm& s) {
        for (auto& p : s.sp) p.v_world = {0, 0, 1};
      },
      1.5);
  both(
      [](Swarm& s) {
        s.sp[0].v_world = {1, 0, 0};    // into the pillar
        s.sp[1].v_world = {0.5, 0, 0};  // into each other
        s.sp[2].v_world = {-0.5, 0, 0};
      },
      4.0);
  both([](Swarm& s) { s.world.reset_drone(1, {-2, 3, 2.5}, 0.0); }, 1.0);  // moved, falls, caught
  both(
      [](Swarm& s) {
        for (auto& p : s.sp) p.v_world = {0, 0, -0.7};
      },
      5.0);  // down to the ground
  both(
      [](Swarm& s) {
        for (auto& p : s.sp) p.motors_on = false;
      },
      1.0);
  EXPECT_GE(events, 4) << "the flight must touch a pillar, a drone and the ground";
  for (int i = 0; i < fast.world.size(); ++i) EXPECT_TRUE(fast.world.touching_ground(i));
}

}  // namespace
}  // namespace ddswarm::sim
