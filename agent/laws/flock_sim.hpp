#pragma once
// A small kinematic world for testing swarm laws alone, without physics or
// DDS: point drones in a plane at one altitude whose velocity follows the
// law's command with a first-order lag (as the flight controller's
// velocity loop does, roughly), seeing every peer exactly and, when given
// pillars, a ring of distance rays against them. Deterministic.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

#include "ddswarm/law.hpp"

namespace ddswarm::agent::laws {

struct Pillar {
  Eigen::Vector2d c{0, 0};
  double radius_m = 0.5;
};

class FlockSim {
 public:
  double dt_s = 0.02;          ///< s, control period
  double response_s = 0.3;     ///< s, velocity-loop time constant
  double max_speed_mps = 3.0;  ///< m/s, command limit (the framework's)
  double z_m = 2.0;            ///< m, every drone's altitude
  int rays = 0;                ///< rays in the ring, 0 = no sensors
  double ray_range_m = 10.0;   ///< m, sensor range
  std::vector<Pillar> pillars;
  Eigen::Vector3d mission_velocity{0, 0, 0};  ///< m/s
  Eigen::Vector3d goal{NAN, NAN, NAN};
  law::Phase phase = law::Phase::kHold;
  double inter_distance_m = 4.0;

  struct Drone {
    Eigen::Vector3d p{0, 0, 0}, v{0, 0, 0};
    std::unique_ptr<law::SwarmLaw> law;
  };
  std::vector<Drone> drones;

  /// Adds a drone at (x, y) with velocity (vx, vy).
  void add(std::unique_ptr<law::SwarmLaw> l, double x, double y, double vx = 0, double vy = 0) {
    drones.push_back({Eigen::Vector3d(x, y, z_m), Eigen::Vector3d(vx, vy, 0), std::move(l)});
  }

  /// One control tick for every drone (commands from the same snapshot).
  void step() {
    std::vector<Eigen::Vector3d> cmd(drones.size());
    for (std::size_t i = 0; i < drones.size(); ++i) {
      peers_.clear();
      for (std::size_t j = 0; j < drones.size(); ++j)
        if (j != i) peers_.push_back({static_cast<int>(j), drones[j].p, drones[j].v, 0.0});
      scan(drones[i].p);
      law::Observation o;
      o.drone_id = static_cast<int>(i);
      o.tick = tick_;
      o.sim_time_s = static_cast<double>(tick_) * dt_s;
      o.dt_s = dt_s;
      o.p_world = drones[i].p;
      o.v_world = drones[i].v;
      o.peers = peers_;
      o.rays = rays_;
      o.phase = phase;
      o.mission_velocity = mission_velocity;
      o.goal_world = goal;
      o.inter_distance_m = inter_distance_m;
      o.altitude_target_m = z_m;
      o.max_speed_mps = max_speed_mps;
      Eigen::Vector3d v = drones[i].law->step(o).velocity_world;
      v.z() = 0;
      if (v.norm() > max_speed_mps) v *= max_speed_mps / v.norm();
      cmd[i] = v;
    }
    const double a = 1.0 - std::exp(-dt_s / response_s);
    for (std::size_t i = 0; i < drones.size(); ++i) {
      drones[i].v += a * (cmd[i] - drones[i].v);
      drones[i].p += drones[i].v * dt_s;
    }
    ++tick_;
    min_distance_seen_m = std::min(min_distance_seen_m, min_distance_m());
    for (const auto& d : drones)
      for (const auto& pl : pillars)
        min_clearance_seen_m =
            std::min(min_clearance_seen_m, (d.p.head<2>() - pl.c).norm() - pl.radius_m);
  }

  void run(double seconds) {
    const auto n = static_cast<long>(std::lround(seconds / dt_s));
    for (long k = 0; k < n; ++k) step();
  }

  /// Smallest distance between two drones now (m).
  double min_distance_m() const {
    double m = HUGE_VAL;
    for (std::size_t i = 0; i < drones.size(); ++i)
      for (std::size_t j = i + 1; j < drones.size(); ++j)
        m = std::min(m, (drones[i].p - drones[j].p).norm());
    return m;
  }

  /// Mean over ordered pairs of cos(angle between velocities): 1 = aligned
  /// (Vásárhelyi et al. 2018's velocity correlation). Pairs with a zero
  /// velocity count 0.
  double order() const {
    double sum = 0;
    std::size_t n = 0;
    for (std::size_t i = 0; i < drones.size(); ++i)
      for (std::size_t j = 0; j < drones.size(); ++j) {
        if (i == j) continue;
        const double a = drones[i].v.norm(), b = drones[j].v.norm();
        sum += a > 1e-9 && b > 1e-9 ? drones[i].v.dot(drones[j].v) / (a * b) : 0.0;
        ++n;
      }
    return n ? sum / static_cast<double>(n) : 1.0;
  }

  Eigen::Vector3d mean_velocity() const {
    Eigen::Vector3d m = Eigen::Vector3d::Zero();
    for (const auto& d : drones) m += d.v;
    return drones.empty() ? m : Eigen::Vector3d(m / static_cast<double>(drones.size()));
  }

  double min_distance_seen_m = HUGE_VAL;
  double min_clearance_seen_m = HUGE_VAL;  ///< m, drone centre to pillar surface

 private:
  /// The ring of rays from p against the pillars (body = world: no yaw).
  void scan(const Eigen::Vector3d& p) {
    rays_.clear();
    for (int k = 0; k < rays; ++k) {
      const double yaw = 2.0 * std::numbers::pi * k / rays;
      const Eigen::Vector2d d(std::cos(yaw), std::sin(yaw));
      double best = HUGE_VAL;
      for (const auto& pl : pillars) {
        // |p + t d - c| = r, smallest t >= 0
        const Eigen::Vector2d f = p.head<2>() - pl.c;
        const double b = f.dot(d), c = f.squaredNorm() - pl.radius_m * pl.radius_m;
        const double disc = b * b - c;
        if (disc < 0) continue;
        double t = -b - std::sqrt(disc);
        if (t < 0) t = -b + std::sqrt(disc);
        if (t >= 0) best = std::min(best, t);
      }
      law::Ray r;
      r.yaw_body_rad = yaw;
      r.hit = best <= ray_range_m;
      r.range_m = r.hit ? best : ray_range_m;
      rays_.push_back(r);
    }
  }

  std::uint64_t tick_ = 0;
  std::vector<law::Peer> peers_;
  std::vector<law::Ray> rays_;
};

}  // namespace ddswarm::agent::laws
