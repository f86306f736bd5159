#include "agent/swarm_law.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace ddswarm::agent {
namespace {

constexpr double kTiny = 1e-9;

/// Linear interpolation through points (x increasing), held flat beyond the ends.
double interpolate(const std::vector<Eigen::Vector2d>& pts, double x) {
  if (x <= pts.front().x()) return pts.front().y();
  if (x >= pts.back().x()) return pts.back().y();
  auto hi = std::upper_bound(pts.begin(), pts.end(), x,
                             [](double v, const Eigen::Vector2d& p) { return v < p.x(); });
  auto lo = hi - 1;
  const double t = (x - lo->x()) / (hi->x() - lo->x());
  return lo->y() + t * (hi->y() - lo->y());
}

/// Scales v down so that its norm is at most limit (direction kept).
template <class V>
void limit_norm(V&& v, double limit) {
  const double n = v.norm();
  if (n > limit && n > 0) v *= limit / n;
}

}  // namespace

double f_rel(double d_r, const ActivationConfig& a) {
  if (std::isnan(d_r)) return d_r;
  double f = 0.0;
  if (a.type == ActivationType::kCustom && !a.points.empty()) {
    f = interpolate(a.points, d_r);
  } else {
    f = d_r >= 0 ? a.attraction_gain * d_r : a.repulsion_gain * d_r;
  }
  return std::clamp(f, -a.max_mps, a.max_mps);
}

Eigen::Vector3d repulsion_attraction(const Eigen::Vector3d& self,
                                     std::span<const Eigen::Vector3d> peers, double d_int,
                                     const ActivationConfig& a) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  auto acts = [&](double dist) { return dist > kTiny && !(a.cutoff_m > 0 && dist > a.cutoff_m); };
  auto term = [&](const Eigen::Vector3d& p, double dist) -> Eigen::Vector3d {
    return f_rel(dist - d_int, a) * ((p - self) / dist);
  };
  const auto k = static_cast<std::size_t>(std::max(a.neighbours, 0));
  if (k == 0 || peers.size() <= k) {
    for (const auto& p : peers)
      if (const double dist = (p - self).norm(); acts(dist)) c += term(p, dist);
    return c;
  }
  // The k nearest by (squared distance, index), kept in a sorted list of at
  // most k while the peers are scanned: a peer farther than the k-th kept one
  // is passed over on its squared distance alone, without a square root. At
  // 512 drones and k = 6 this scan replaced a partial sort of every peer,
  // which was the agent host's largest cost (docs/performance.md).
  // Ties go to the lower index, and the terms are summed nearest first, so
  // the result depends on the input alone.
  struct Near {
    double d2, dist;
    std::size_t j;
  };
  thread_local std::vector<Near> near;
  near.clear();
  for (std::size_t j = 0; j < peers.size(); ++j) {
    const double d2 = (peers[j] - self).squaredNorm();
    // A later peer at an equal squared distance never displaces a kept one.
    if (near.size() == k && !(d2 < near.back().d2)) continue;
    const double dist = std::sqrt(d2);  // what .norm() gives, bit for bit
    if (!acts(dist)) continue;
    if (near.size() == k) near.pop_back();
    auto at = std::upper_bound(near.begin(), near.end(), d2,
                               [](double v, const Near& n) { return v < n.d2; });
    near.insert(at, Near{d2, dist, j});
  }
  for (const Near& n : near) c += term(peers[n.j], n.dist);
  return c;
}

double sensor_range_m(const SensorFunctionConfig& s) {
  switch (s.type) {
    case SensorFunctionType::kFs1:
      return kFs1RangeM;
    case SensorFunctionType::kFs2:
      return kFs2RangeM;
    case SensorFunctionType::kLog:
      return kLogRangeM;
    case SensorFunctionType::kCustom:
      return s.points.empty() ? 0.0 : s.points.back().x();
  }
  return 0.0;
}

double sensor_activation(double range_m, bool hit, const SensorFunctionConfig& s) {
  if (!hit || std::isnan(range_m)) return 0.0;
  const double r = std::max(range_m, 0.0);
  const double range = sensor_range_m(s);
  if (r >= range) return 0.0;
  switch (s.type) {
    case SensorFunctionType::kFs1:
    case SensorFunctionType::kFs2:
      if (r <= kSensorPlateauM) return s.max_mps;
      return s.max_mps * (range - r) / (range - kSensorPlateauM);
    case SensorFunctionType::kLog:
      if (r <= 0.0) return s.max_mps;
      return std::min(s.max_mps, s.log_gain_mps * std::log(range / r));
    case SensorFunctionType::kCustom:
      return std::max(0.0, interpolate(s.points, r));
  }
  return 0.0;
}

Eigen::Vector3d ray_direction_world(double ray_yaw_body_rad, const Eigen::Quaterniond& q_world_body,
                                    double ray_elevation_body_rad) {
  const Eigen::Vector3d body(std::cos(ray_yaw_body_rad), std::sin(ray_yaw_body_rad), 0.0);
  Eigen::Vector3d w = q_world_body * body;
  w.z() = 0.0;
  const double n = w.norm();
  const Eigen::Vector3d h = n > kTiny ? Eigen::Vector3d(w / n) : Eigen::Vector3d::Zero();
  if (ray_elevation_body_rad == 0.0) return h;
  const double ce = std::cos(ray_elevation_body_rad);
  return {ce * h.x(), ce * h.y(), std::sin(ray_elevation_body_rad)};
}

double ray_weight(std::span<const float> ray_elevation_body_rad) {
  if (ray_elevation_body_rad.empty()) return 1.0;
  std::size_t columns = 0;
  for (const float e : ray_elevation_body_rad) columns += e == ray_elevation_body_rad[0];
  // columns >= 1 unless ray 0's elevation is NaN; then every ray counts fully.
  return columns == 0
             ? 1.0
             : static_cast<double>(columns) / static_cast<double>(ray_elevation_body_rad.size());
}

