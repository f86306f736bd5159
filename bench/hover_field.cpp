#include "bench/hover_field.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace ddswarm::bench {
namespace {

double pillar_clearance(double x, double y) {
  double best = 1e9;
  for (int row = -20; row <= 20; ++row)
    for (int col = -20; col <= 20; ++col) {
      const double px = col * 8.0 + (row % 2 ? 4.0 : 0.0), py = row * 8.0;
      best = std::min(best, std::hypot(x - px, y - py));
    }
  return best;
}
/// Grid side (points) that leaves room for n drones between the pillars.
int side_for(int n) { return static_cast<int>(std::ceil(std::sqrt(n * 1.4))) + 2; }
/// Points of a 2 m grid, row by row, at least 2 m from every pillar axis.
std::vector<Eigen::Vector3d> grid(int n) {
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
SceneConfig make_scene(int n) {
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

}  // namespace

HoverField::HoverField(int n, double dt)
    : HoverField(make_scene(n), sim::QuadrotorParams{}, sim::ControllerConfig{}, grid(n), dt) {}

HoverField::HoverField(const SceneConfig& scene, const sim::QuadrotorParams& q,
                       const sim::ControllerConfig& c, const std::vector<Eigen::Vector3d>& starts,
                       double dt)
    : dt_(dt), world_(scene, q, starts, 0.0) {
  fc_.reserve(starts.size());
  for (int i = 0; i < world_.size(); ++i) {
    fc_.emplace_back(q, c);
    const Eigen::Vector3d p = world_.state(i).p_world;
    world_.reset_drone(i, {p.x(), p.y(), starts[i].z() + 2.0}, 0.0);
  }
  sp_.motors_on = true;
  const int settle = static_cast<int>(0.3 / dt + 0.5);  // spin up and settle: 0.3 s
  for (int k = 0; k < settle; ++k) control_and_step();
}

void HoverField::control() {
  for (int i = 0; i < world_.size(); ++i)
    world_.set_rotor_commands(i, fc_[i].update(world_.state(i), sp_, dt_));
}

void HoverField::control_and_step() {
  control();
  world_.step(dt_);
}

TickPlan TickPlan::at(double physics_hz, double control_hz) {
  TickPlan p;
  p.substeps = static_cast<int>(std::lround(physics_hz / control_hz));
  p.sensors.count = 8;
  p.sensors.max_range_m = 6.0;
  return p;
}

double HoverField::server_tick(const TickPlan& plan, std::uint64_t tick) {
  for (int k = 0; k < plan.substeps; ++k) control_and_step();
  if (tick % static_cast<std::uint64_t>(plan.sensor_every) != 0) return 0.0;
  const sim::SensorConfig& sensors = plan.sensors;
  long hits = 0, cast = 0;
  for (int d = 0; d < world_.size(); ++d) {
    world_.cast_rays(d, sensors, rng_, range_, hit_);
    for (auto h : hit_) hits += h;
    cast += static_cast<long>(hit_.size());
  }
  return cast ? static_cast<double>(hits) / static_cast<double>(cast) : 0.0;
}

}  // namespace ddswarm::bench
