#pragma once
// One tick's swarm state as the benches decode and encode it: n drones
// hovering near 2 m in a 100 m square, each with a scan of `rays` rays.
#include <cmath>
#include <random>

#include "SwarmState.h"

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
    msg::Vec3 p;
    p.x(u(rng));
    p.y(u(rng));
    p.z(2 + u(rng) / 50);
    d.position(p);
    msg::Quat q;
    q.w(0.99875);
    q.x(0.0499792);
    d.orientation(q);
    msg::Vec3 v;
    v.x(0.8123);
    v.y(-0.0421);
    d.velocity(v);
    d.motor_speed_rad_s({612.3f, 611.9f, 613.0f, 612.7f});
    d.flags(1 | 4 | 32);
    d.phase(4);
    s.drones().push_back(d);
    msg::DistanceScan sc;
    sc.drone_id(i);
    for (int k = 0; k < rays; ++k) {
      sc.angle_body_rad().push_back(static_cast<float>(k * 2 * M_PI / rays));
      sc.range_m().push_back(static_cast<float>(3 + k % 5));
      sc.hit().push_back(k % 2);
    }
    s.scans().push_back(sc);
  }
  return s;
}

}  // namespace ddswarm
