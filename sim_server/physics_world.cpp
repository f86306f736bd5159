#include "sim_server/physics_world.hpp"

#include <BulletCollision/NarrowPhaseCollision/btRaycastCallback.h>
#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace ddswarm::sim {
namespace {

/// A pair touches while a contact point of theirs is closer than this (m).
/// (Bullet drops manifold points beyond ~8 mm for drone-sized shapes, so a
/// distance hysteresis cannot tell a bounce from a separation.)
constexpr double kTouchM = 0.005;
/// cast_rays queries Bullet's broadphase with this much slack (m) around the
/// sensor range: Bullet refreshes a drone's AABB at the start of a step, so
/// it may lag one step's motion (0.3 m is 300 m/s at 1 kHz), and its AABB of a
/// rounded (margin) shape can be a few mm smaller than the exact shape's.
constexpr double kQuerySlackM = 0.3;
/// Rounding pad (m) on the exact AABBs used to cull rays.
constexpr double kAabbPadM = 1e-3;
constexpr double kInf = std::numeric_limits<double>::infinity();
/// Collision margin (m) of drones and obstacles. Bullet's default (4 cm) would
/// round a 5 cm half-height drone into a lens with a 2 cm tall side.
constexpr btScalar kShapeMarginM = 0.01;

btVector3 to_bt(const Eigen::Vector3d& v) {
  return btVector3(static_cast<btScalar>(v.x()), static_cast<btScalar>(v.y()),
                   static_cast<btScalar>(v.z()));
}
Eigen::Vector3d to_eigen(const btVector3& v) { return {v.x(), v.y(), v.z()}; }
Eigen::Matrix3d to_eigen(const btMatrix3x3& m) {
  Eigen::Matrix3d r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r(i, j) = m[i][j];
  return r;
}

ContactKind kind_of(const btCollisionObject* o) {
  return static_cast<ContactKind>(o->getUserIndex2());
}

/// Key of a pair: drone (20 bits) | kind (8) | other + 1 (32), so sorting
/// groups by drone. Returns false for pairs without a drone.
bool pair_key(const btCollisionObject* a, const btCollisionObject* b, std::uint64_t& key) {
  if (kind_of(a) != ContactKind::kDrone) std::swap(a, b);
  if (kind_of(a) != ContactKind::kDrone) return false;
  int drone = a->getUserIndex();
  int other = b->getUserIndex();
  const ContactKind kind = kind_of(b);
  if (kind == ContactKind::kDrone && other < drone) std::swap(drone, other);
  key = (static_cast<std::uint64_t>(drone) << 40) | (static_cast<std::uint64_t>(kind) << 32) |
        static_cast<std::uint32_t>(other + 1);
  return true;
}

/// The event a pair key stands for (where_world left at zero).
ContactEvent event_of(std::uint64_t key) {
  ContactEvent e;
  e.drone = static_cast<int>(key >> 40);
  e.kind = static_cast<ContactKind>((key >> 32) & 0xff);
  e.other = static_cast<int>(static_cast<std::uint32_t>(key)) - 1;
  return e;
}

bool involves(std::uint64_t key, int drone) {
  const ContactEvent e = event_of(key);
  return e.drone == drone || (e.kind == ContactKind::kDrone && e.other == drone);
}

/// Clips the ray parameter interval [t0, t1] to the slab lo <= o + t d <= hi
/// (one axis); false when the interval becomes empty.
bool clip_slab(double o, double d, double lo, double hi, double& t0, double& t1) {
  if (d == 0) return o >= lo && o <= hi;
  double a = (lo - o) / d, b = (hi - o) / d;
  if (a > b) std::swap(a, b);
  t0 = std::max(t0, a);
  t1 = std::min(t1, b);
  return t0 <= t1;
}

/// Distance along a unit ray (o, d) to a z-axis cylinder centred at the
/// origin (radius r, half height h), within [0, t_max]; kInf if none. A ray
/// starting inside returns 0.
double ray_cylinder_z(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double r, double h,
                      double t_max) {
  double t0 = 0, t1 = t_max;
  if (!clip_slab(o.z(), d.z(), -h, h, t0, t1)) return kInf;
  const double a = d.x() * d.x() + d.y() * d.y();
  const double b = o.x() * d.x() + o.y() * d.y();
  const double c = o.x() * o.x() + o.y() * o.y() - r * r;
  if (a < 1e-18) return c <= 0 ? t0 : kInf;  // parallel to the axis
  const double disc = b * b - a * c;
  if (disc < 0) return kInf;
  const double sq = std::sqrt(disc);
  t0 = std::max(t0, (-b - sq) / a);
  t1 = std::min(t1, (-b + sq) / a);
  return t0 <= t1 ? t0 : kInf;
}

/// Distance along a unit ray to an axis-aligned box centred at the origin.
double ray_box(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& half,
               double t_max) {
  double t0 = 0, t1 = t_max;
  for (int k = 0; k < 3; ++k)
    if (!clip_slab(o[k], d[k], -half[k], half[k], t0, t1)) return kInf;
  return t0;
}

/// The nearest triangle a ray crosses, either face.
struct NearestTriangle final : btTriangleRaycastCallback {
  using btTriangleRaycastCallback::btTriangleRaycastCallback;
  btScalar reportHit(const btVector3&, btScalar fraction, int, int) override {
    return m_hitFraction = std::min(m_hitFraction, fraction);
  }
};

/// Distance along a unit ray to a triangle mesh whose vertices are in the
/// world frame, within [0, t_max]; kInf if none.
double ray_mesh(btBvhTriangleMeshShape& mesh, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                double t_max) {
  const btVector3 from = to_bt(o), to = to_bt(o + d * t_max);
  NearestTriangle cb(from, to);
  mesh.performRaycast(&cb, from, to);
  return cb.m_hitFraction < 1 ? cb.m_hitFraction * t_max : kInf;
}

/// Distance along a unit ray to the half-space z <= ground_z.
double ray_ground(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double ground_z,
                  double t_max) {
  double t0 = 0, t1 = t_max;
  return clip_slab(o.z(), d.z(), -kInf, ground_z, t0, t1) ? t0 : kInf;
}

bool ray_hits_aabb(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& lo,
                   const Eigen::Vector3d& hi, double t_max) {
  double t0 = 0, t1 = t_max;
  for (int k = 0; k < 3; ++k)
    if (!clip_slab(o[k], d[k], lo[k], hi[k], t0, t1)) return false;
  return true;
}

bool overlaps(const Eigen::Vector3d& amin, const Eigen::Vector3d& amax, const Eigen::Vector3d& bmin,
              const Eigen::Vector3d& bmax) {
  return (amin.array() <= bmax.array()).all() && (amax.array() >= bmin.array()).all();
}

/// Closest hit ignoring one object (the casting drone), for kWorldRayTest.
/// Uses the GJK convex cast: Bullet's default (subsimplex) cast reports rays
/// passing within 1 cm of a shape as hits.
struct ClosestExcept : btCollisionWorld::ClosestRayResultCallback {
  ClosestExcept(const btVector3& from, const btVector3& to, const btCollisionObject* self)
      : ClosestRayResultCallback(from, to), self_(self) {
    m_flags |= btTriangleRaycastCallback::kF_UseGjkConvexCastRaytest;
  }
  bool needsCollision(btBroadphaseProxy* proxy) const override {
    return proxy->m_clientObject != self_ && ClosestRayResultCallback::needsCollision(proxy);
  }
  const btCollisionObject* self_;
};

/// Collects the drones and obstacles whose broadphase proxy overlaps a box.
struct GatherProxies : btBroadphaseAabbCallback {
  GatherProxies(const btCollisionObject* self, std::vector<const btCollisionObject*>& out)
      : self_(self), out_(out) {}
  bool process(const btBroadphaseProxy* proxy) override {
    const auto* o = static_cast<const btCollisionObject*>(proxy->m_clientObject);
    if (o != self_ && kind_of(o) != ContactKind::kGround) out_.push_back(o);
    return true;
  }
  const btCollisionObject* self_;
  std::vector<const btCollisionObject*>& out_;
};

/// Bullet's dispatcher, minus one test that can have no result: the ground
/// plane's AABB is infinite, so every drone stays paired with it and Bullet
/// runs the convex-plane test for each drone at every step (16 % of a step
/// at 64 hovering drones, measured with callgrind). A drone whose broadphase
/// AABB (which already includes Bullet's contact threshold) is clear of the
/// ground, and whose manifold with it is empty, gets no point from that test
/// and leaves the manifold as it is, so skipping it changes nothing.
class DroneDispatcher final : public btCollisionDispatcher {
 public:
  DroneDispatcher(btCollisionConfiguration* config, double ground_z_m)
      : btCollisionDispatcher(config),
        clear_above_z_(static_cast<btScalar>(ground_z_m) + kGroundClearM) {
    setNearCallback(&DroneDispatcher::near_callback);
  }

