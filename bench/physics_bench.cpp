// Cost of the simulation server's physics: one fixed step for N hovering
// drones, and one sensor frame (8 rays per drone), in a thesis-like field of
// pillars (staggered rows, radius 1 m, 8 m apart, 12 m tall).
//
// Only step() / cast_rays() are timed (manual time); the flight controllers
// that keep the drones hovering run between timed sections. Counters:
//   us_per_step   wall time of one PhysicsWorld::step()
//   us_per_drone  us_per_step / N
//   rt_1khz       real-time factor at 1 kHz physics (1000 us / us_per_step)
//   us_per_frame  one cast_rays() for every drone
//   rays_per_s    rays cast per second of wall time
//   hit_frac      share of rays that hit something
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "common/scene.hpp"
#include "sim_server/flight_controller.hpp"
#include "sim_server/physics_world.hpp"

namespace {

using ddswarm::Cylinder;
using ddswarm::SceneConfig;
using namespace ddswarm::sim;
using Clock = std::chrono::steady_clock;

constexpr double kDt = 0.001;

/// N drones hovering at 2 m in a 2 m grid laid over a staggered pillar field.
class HoverField {
 public:
  explicit HoverField(int n) : world_(make_scene(n), QuadrotorParams{}, grid(n), 0.0) {
    fc_.reserve(n);
    for (int i = 0; i < n; ++i) {
      fc_.emplace_back(QuadrotorParams{}, ControllerConfig{});
      const Eigen::Vector3d p = world_.state(i).p_world;
      world_.reset_drone(i, {p.x(), p.y(), 2.0}, 0.0);
    }
    sp_.motors_on = true;
    for (int k = 0; k < 300; ++k) control_and_step();  // spin up and settle
  }

  void control() {
    for (int i = 0; i < world_.size(); ++i)
      world_.set_rotor_commands(i, fc_[i].update(world_.state(i), sp_, kDt));
  }
  void control_and_step() {
    control();
    world_.step(kDt);
  }
  PhysicsWorld& world() { return world_; }

 private:
  static double pillar_clearance(double x, double y) {
    double best = 1e9;
    for (int row = -20; row <= 20; ++row)
      for (int col = -20; col <= 20; ++col) {
        const double px = col * 8.0 + (row % 2 ? 4.0 : 0.0), py = row * 8.0;
        best = std::min(best, std::hypot(x - px, y - py));
      }
    return best;
  }
  /// Grid side (points) that leaves room for n drones between the pillars.
  static int side_for(int n) { return static_cast<int>(std::ceil(std::sqrt(n * 1.4))) + 2; }
  /// Points of a 2 m grid, row by row, at least 2 m from every pillar axis.
  static std::vector<Eigen::Vector3d> grid(int n) {
    std::vector<Eigen::Vector3d> out;
    const int side = side_for(n);
    for (int j = 0; j < side && static_cast<int>(out.size()) < n; ++j)
      for (int i = 0; i < side && static_cast<int>(out.size()) < n; ++i) {
        const double x = (i - side / 2) * 2.0 + 1.0, y = (j - side / 2) * 2.0 + 1.0;
        if (pillar_clearance(x, y) >= 2.0) out.emplace_back(x, y, 0.0);
      }
    if (static_cast<int>(out.size()) < n) throw std::logic_error("bench grid too small");
    return out;
  }
  static SceneConfig make_scene(int n) {
    SceneConfig s;
    const double half = side_for(n) + 8.0;  // grid half-width (m) + a row
    for (int row = -20; row <= 20; ++row)
      for (int col = -20; col <= 20; ++col) {
        const double px = col * 8.0 + (row % 2 ? 4.0 : 0.0), py = row * 8.0;
        if (std::abs(px) <= half && std::abs(py) <= half)
          s.cylinders.push_back(Cylinder{{px, py}, 1.0, 12.0});
      }
    return s;
  }

  PhysicsWorld world_;
  std::vector<FlightController> fc_;
  VelocitySetpoint sp_;
};

void BM_PhysicsStep(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  HoverField field(n);
  double total_s = 0;
  for (auto _ : state) {
    field.control();
    const auto t0 = Clock::now();
    field.world().step(kDt);
    const double s = std::chrono::duration<double>(Clock::now() - t0).count();
    state.SetIterationTime(s);
    total_s += s;
  }
  const double us = total_s * 1e6 / static_cast<double>(state.iterations());
  state.counters["us_per_step"] = us;
  state.counters["us_per_drone"] = us / n;
  state.counters["rt_1khz"] = 1000.0 / us;
  state.counters["contact_events"] =
      static_cast<double>(field.world().take_contact_events().size());
}
BENCHMARK(BM_PhysicsStep)
    ->Arg(1)
    ->Arg(6)
    ->Arg(16)
    ->Arg(64)
    ->Arg(128)
    ->Arg(512)
    ->Arg(1024)
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

/// args: drones, max range (m), mode (0 culled, 1 Bullet rayTest per ray).
void BM_RayFrame(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  HoverField field(n);
  SensorConfig cfg;
  cfg.count = 8;
  cfg.max_range_m = static_cast<double>(state.range(1));
  field.world().set_ray_cast_mode(state.range(2) == 0 ? RayCastMode::kCulled
                                                      : RayCastMode::kWorldRayTest);
  std::mt19937_64 rng(1);
  std::vector<float> range;
  std::vector<std::uint8_t> hit;
  double total_s = 0;
  long hits = 0, rays = 0;
  for (auto _ : state) {
    field.control_and_step();  // the swarm moves on between frames (untimed)
    const auto t0 = Clock::now();
    for (int d = 0; d < n; ++d) {
      field.world().cast_rays(d, cfg, rng, range, hit);
      for (auto h : hit) hits += h;
    }
    const double s = std::chrono::duration<double>(Clock::now() - t0).count();
    state.SetIterationTime(s);
    total_s += s;
    rays += static_cast<long>(n) * cfg.count;
  }
  const double us = total_s * 1e6 / static_cast<double>(state.iterations());
  state.counters["us_per_frame"] = us;
  state.counters["us_per_drone"] = us / n;
  state.counters["rays_per_s"] = static_cast<double>(rays) / total_s;
  state.counters["hit_frac"] = rays ? static_cast<double>(hits) / static_cast<double>(rays) : 0.0;
}
BENCHMARK(BM_RayFrame)
    ->ArgNames({"drones", "range_m", "bullet_raytest"})
    ->ArgsProduct({{6, 64, 512}, {4, 6}, {0, 1}})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

/// One flight-controller update (the server runs one per drone per step).
void BM_Controller(benchmark::State& state) {
  FlightController fc(QuadrotorParams{}, ControllerConfig{});
  RigidState s;
  s.p_world = {0, 0, 2};
  VelocitySetpoint sp;
  sp.motors_on = true;
  sp.v_world = {1, 0.5, 0};
  sp.yaw_rate_rad_s = 0.3;
  for (auto _ : state) {
    benchmark::DoNotOptimize(fc.update(s, sp, kDt));
    s.v_world.x() += 1e-6;
  }
}
BENCHMARK(BM_Controller);

}  // namespace

BENCHMARK_MAIN();
