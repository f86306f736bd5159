#pragma once
// One tick's swarm state as the benches decode and encode it: n drones
// hovering near 2 m in a 100 m square, each with a scan of `rays` rays.
#include <cmath>
#include <random>

#include "SwarmState.h"
#include "common/convert.hpp"

namespace ddswarm {

inline msg::SwarmState bench_swarm(int n, int rays) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-50, 50);
  msg::SwarmState s;
  s.tick(123456);
  s.sim_time_s(2469.12);
  for (int i = 0; i < n; ++i) {
    msg::DroneState d;
    d.drone_id(i);
    const double x = u(rng), y = u(rng), z = 2 + u(rng) / 50;  // in this order
    d.position(to_msg(Eigen::Vector3d(x, y, z)));
    d.orientation(to_msg(Eigen::Quaterniond(0.99875, 0.0499792, 0, 0)));
    d.velocity(to_msg(Eigen::Vector3d(0.8123, -0.0421, 0)));
    d.motor_speed_rad_s({612.3f, 611.9f, 613.0f, 612.7f});
    d.flags(1 | 4 | 32);
    d.phase(4);
    s.drones().push_back(d);
    msg::DistanceScan sc;
    sc.drone_id(i);
    for (int k = 0; k < rays; ++k) {
      sc.angle_body_rad().push_back(static_cast<float>(k * 2 * M_PI / rays));
      sc.elevation_body_rad().push_back(0.0f);
      sc.range_m().push_back(static_cast<float>(3 + k % 5));
      sc.hit().push_back(k % 2);
    }
    s.scans().push_back(sc);
  }
  return s;
}

}  // namespace ddswarm