 private:
  /// Far more than Bullet's contact breaking threshold (2 cm at most).
  static constexpr btScalar kGroundClearM = 0.05f;

  static void near_callback(btBroadphasePair& pair, btCollisionDispatcher& dispatcher,
                            const btDispatcherInfo& info) {
    auto& self = static_cast<DroneDispatcher&>(dispatcher);
    if (pair.m_algorithm && self.clear_of_ground(pair)) return;
    defaultNearCallback(pair, dispatcher, info);
  }

  bool clear_of_ground(const btBroadphasePair& pair) {
    const auto* a = static_cast<const btCollisionObject*>(pair.m_pProxy0->m_clientObject);
    const auto* b = static_cast<const btCollisionObject*>(pair.m_pProxy1->m_clientObject);
    const btBroadphaseProxy* drone;
    if (kind_of(a) == ContactKind::kGround && kind_of(b) == ContactKind::kDrone)
      drone = pair.m_pProxy1;
    else if (kind_of(b) == ContactKind::kGround && kind_of(a) == ContactKind::kDrone)
      drone = pair.m_pProxy0;
    else
      return false;
    if (!(drone->m_aabbMin.z() > clear_above_z_)) return false;
    manifolds_.resize(0);
    pair.m_algorithm->getAllContactManifolds(manifolds_);
    for (int i = 0; i < manifolds_.size(); ++i)
      if (manifolds_[i]->getNumContacts() > 0) return false;
    return true;
  }