Eigen::Vector3d obstacle_avoidance(std::span<const float> range_m,
                                   std::span<const std::uint8_t> hit,
                                   std::span<const float> ray_yaw_body_rad,
                                   std::span<const float> ray_elevation_body_rad,
                                   const Eigen::Quaterniond& q_world_body,
                                   const SensorFunctionConfig& s) {
  if (range_m.size() != hit.size() || range_m.size() != ray_yaw_body_rad.size() ||
      (!ray_elevation_body_rad.empty() && ray_elevation_body_rad.size() != range_m.size()))
    throw std::invalid_argument(
        "obstacle_avoidance: ray spans differ in size (range " + std::to_string(range_m.size()) +
        ", hit " + std::to_string(hit.size()) + ", yaw " + std::to_string(ray_yaw_body_rad.size()) +
        ", elevation " + std::to_string(ray_elevation_body_rad.size()) + ")");
  const double w = ray_weight(ray_elevation_body_rad);
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < range_m.size(); ++k) {
    const double f = sensor_activation(range_m[k], hit[k] != 0, s);
    if (f > 0)
      c -= w * f *
           ray_direction_world(ray_yaw_body_rad[k], q_world_body,
                               ray_elevation_body_rad.empty() ? 0.0 : ray_elevation_body_rad[k]);
  }
  return c;
}

LawTerms evaluate_law(const LawInput& in, const AgentConfig& c) {
  Eigen::Vector3d swarm = Eigen::Vector3d::Zero();
  if (in.swarm_enabled)
    swarm = repulsion_attraction(in.p_world, in.peers_world, in.inter_distance_m, c.activation);
  if (in.swarm_horizontal_only) swarm.z() = 0;
  return frame_law(in, swarm, swarm + in.mission_velocity, true, c);
}

LawTerms frame_law(const LawInput& in, const Eigen::Vector3d& swarm, Eigen::Vector3d other,
                   bool obstacle_term, const AgentConfig& c) {
  LawTerms t;
  t.swarm = swarm;
  if (in.obstacle_avoidance_enabled && obstacle_term) {
    t.obstacle = obstacle_avoidance(in.ray_range_m, in.ray_hit, in.ray_yaw_body_rad,
                                    in.ray_elevation_body_rad, in.q_world_body, c.sensor_function);
    auto direction = [&](std::size_t k) {
      return ray_direction_world(
          in.ray_yaw_body_rad[k], in.q_world_body,
          in.ray_elevation_body_rad.empty() ? 0.0 : in.ray_elevation_body_rad[k]);
    };
    const double safety = c.sensor_function.safety_distance_m;
    if (safety > 0) {
      Eigen::Vector3d away = Eigen::Vector3d::Zero();
      for (std::size_t k = 0; k < in.ray_range_m.size(); ++k) {
        const float r = in.ray_range_m[k];
        if (in.ray_hit[k] == 0 || std::isnan(r) || r >= safety) continue;
        t.safety_active = true;
        away -= direction(k);
      }
      if (t.safety_active) {
        // Hits on opposite sides cancel; then fall back on the graded reaction.
        if (away.norm() < 1e-6) away = t.obstacle;
        if (away.norm() >= 1e-6) {
          const Eigen::Vector3d u = away.normalized();
          const double toward = other.dot(u);
          if (toward < 0) other -= toward * u;
          t.obstacle = c.max_speed_mps * u;
        } else {
          // Squeezed between opposite hits: no way out, so at least stop closing in.
          for (std::size_t k = 0; k < in.ray_range_m.size(); ++k) {
            const float r = in.ray_range_m[k];
            if (in.ray_hit[k] == 0 || std::isnan(r) || r >= safety) continue;
            const Eigen::Vector3d d = direction(k);
            const double toward = other.dot(d);
            if (toward > 0) other -= toward * d;
          }
        }
      }
    }
  }

  if (in.obstacle_avoidance_enabled && obstacle_term && !t.safety_active &&
      c.sensor_function.slide_gain > 0) {
    Eigen::Vector2d n = t.obstacle.head<2>();
    const Eigen::Vector2d r = other.head<2>();
    const double n_norm = n.norm();
    if (n_norm > 1e-6) {
      n /= n_norm;
      const double into = -r.dot(n);  // how hard the other terms push toward the obstacle
      if (into > 0) {
        Eigen::Vector2d tangent(-n.y(), n.x());
        const double side = r.dot(tangent);
        if (side < -1e-3 * r.norm()) tangent = -tangent;
        t.slide.head<2>() = c.sensor_function.slide_gain * into * tangent;
      }
    }
  }

  Eigen::Vector3d v = t.obstacle + other + t.slide;
  if (in.altitude_hold) {
    const double correction = std::clamp(c.altitude_gain * (in.altitude_target_m - in.p_world.z()),
                                         -c.landing_speed_mps, c.takeoff_speed_mps);
    v.z() = in.mission_velocity.z() + correction;
  }
  limit_norm(v.head<2>(), c.max_speed_mps);
  limit_norm(v, c.max_speed_mps);
  t.velocity = v;
  return t;
}

Eigen::Vector3d control_velocity(const LawInput& in, const AgentConfig& c) {
  return evaluate_law(in, c).velocity;
}

bool swarm_condition(std::span<const Eigen::Vector3d> positions, double epsilon_m) {
  for (std::size_t i = 0; i < positions.size(); ++i)
    for (std::size_t j = i + 1; j < positions.size(); ++j)
      if (!((positions[i] - positions[j]).norm() < epsilon_m)) return false;
  return true;
}

}  // namespace ddswarm::agent
