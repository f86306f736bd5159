#pragma once
// The simulated world: every drone, the ground and the obstacles, stepped by
// Bullet. This is the one class that touches Bullet; the rest of the server
// sees Eigen states, rotor commands, contact events and ray ranges.
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include "common/scene.hpp"
#include "sim_server/aero.hpp"
#include "sim_server/quadrotor.hpp"

class btDefaultCollisionConfiguration;
class btCollisionDispatcher;
struct btDbvtBroadphase;  // Bullet declares it a struct (clang: -Wmismatched-tags)
class btSequentialImpulseConstraintSolver;
class btDiscreteDynamicsWorld;
class btCollisionObject;
class btCollisionShape;
class btRigidBody;
class btTriangleMesh;
class btBvhTriangleMeshShape;

namespace ddswarm::sim {

enum class ContactKind : std::uint8_t { kObstacle, kDrone, kGround };

/// A contact that began during a step.
struct ContactEvent {
  int drone = 0;  ///< drone id (for drone-drone contacts, the lower id)
  ContactKind kind = ContactKind::kGround;
  /// kDrone: the other (higher) drone id; kObstacle: obstacle index, scene
  /// cylinders first, then boxes (cylinders.size() + box index), then meshes
  /// (cylinders.size() + boxes.size() + mesh index); kGround: -1.
  int other = -1;
  Eigen::Vector3d where_world{0, 0, 0};  ///< m, a contact point, ENU
};

/// How cast_rays finds what a ray hits. kCulled and kBruteForce intersect
/// rays analytically with the exact shapes (ground plane, cylinders, boxes,
/// drone cylinders at full attitude; a mesh's triangles through its Bullet
/// bounding-volume tree, both faces) and give identical ranges; kCulled asks
/// Bullet's broadphase for what lies within range first and tests a ray only
/// against objects whose bounding box it crosses.
enum class RayCastMode : std::uint8_t {
  kCulled,        ///< broadphase query, then per-ray AABB tests (default)
  kBruteForce,    ///< every ray against every object (slow reference)
  kWorldRayTest,  ///< Bullet's btCollisionWorld::rayTest (GJK ray cast) per ray, for
                  ///< comparison only: ~10x slower, approximate on a drone's thin
                  ///< disc at shallow incidence (most ranges agree to 5 mm)
};

/// How the world calls Bullet. kShortcuts (default) skips the work that can
/// have no result for our bodies: the drone-ground test for a drone clear of
/// the ground, the continuous-collision pass (no body uses CCD), unit damping
/// and static bodies' AABB updates; a step costs 25-45 % less. kStock runs
/// Bullet's pipeline as shipped: the reference that unit tests compare with,
/// state for state, to the last bit.
enum class BulletPath : std::uint8_t { kShortcuts, kStock };

class PhysicsWorld {
 public:
  /// Builds the ground plane at scene.ground_z_m, the scene's cylinders,
  /// boxes and meshes (static triangle meshes, btBvhTriangleMeshShape, of
  /// each mesh's world triangles; a mesh without them, as from the wire, is
  /// left out), and one drone per start position, resting on the ground: the
  /// bottom of its collision cylinder at start_positions[i] (whose z is
  /// normally the ground height), level, heading start_yaw_rad. Contacts that
  /// exist at construction (drones resting on the ground) are not reported.
  /// Throws std::invalid_argument for 2^20 drones or more.
  PhysicsWorld(const SceneConfig& scene, const QuadrotorParams& q,
               const std::vector<Eigen::Vector3d>& start_positions, double start_yaw_rad,
               BulletPath path = BulletPath::kShortcuts);
  /// A swarm of several airframes: drone i flies airframes[airframe_of[i]]
  /// (airframe_of has one entry per start position, each indexing airframes).
  PhysicsWorld(const SceneConfig& scene, const std::vector<QuadrotorParams>& airframes,
               const std::vector<int>& airframe_of,
               const std::vector<Eigen::Vector3d>& start_positions, double start_yaw_rad,
               BulletPath path = BulletPath::kShortcuts);
  ~PhysicsWorld();
  PhysicsWorld(const PhysicsWorld&) = delete;
  PhysicsWorld& operator=(const PhysicsWorld&) = delete;