  btScalar clear_above_z_;
  btManifoldArray manifolds_;
};

/// Bullet's world, minus two passes that change nothing for our bodies:
/// - the continuous-collision pass when no body asks for it:
///   createPredictiveContacts predicts every body's motion each step (7 % of
///   a step at 64 drones) only to compare it with a CCD threshold of 0. What
///   it leaves behind without CCD, each body's hit fraction at 1 and no
///   predictive manifolds, is done here directly;
/// - damping by a factor of powf(1 - 0, dt) = 1 (two powf calls per body and
///   step, 4 %): drones have no Bullet damping (drag is our force model) and
///   no body here is made with additional damping.
class DroneDynamicsWorld final : public btDiscreteDynamicsWorld {
 public:
  using btDiscreteDynamicsWorld::btDiscreteDynamicsWorld;

 protected:
  void predictUnconstraintMotion(btScalar time_step) override {
    for (int i = 0; i < m_nonStaticRigidBodies.size(); ++i) {
      btRigidBody* body = m_nonStaticRigidBodies[i];
      if (body->isStaticOrKinematicObject()) continue;
      if (body->getLinearDamping() != 0 || body->getAngularDamping() != 0)
        body->applyDamping(time_step);
      body->predictIntegratedTransform(time_step, body->getInterpolationWorldTransform());
    }
  }

  void createPredictiveContacts(btScalar time_step) override {
    for (int i = 0; i < m_nonStaticRigidBodies.size(); ++i)
      if (m_nonStaticRigidBodies[i]->getCcdSquareMotionThreshold() != 0) {
        btDiscreteDynamicsWorld::createPredictiveContacts(time_step);
        return;
      }
    releasePredictiveContacts();
    for (int i = 0; i < m_nonStaticRigidBodies.size(); ++i)
      m_nonStaticRigidBodies[i]->setHitFraction(1.f);
  }
};

}  // namespace

PhysicsWorld::PhysicsWorld(const SceneConfig& scene, const QuadrotorParams& q,
                           const std::vector<Eigen::Vector3d>& start_positions,
                           double start_yaw_rad, BulletPath path)
    : PhysicsWorld(scene, std::vector<QuadrotorParams>{q},
                   std::vector<int>(start_positions.size(), 0), start_positions, start_yaw_rad,
                   path) {}

