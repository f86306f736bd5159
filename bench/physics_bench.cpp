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
//   us_per_tick   BM_ServerTick: one 50 Hz control tick of a lockstep server's
//                 compute (physics_hz / 50 substeps of every drone's flight
//                 controller and step(), then 8 rays of 6 m per drone)
//   us_per_drone_step  BM_Weather: one control period of SwarmPhysics (the
//                 wind taken at every drone, then 5 steps of 4 ms: swarm_field's
//                 250 Hz) per drone and step, calm and plain, with wind
//                 (3 m/s, Dryden turbulence, gusts), with the aerodynamic
//                 terms (ground effect, downwash, rotor drag), or with all
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <random>
#include <vector>

#include "bench/hover_field.hpp"
#include "sim_server/swarm_physics.hpp"

namespace {

using ddswarm::bench::HoverField;
using namespace ddswarm::sim;
using Clock = std::chrono::steady_clock;

constexpr double kDt = 0.001;

void BM_PhysicsStep(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  HoverField field(n, kDt);
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
  HoverField field(n, kDt);
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

/// args: drones, physics rate (Hz). Sensors as config/thesis_course.yaml: 8
/// rays of 6 m, at the 50 Hz control rate.
void BM_ServerTick(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const double hz = static_cast<double>(state.range(1));
  HoverField field(n, 1.0 / hz);
  const ddswarm::bench::TickPlan plan = ddswarm::bench::TickPlan::at(hz);
  double hit_frac = 0, total_s = 0;
  for (auto _ : state) {
    const auto t0 = Clock::now();
    hit_frac = field.server_tick(plan);
    total_s += std::chrono::duration<double>(Clock::now() - t0).count();
  }
  state.counters["us_per_tick"] = total_s * 1e6 / static_cast<double>(state.iterations());
  state.counters["hit_frac"] = hit_frac;
}
BENCHMARK(BM_ServerTick)
    ->ArgNames({"drones", "physics_hz"})
    ->ArgsProduct({{6, 16, 32, 64, 128}, {1000, 500, 250}})
    ->Unit(benchmark::kMicrosecond);

/// args: drones, effects (0 none, 1 wind, 2 aero, 3 both). swarm_field's
/// start: a lattice 2.5 m apart, hovering at 5 to 5.6 m, so downwash acts.
void BM_Weather(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const int effects = static_cast<int>(state.range(1));
  WindConfig wind;
  if (effects & 1) {
    wind.steady_mps = {3, 0, 0};
    wind.turbulence = true;
    wind.gusts_per_minute = 2;
  }
  AeroConfig aero;
  aero.ground_effect = aero.downwash = aero.rotor_drag = (effects & 2) != 0;
  const int side = static_cast<int>(std::ceil(std::sqrt(n)));
  std::vector<Eigen::Vector3d> starts;
  for (int i = 0; i < n; ++i)
    starts.emplace_back(2.5 * (i % side), 2.5 * (i / side), 5.0 + 0.3 * (i % 3));
  SwarmPhysics swarm(ddswarm::SceneConfig{}, QuadrotorParams{}, ControllerConfig{}, starts, 1, wind,
                     aero);
  VelocitySetpoint hold;
  hold.motors_on = true;
  const std::vector<VelocitySetpoint> setpoints(n, hold);
  constexpr int kSubsteps = 5;
  double total_s = 0;
  for (auto _ : state) {
    const auto t0 = Clock::now();
    benchmark::DoNotOptimize(swarm.step(setpoints, kSubsteps, 0.004));
    total_s += std::chrono::duration<double>(Clock::now() - t0).count();
  }
  state.counters["us_per_drone_step"] =
      total_s * 1e6 / (static_cast<double>(state.iterations()) * n * kSubsteps);
}
BENCHMARK(BM_Weather)
    ->ArgNames({"drones", "effects"})
    ->ArgsProduct({{64, 512, 1024}, {0, 1, 2, 3}})
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