  /// Number of drones.
  int size() const { return static_cast<int>(drones_.size()); }

  /// Sets the rotor speed commands (rad/s, clamped to [omega_min, omega_max]);
  /// the first-order motor lag is applied inside step(). Held until changed.
  void set_rotor_commands(int drone, const std::array<double, 4>& omega_cmd_rad_s);

  /// The air's velocity at the drone (m/s, world ENU: the wind, sim/wind.hpp);
  /// body drag acts on the velocity relative to it. Held until changed; calm
  /// (zero) at start.
  void set_air_velocity(int drone, const Eigen::Vector3d& air_world) {
    drones_[drone].air_world = air_world;
  }
  /// Ground effect, downwash and rotor drag (sim/aero.hpp); off unless set.
  void set_aero(const AeroConfig& aero) { aero_ = aero; }

  /// Advances one fixed step of dt seconds: motor lag, rotor thrust k_f w^2 at
  /// the rotor hubs along body z, reaction torques -+k_m w^2 about body z,
  /// body drag, gravity, contacts. Then records the contacts that began.
  /// Does not allocate once the contact buffers have grown.
  void step(double dt);

  /// s, simulated time (sum of the dt passed to step()).
  double time_s() const { return time_s_; }

  RigidState state(int drone) const;
  /// rad/s, actual (lagged) rotor speeds.
  std::array<double, 4> rotor_speeds(int drone) const;

  /// Teleports a drone: bottom of its collision cylinder at p, level, heading
  /// yaw, at rest, rotors stopped (commands cleared). Its contacts end; the
  /// contacts it has at the new place (e.g. the ground) are not reported.
  void reset_drone(int drone, const Eigen::Vector3d& p, double yaw_rad);

  /// A pair is in contact while some contact point of theirs is within 5 mm;
  /// the contact ends once the pair has not touched for this long (s), so a
  /// bounce within a push is one contact, not several.
  static constexpr double kContactReleaseS = 0.5;

  /// Contact events since the last call, in step order: one per contact that
  /// begins. A pair in contact over many steps counts once; it counts again
  /// only after kContactReleaseS apart.
  std::vector<ContactEvent> take_contact_events();

  /// True while the drone touches the ground plane (as of the last step).
  bool touching_ground(int drone) const { return touching_ground_[drone] != 0; }

  /// Casts the drone's distance sensors from its body centre. Ray k points
  /// along cfg.ray_direction_body(k) (body yaw of its column, elevation of its
  /// row), turned with the full body attitude. A ray never hits its own drone; it
  /// hits other drones, obstacles and the ground. On return both vectors have
  /// cfg.rays() entries: hit[k] = 1 and range_m[k] = true distance + N(0,
  /// sigma) clamped to [min_range_m, max_range_m] when something is within
  /// max_range_m; otherwise hit[k] = 0 and range_m[k] = max_range_m. A ray
  /// starting inside an object measures 0 (then min_range_m). Noise is drawn
  /// from rng once per hit ray, in ray order. Concurrent calls are safe in the
  /// default mode (kCulled), never concurrently with step().
  void cast_rays(int drone, const SensorConfig& cfg, std::mt19937_64& rng,
                 std::vector<float>& range_m, std::vector<std::uint8_t>& hit) const;

  void set_ray_cast_mode(RayCastMode mode) { ray_mode_ = mode; }

  /// The first airframe (the only one unless several were given).
  const QuadrotorParams& params() const { return models_[0].p; }
  /// The airframe drone flies.
  const QuadrotorParams& params(int drone) const { return models_[drones_[drone].model].p; }

 private:
  /// One airframe: its parameters and what step() needs of them, cached.
  struct Model {
    QuadrotorParams p;
    double k_f, k_m, omega_min, omega_max;
    std::array<Eigen::Vector3d, 4> rotor_pos;
    std::unique_ptr<btCollisionShape> shape;  ///< shared by its drones
  };
  struct Drone {
    std::unique_ptr<btRigidBody> body;
    int model = 0;  ///< index into models_
    std::array<double, 4> omega_cmd{};
    std::array<double, 4> omega{};
    Eigen::Vector3d air_world{0, 0, 0};
  };
  /// A pair touching in this step's manifolds.
  struct PairContact {
    std::uint64_t key;
    Eigen::Vector3d where_world;
  };
  /// A pair in contact, and when it last touched.
  struct ContactState {
    std::uint64_t key;
    double last_touch_s;
  };