PhysicsWorld::PhysicsWorld(const SceneConfig& scene, const std::vector<QuadrotorParams>& airframes,
                           const std::vector<int>& airframe_of,
                           const std::vector<Eigen::Vector3d>& start_positions,
                           double start_yaw_rad, BulletPath path)
    : ground_z_m_(scene.ground_z_m) {
  if (start_positions.size() >= (1u << 20))
    throw std::invalid_argument("PhysicsWorld: too many drones (" +
                                std::to_string(start_positions.size()) + ")");
  if (airframes.empty() || airframe_of.size() != start_positions.size())
    throw std::invalid_argument("PhysicsWorld: one airframe index per drone needed");
  for (int a : airframe_of)
    if (a < 0 || a >= static_cast<int>(airframes.size()))
      throw std::invalid_argument("PhysicsWorld: airframe index " + std::to_string(a));
  for (const QuadrotorParams& q : airframes) {
    Model m{q, q.k_f(), q.k_m(), q.omega_min_rad_s, q.omega_max_rad_s(), {}, nullptr};
    for (int i = 0; i < 4; ++i) m.rotor_pos[i] = q.rotor_position_body(i);
    m.shape = std::make_unique<btCylinderShapeZ>(to_bt(
        Eigen::Vector3d(q.collision_radius_m, q.collision_radius_m, q.collision_half_height_m)));
    m.shape->setMargin(
        std::min(kShapeMarginM, static_cast<btScalar>(q.collision_half_height_m / 2)));
    models_.push_back(std::move(m));
  }
  lag_up_.resize(models_.size());
  lag_down_.resize(models_.size());

  collision_config_ = std::make_unique<btDefaultCollisionConfiguration>();
  broadphase_ = std::make_unique<btDbvtBroadphase>();
  solver_ = std::make_unique<btSequentialImpulseConstraintSolver>();
  if (path == BulletPath::kShortcuts) {
    dispatcher_ = std::make_unique<DroneDispatcher>(collision_config_.get(), scene.ground_z_m);
    world_ = std::make_unique<DroneDynamicsWorld>(dispatcher_.get(), broadphase_.get(),
                                                  solver_.get(), collision_config_.get());
    // Static bodies never move: their AABBs need no update at every step (by
    // default Bullet recomputes all of them; the thesis course has 16 obstacles).
    world_->setForceUpdateAllAabbs(false);
  } else {
    dispatcher_ = std::make_unique<btCollisionDispatcher>(collision_config_.get());
    world_ = std::make_unique<btDiscreteDynamicsWorld>(dispatcher_.get(), broadphase_.get(),
                                                       solver_.get(), collision_config_.get());
  }
  world_->setGravity(btVector3(0, 0, static_cast<btScalar>(-kGravityMps2)));

  add_static(std::make_unique<btStaticPlaneShape>(btVector3(0, 0, 1),
                                                  static_cast<btScalar>(scene.ground_z_m)),
             Eigen::Vector3d::Zero(), 0.0, ContactKind::kGround, -1);
  int index = 0;
  for (const Cylinder& c : scene.cylinders) {
    const double h = c.height_m / 2;
    obstacle_shapes_.push_back(
        {Eigen::Vector3d(c.center_xy.x(), c.center_xy.y(), scene.ground_z_m + h),
         Eigen::Vector3d(c.radius_m, c.radius_m, h), 1.0, 0.0, false});
    add_static(
        std::make_unique<btCylinderShapeZ>(to_bt(Eigen::Vector3d(c.radius_m, c.radius_m, h))),
        Eigen::Vector3d(c.center_xy.x(), c.center_xy.y(), scene.ground_z_m + h), 0.0,
        ContactKind::kObstacle, index++);
  }
  for (const Box& b : scene.boxes) {
    obstacle_shapes_.push_back(
        {b.center, b.size / 2, std::cos(b.yaw_rad), std::sin(b.yaw_rad), true});
    add_static(std::make_unique<btBoxShape>(to_bt(b.size / 2)), b.center, b.yaw_rad,
               ContactKind::kObstacle, index++);
  }
  for (const MeshObstacle& m : scene.meshes) {
    if (!m.world || m.world->triangles.empty()) {
      // Nothing to collide with, but the indices stay the Scene's.
      obstacle_shapes_.push_back(
          {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), 1.0, 0.0, false, nullptr});
      ++index;
      continue;
    }
    auto tm = std::make_unique<btTriangleMesh>(true, false);
    const auto& v = m.world->vertices;
    for (const auto& t : m.world->triangles)
      tm->addTriangle(btVector3(v[t[0]].x(), v[t[0]].y(), v[t[0]].z()),
                      btVector3(v[t[1]].x(), v[t[1]].y(), v[t[1]].z()),
                      btVector3(v[t[2]].x(), v[t[2]].y(), v[t[2]].z()), false);
    auto shape = std::make_unique<btBvhTriangleMeshShape>(tm.get(), true);
    obstacle_shapes_.push_back({(m.bounds_min + m.bounds_max) / 2,
                                (m.bounds_max - m.bounds_min) / 2, 1.0, 0.0, false, shape.get()});
    triangle_meshes_.push_back(std::move(tm));
    add_static(std::move(shape), Eigen::Vector3d::Zero(), 0.0, ContactKind::kObstacle, index++);
  }

  drones_.reserve(start_positions.size());
  for (std::size_t i = 0; i < start_positions.size(); ++i) {
    const Model& m = models_[airframe_of[i]];
    btRigidBody::btRigidBodyConstructionInfo info(static_cast<btScalar>(m.p.mass_kg), nullptr,
                                                  m.shape.get(), to_bt(m.p.inertia()));
    Drone d;
    d.model = airframe_of[i];
    d.body = std::make_unique<btRigidBody>(info);
    d.body->setActivationState(DISABLE_DEACTIVATION);
    d.body->setUserIndex(static_cast<int>(i));
    d.body->setUserIndex2(static_cast<int>(ContactKind::kDrone));
    place(*d.body, m.p.collision_half_height_m, start_positions[i], start_yaw_rad);
    world_->addRigidBody(d.body.get());
    drones_.push_back(std::move(d));
  }
  touching_ground_.assign(drones_.size(), 0);
  quiet_.assign(drones_.size(), 0);
  touching_.reserve(2 * drones_.size() + 16);
  in_contact_.reserve(2 * drones_.size() + 16);
  in_contact_next_.reserve(2 * drones_.size() + 16);

  // Seed the contact state with what touches already (drones on the ground).
  world_->performDiscreteCollisionDetection();
  update_contacts(false);
}

PhysicsWorld::~PhysicsWorld() {
  // The world's destructor touches every object still in it: take them out first.
  for (auto& d : drones_) world_->removeRigidBody(d.body.get());
  for (auto& s : statics_) world_->removeRigidBody(s.get());
}

void PhysicsWorld::add_static(std::unique_ptr<btCollisionShape> shape,
                              const Eigen::Vector3d& origin, double yaw_rad, ContactKind kind,
                              int index) {
  btTransform t;
  t.setIdentity();
  t.setOrigin(to_bt(origin));
  t.setRotation(btQuaternion(btVector3(0, 0, 1), static_cast<btScalar>(yaw_rad)));
  if (kind != ContactKind::kGround) shape->setMargin(kShapeMarginM);
  btRigidBody::btRigidBodyConstructionInfo info(0, nullptr, shape.get());
  info.m_startWorldTransform = t;
  auto body = std::make_unique<btRigidBody>(info);
  body->setUserIndex(index);
  body->setUserIndex2(static_cast<int>(kind));
  world_->addRigidBody(body.get());
  static_shapes_.push_back(std::move(shape));
  statics_.push_back(std::move(body));
}

void PhysicsWorld::place(btRigidBody& body, double half_height_m, const Eigen::Vector3d& bottom,
                         double yaw_rad) const {
  btTransform t;
  t.setIdentity();
  t.setOrigin(to_bt(bottom + Eigen::Vector3d(0, 0, half_height_m)));
  t.setRotation(btQuaternion(btVector3(0, 0, 1), static_cast<btScalar>(yaw_rad)));
  body.setWorldTransform(t);
  body.setInterpolationWorldTransform(t);
  body.setLinearVelocity(btVector3(0, 0, 0));
  body.setAngularVelocity(btVector3(0, 0, 0));
  body.setInterpolationLinearVelocity(btVector3(0, 0, 0));
  body.setInterpolationAngularVelocity(btVector3(0, 0, 0));
  body.clearForces();
}

void PhysicsWorld::set_rotor_commands(int drone, const std::array<double, 4>& omega_cmd_rad_s) {
  Drone& d = drones_[drone];
  const Model& m = models_[d.model];
  for (int i = 0; i < 4; ++i)
    d.omega_cmd[i] = std::clamp(omega_cmd_rad_s[i], m.omega_min, m.omega_max);
}

void PhysicsWorld::step(double dt) {
  // Exact first-order steps; a rotor slowing down may lag more than one speeding up.
  for (std::size_t k = 0; k < models_.size(); ++k) {
    const double tau = models_[k].p.motor_tau_s;
    const double tau_down = models_[k].p.motor_tau_down_s > 0 ? models_[k].p.motor_tau_down_s : tau;
    lag_up_[k] = tau > 0 ? 1.0 - std::exp(-dt / tau) : 1.0;
    lag_down_[k] = tau_down > 0 ? 1.0 - std::exp(-dt / tau_down) : 1.0;
  }
  if (aero_.downwash) update_downwash_candidates();
  for (std::size_t n = 0; n < drones_.size(); ++n) {
    Drone& d = drones_[n];
    const Model& m = models_[d.model];
    const Eigen::Vector3d& c_quad = m.p.drag_quadratic_body;
    const double c_lin = m.p.drag_linear_n_per_mps;
    const double c_ang = m.p.angular_drag_nm_per_rad_s;
    const double prop_r = 0.5 * m.p.prop_diameter_m;
    const double lag_up = lag_up_[d.model], lag_down = lag_down_[d.model];
    double thrust = 0.0;
    Eigen::Vector3d torque_b(0, 0, 0);
    btRigidBody& body = *d.body;
    const Eigen::Matrix3d r = to_eigen(body.getWorldTransform().getBasis());
    const Eigen::Vector3d p = to_eigen(body.getWorldTransform().getOrigin());
    for (int i = 0; i < 4; ++i) {
      const double lag = d.omega_cmd[i] >= d.omega[i] ? lag_up : lag_down;
      d.omega[i] += lag * (d.omega_cmd[i] - d.omega[i]);
      const double w2 = d.omega[i] * d.omega[i];
      double t = m.k_f * w2;
      // Each rotor's hub height above the ground sets its ground effect.
      if (aero_.ground_effect)
        t *= ground_effect_ratio((p + r * m.rotor_pos[i]).z() - ground_z_m_, prop_r);
      thrust += t;
      torque_b.x() += m.rotor_pos[i].y() * t;
      torque_b.y() -= m.rotor_pos[i].x() * t;
      torque_b.z() -= QuadrotorParams::rotor_spin(i) * m.k_m * w2;
    }
    // Drag acts on the airspeed: the velocity relative to the air (the wind).
    const Eigen::Vector3d v_b = r.transpose() * (to_eigen(body.getLinearVelocity()) - d.air_world);
    const Eigen::Vector3d w_b = r.transpose() * to_eigen(body.getAngularVelocity());
    Eigen::Vector3d force_b = -c_quad.cwiseProduct(v_b.cwiseProduct(v_b.cwiseAbs())) - c_lin * v_b;
    if (aero_.rotor_drag) force_b += rotor_drag_force(m.p.rotor_drag_body, v_b, d.omega);
    force_b.z() += thrust;
    torque_b -= c_ang * w_b;
    Eigen::Vector3d force_w = r * force_b;
    if (aero_.downwash)
      for (std::size_t k = downwash_begin_[n]; k < downwash_begin_[n + 1]; ++k) {
        // Only a drone above and within reach pushes (downwash_force decides
        // at the edge: the margin keeps every pair it would take).
        const int u = downwash_from_[k];
        const Eigen::Vector3d d = downwash_p_[u] - p;
        constexpr double kReach2 = kDownwashReachM * kDownwashReachM * (1 + 1e-9);
        if (d.z() > 0 && d.head<2>().squaredNorm() < kReach2)
          force_w.z() -= downwash_force(aero_, downwash_p_[u], p,
                                        0.5 * models_[drones_[u].model].p.prop_diameter_m);
      }
    body.applyCentralForce(to_bt(force_w));
    body.applyTorque(to_bt(r * torque_b));
  }
  world_->stepSimulation(static_cast<btScalar>(dt), 0);
  time_s_ += dt;
  update_contacts(true);
}