  std::vector<Eigen::Vector3d> downwash_p_;           ///< each drone's position this step
  std::vector<Eigen::Vector3d> downwash_built_p_;     ///< and when the candidates were found
  std::vector<std::pair<std::uint64_t, int>> cells_;  ///< (grid cell, drone), sorted
  std::vector<int> downwash_from_;                    ///< candidates, drone by drone
  std::vector<std::size_t> downwash_begin_;           ///< drone n's: [begin[n], begin[n + 1])

  /// Exact geometry of an obstacle, for ray casts.
  struct ObstacleShape {
    Eigen::Vector3d center;
    Eigen::Vector3d half;  ///< cylinder: (r, r, h/2); box: half sizes; mesh: half its bounds
    double cos_yaw, sin_yaw;
    bool box;
    btBvhTriangleMeshShape* mesh = nullptr;  ///< a mesh's triangles (world frame)
  };
  /// A drone or obstacle a ray may hit, with its exact AABB.
  struct RayTarget {
    bool drone;
    int index;               ///< drone id or obstacle index
    Eigen::Vector3d center;  ///< world
    Eigen::Matrix3d rot;     ///< drones: body -> world
    Eigen::Vector3d aabb_min, aabb_max;
  };

  /// Keeps downwash_from_: for each drone, the others within kDownwashReachM
  /// plus kDownwashSkinM of it sideways, in index order; rebuilt (on a grid,
  /// O(N k) for k drones near each) only once a drone has moved half the
  /// skin. Each step then checks these few; the forces, and the order they
  /// are summed in, are those of every pair.
  void update_downwash_candidates();
  static constexpr double kDownwashSkinM = 2.0;

  void ray_target(const btCollisionObject* o, RayTarget& t) const;
  double ray_distance(const RayTarget& t, const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                      double t_max) const;
  void add_static(std::unique_ptr<btCollisionShape> shape, const Eigen::Vector3d& origin,
                  double yaw_rad, ContactKind kind, int index);
  void place(btRigidBody& body, double half_height_m, const Eigen::Vector3d& bottom,
             double yaw_rad) const;
  void update_contacts(bool report);

  std::vector<Model> models_;
  double ground_z_m_;
  AeroConfig aero_;
  std::vector<double> lag_up_, lag_down_;  ///< scratch: per model, this step's motor lag

  // Bullet objects, in construction order (destroyed in reverse).
  std::unique_ptr<btDefaultCollisionConfiguration> collision_config_;
  std::unique_ptr<btCollisionDispatcher> dispatcher_;
  std::unique_ptr<btDbvtBroadphase> broadphase_;
  std::unique_ptr<btSequentialImpulseConstraintSolver> solver_;
  std::unique_ptr<btDiscreteDynamicsWorld> world_;
  std::vector<std::unique_ptr<btTriangleMesh>> triangle_meshes_;  ///< outlive their shapes
  std::vector<std::unique_ptr<btCollisionShape>>
      static_shapes_;                                  ///< ground, cylinders, boxes, meshes
  std::vector<std::unique_ptr<btRigidBody>> statics_;  ///< ground, then obstacles
  std::vector<Drone> drones_;
  std::vector<ObstacleShape> obstacle_shapes_;  ///< by obstacle index

  double time_s_ = 0.0;
  RayCastMode ray_mode_ = RayCastMode::kCulled;
  std::vector<PairContact> touching_;     ///< scratch: pairs touching this step
  std::vector<ContactState> in_contact_;  ///< pairs in contact, sorted by key
  std::vector<ContactState> in_contact_next_;
  std::vector<ContactEvent> events_;
  std::vector<std::uint8_t> touching_ground_;  ///< per drone, this step
  std::vector<std::uint8_t> quiet_;            ///< per drone: adopt contacts without events
};

}  // namespace ddswarm::sim