void PhysicsWorld::update_downwash_candidates() {
  const std::size_t count = drones_.size();
  downwash_p_.resize(count);
  bool rebuild = downwash_built_p_.size() != count;
  constexpr double kHalfSkin2 = 0.25 * kDownwashSkinM * kDownwashSkinM;
  for (std::size_t n = 0; n < count; ++n) {
    const Eigen::Vector3d p = to_eigen(drones_[n].body->getWorldTransform().getOrigin());
    downwash_p_[n] = p;
    if (rebuild) continue;
    const Eigen::Vector3d& built = downwash_built_p_[n];
    if (p.allFinite() != built.allFinite() ||
        (p.allFinite() && (p - built).head<2>().squaredNorm() > kHalfSkin2))
      rebuild = true;
  }
  if (!rebuild) return;
  // Every drone has moved less than half the skin sideways since the list was
  // built, so a pair within reach now was within reach plus the skin then.
  downwash_built_p_ = downwash_p_;
  // A grid cell per reach-plus-skin square: such a pair sits in the same or
  // adjacent cells. Far-off cells are clamped, which keeps adjacency; a drone
  // with a non-finite position is in none (it feels and gives no downwash, as
  // downwash_force says of it).
  constexpr double kCellM = kDownwashReachM + kDownwashSkinM;
  auto cell_of = [](double x) {
    return static_cast<std::int64_t>(std::clamp(std::floor(x / kCellM), -1e8, 1e8));
  };
  auto key = [](std::int64_t cx, std::int64_t cy) {
    return (static_cast<std::uint64_t>(cx) << 32) ^ static_cast<std::uint32_t>(cy);
  };
  cells_.clear();
  for (std::size_t n = 0; n < count; ++n) {
    const Eigen::Vector3d& p = downwash_p_[n];
    if (p.allFinite()) cells_.push_back({key(cell_of(p.x()), cell_of(p.y())), static_cast<int>(n)});
  }
  std::sort(cells_.begin(), cells_.end());
  downwash_from_.clear();
  downwash_begin_.assign(count + 1, 0);
  for (std::size_t n = 0; n < count; ++n) {
    downwash_begin_[n] = downwash_from_.size();
    const Eigen::Vector3d& p = downwash_p_[n];
    if (!p.allFinite()) continue;
    const std::int64_t cx = cell_of(p.x()), cy = cell_of(p.y());
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy) {
        const std::uint64_t k = key(cx + dx, cy + dy);
        for (auto it = std::lower_bound(cells_.begin(), cells_.end(), std::make_pair(k, 0));
             it != cells_.end() && it->first == k; ++it)
          if (it->second != static_cast<int>(n) &&
              (downwash_p_[it->second] - p).head<2>().squaredNorm() < kCellM * kCellM)
            downwash_from_.push_back(it->second);
      }
    // Index order, as every pair summed in turn would give.
    std::sort(downwash_from_.begin() + static_cast<std::ptrdiff_t>(downwash_begin_[n]),
              downwash_from_.end());
  }
  downwash_begin_[count] = downwash_from_.size();
}

void PhysicsWorld::update_contacts(bool report) {
  touching_.clear();
  const int manifolds = dispatcher_->getNumManifolds();
  for (int m = 0; m < manifolds; ++m) {
    const btPersistentManifold* pm = dispatcher_->getManifoldByIndexInternal(m);
    const int n = pm->getNumContacts();
    if (n == 0) continue;
    int best = 0;
    for (int k = 1; k < n; ++k)
      if (pm->getContactPoint(k).getDistance() < pm->getContactPoint(best).getDistance()) best = k;
    const btManifoldPoint& pt = pm->getContactPoint(best);
    if (pt.getDistance() >= kTouchM) continue;
    std::uint64_t key;
    if (!pair_key(pm->getBody0(), pm->getBody1(), key)) continue;
    touching_.push_back(
        {key, to_eigen((pt.getPositionWorldOnA() + pt.getPositionWorldOnB()) * 0.5)});
  }
  std::sort(touching_.begin(), touching_.end(),
            [](const PairContact& a, const PairContact& b) { return a.key < b.key; });

  // Merge this step's touching pairs (sorted) with the pairs in contact
  // (sorted): new ones begin (an event unless their drone was just placed),
  // absent ones end once they have been apart for kContactReleaseS.
  const auto quiet = [&](std::uint64_t key) {
    const ContactEvent e = event_of(key);
    return quiet_[e.drone] || (e.kind == ContactKind::kDrone && quiet_[e.other]);
  };
  in_contact_next_.clear();
  std::size_t i = 0, j = 0;
  while (i < touching_.size() || j < in_contact_.size()) {
    if (i < touching_.size() && i + 1 < touching_.size() &&
        touching_[i + 1].key == touching_[i].key) {
      ++i;  // two manifolds for one pair
      continue;
    }
    const bool take_new =
        j == in_contact_.size() || (i < touching_.size() && touching_[i].key < in_contact_[j].key);
    const bool take_old =
        i == touching_.size() || (j < in_contact_.size() && in_contact_[j].key < touching_[i].key);
    if (take_new) {
      in_contact_next_.push_back({touching_[i].key, time_s_});
      if (report && !quiet(touching_[i].key)) {
        events_.push_back(event_of(touching_[i].key));
        events_.back().where_world = touching_[i].where_world;
      }
      ++i;
    } else if (take_old) {
      if (time_s_ - in_contact_[j].last_touch_s < kContactReleaseS)
        in_contact_next_.push_back(in_contact_[j]);
      ++j;
    } else {  // still touching
      in_contact_next_.push_back({touching_[i].key, time_s_});
      ++i;
      ++j;
    }
  }
  in_contact_.swap(in_contact_next_);

  std::fill(touching_ground_.begin(), touching_ground_.end(), 0);
  std::fill(quiet_.begin(), quiet_.end(), 0);
  for (const PairContact& c : touching_)
    if (static_cast<ContactKind>((c.key >> 32) & 0xff) == ContactKind::kGround)
      touching_ground_[c.key >> 40] = 1;
}

RigidState PhysicsWorld::state(int drone) const {
  const btRigidBody& body = *drones_[drone].body;
  const btTransform& t = body.getWorldTransform();
  const btQuaternion bq = t.getRotation();
  RigidState s;
  s.p_world = to_eigen(t.getOrigin());
  s.v_world = to_eigen(body.getLinearVelocity());
  s.q_world_body = Eigen::Quaterniond(bq.w(), bq.x(), bq.y(), bq.z()).normalized();
  s.w_body = s.q_world_body.inverse() * to_eigen(body.getAngularVelocity());
  return s;
}

std::array<double, 4> PhysicsWorld::rotor_speeds(int drone) const { return drones_[drone].omega; }

void PhysicsWorld::reset_drone(int drone, const Eigen::Vector3d& p, double yaw_rad) {
  Drone& d = drones_[drone];
  // Re-adding the body drops its stale contact manifolds and lets the
  // broadphase find its new neighbours at once.
  world_->removeRigidBody(d.body.get());
  place(*d.body, models_[d.model].p.collision_half_height_m, p, yaw_rad);
  world_->addRigidBody(d.body.get());
  d.omega_cmd.fill(0.0);
  d.omega.fill(0.0);
  // A teleport ends the drone's contacts; those at its new place are adopted
  // by the next step without events, as at construction.
  in_contact_.erase(std::remove_if(in_contact_.begin(), in_contact_.end(),
                                   [&](const ContactState& c) { return involves(c.key, drone); }),
                    in_contact_.end());
  touching_ground_[drone] = 0;
  quiet_[drone] = 1;
}

std::vector<ContactEvent> PhysicsWorld::take_contact_events() {
  std::vector<ContactEvent> out(events_.begin(), events_.end());
  events_.clear();
  return out;
}

void PhysicsWorld::ray_target(const btCollisionObject* o, RayTarget& t) const {
  t.drone = kind_of(o) == ContactKind::kDrone;
  t.index = o->getUserIndex();
  Eigen::Vector3d extent;
  if (t.drone) {
    const btTransform& tr = o->getWorldTransform();
    t.center = to_eigen(tr.getOrigin());
    t.rot = to_eigen(tr.getBasis());
    const QuadrotorParams& q = models_[drones_[t.index].model].p;
    const Eigen::Vector3d half(q.collision_radius_m, q.collision_radius_m,
                               q.collision_half_height_m);
    extent = t.rot.cwiseAbs() * half;
  } else {
    const ObstacleShape& s = obstacle_shapes_[t.index];
    t.center = s.center;
    extent =
        s.box ? Eigen::Vector3d(std::abs(s.cos_yaw) * s.half.x() + std::abs(s.sin_yaw) * s.half.y(),
                                std::abs(s.sin_yaw) * s.half.x() + std::abs(s.cos_yaw) * s.half.y(),
                                s.half.z())
              : s.half;
  }
  t.aabb_min = t.center - extent - Eigen::Vector3d::Constant(kAabbPadM);
  t.aabb_max = t.center + extent + Eigen::Vector3d::Constant(kAabbPadM);
}

double PhysicsWorld::ray_distance(const RayTarget& t, const Eigen::Vector3d& o,
                                  const Eigen::Vector3d& d, double t_max) const {
  if (t.drone) {
    const QuadrotorParams& q = models_[drones_[t.index].model].p;
    return ray_cylinder_z(t.rot.transpose() * (o - t.center), t.rot.transpose() * d,
                          q.collision_radius_m, q.collision_half_height_m, t_max);
  }
  const ObstacleShape& s = obstacle_shapes_[t.index];
  if (s.mesh) return ray_mesh(*s.mesh, o, d, t_max);
  const Eigen::Vector3d r = o - s.center;
  if (!s.box) return ray_cylinder_z(r, d, s.half.x(), s.half.z(), t_max);
  // Into the box frame: rotate by -yaw.
  const Eigen::Vector3d lo(s.cos_yaw * r.x() + s.sin_yaw * r.y(),
                           -s.sin_yaw * r.x() + s.cos_yaw * r.y(), r.z());
  const Eigen::Vector3d ld(s.cos_yaw * d.x() + s.sin_yaw * d.y(),
                           -s.sin_yaw * d.x() + s.cos_yaw * d.y(), d.z());
  return ray_box(lo, ld, s.half, t_max);
}

void PhysicsWorld::cast_rays(int drone, const SensorConfig& cfg, std::mt19937_64& rng,
                             std::vector<float>& range_m, std::vector<std::uint8_t>& hit) const {
  const int n = std::clamp(cfg.rays(), 0, SensorConfig::kMaxRays);
  const double max_range = cfg.max_range_m;
  range_m.assign(n, static_cast<float>(max_range));
  hit.assign(n, 0);

  const btRigidBody* self = drones_[drone].body.get();
  const btTransform& body_t = self->getWorldTransform();
  const Eigen::Vector3d origin = to_eigen(body_t.getOrigin());
  const Eigen::Matrix3d rot = to_eigen(body_t.getBasis());
  std::array<Eigen::Vector3d, SensorConfig::kMaxRays> dir;
  for (int k = 0; k < n; ++k) dir[k] = rot * cfg.ray_direction_body(k);
  std::array<double, SensorConfig::kMaxRays> dist;
  dist.fill(kInf);

  if (ray_mode_ == RayCastMode::kWorldRayTest) {
    const btVector3 from = body_t.getOrigin();
    for (int k = 0; k < n; ++k) {
      const btVector3 to = from + to_bt(dir[k] * max_range);
      ClosestExcept cb(from, to, self);
      world_->rayTest(from, to, cb);
      if (cb.hasHit()) dist[k] = cb.m_closestHitFraction * max_range;
    }
  } else {
    // Candidates: every other drone and obstacle (kBruteForce), or those whose
    // broadphase proxy lies near the sensor range (kCulled). Rays then test
    // only candidates whose exact AABB they cross: a skipped ray or object
    // could not have been hit, so both modes give identical ranges.
    thread_local std::vector<const btCollisionObject*> objects;
    thread_local std::vector<RayTarget> targets;
    objects.clear();
    targets.clear();
    if (ray_mode_ == RayCastMode::kBruteForce) {
      for (const auto& s : statics_)
        if (kind_of(s.get()) != ContactKind::kGround) objects.push_back(s.get());
      for (const auto& d : drones_)
        if (d.body.get() != self) objects.push_back(d.body.get());
    } else {
      GatherProxies gather(self, objects);
      const btVector3 reach = to_bt(Eigen::Vector3d::Constant(max_range + kQuerySlackM));
      broadphase_->aabbTest(body_t.getOrigin() - reach, body_t.getOrigin() + reach, gather);
    }
    const Eigen::Vector3d reach = Eigen::Vector3d::Constant(max_range);
    for (const btCollisionObject* o : objects) {
      RayTarget t;
      ray_target(o, t);
      if (ray_mode_ == RayCastMode::kBruteForce ||
          overlaps(t.aabb_min, t.aabb_max, origin - reach, origin + reach))
        targets.push_back(t);
    }
    const bool ground_near = origin.z() - max_range <= ground_z_m_ + kAabbPadM;
    if (!targets.empty() || ground_near || ray_mode_ == RayCastMode::kBruteForce) {
      for (int k = 0; k < n; ++k) {
        double best = kInf;
        if (ground_near || ray_mode_ == RayCastMode::kBruteForce)
          best = ray_ground(origin, dir[k], ground_z_m_, max_range);
        for (const RayTarget& t : targets)
          if (ray_mode_ == RayCastMode::kBruteForce ||
              ray_hits_aabb(origin, dir[k], t.aabb_min, t.aabb_max, std::min(best, max_range)))
            best = std::min(best, ray_distance(t, origin, dir[k], max_range));
        dist[k] = best;
      }
    }
  }

  std::normal_distribution<double> noise(0.0, cfg.noise_sigma_m);
  for (int k = 0; k < n; ++k) {
    if (!(dist[k] <= max_range)) continue;
    double r = dist[k];
    if (cfg.noise_sigma_m > 0) r += noise(rng);
    range_m[k] = static_cast<float>(std::clamp(r, cfg.min_range_m, max_range));
    hit[k] = 1;
  }
}

}  // namespace ddswarm::sim
