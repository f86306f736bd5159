#include "common/scene.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

namespace ddswarm {

void load(YamlSection s, SceneConfig& c) {
  FieldLoader load(s);
  SceneConfig::fields(c, load);
  s.finish();
}

void SceneConfig::validate() const {
  FieldChecker check("scene");
  fields(*this, check);
  generate.validate();
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    std::string p = "scene.boxes[" + std::to_string(i) + "]";
    for (int k = 0; k < 3; ++k) check_positive(p + ".size", boxes[i].size[k]);
  }
  for (int k = 0; k < 3; ++k)
    if (!(bounds_max[k] > bounds_min[k]))
      throw FieldError("scene.bounds_max", to_text(bounds_max.transpose()),
                       "must exceed bounds_min on every axis");
  if (!(bounds_max.z() > ground_z_m))
    throw FieldError("scene.bounds_max", to_text(bounds_max.z()), "z must be above the ground");
  if ((finish_b - finish_a).norm() < 1e-6)
    throw FieldError("scene.finish_line.b", to_text(finish_b.transpose()), "must differ from a");
  if (start.spacing_m < 0.7)
    throw FieldError("scene.start.spacing_m", to_text(start.spacing_m),
                     "must be >= 0.7 (drones would overlap)");
  // The goal must lie strictly on one side of the finish line.
  Eigen::Vector2d d = finish_b - finish_a;
  Eigen::Vector2d g = goal_xy - finish_a;
  if (std::abs(d.x() * g.y() - d.y() * g.x()) < 1e-9)
    throw FieldError("scene.goal_xy", to_text(goal_xy.transpose()),
                     "must not lie on the finish line");
}

Eigen::Vector2d SceneConfig::task_direction() const {
  Eigen::Vector2d d = goal_xy - start.center_xy;
  double n = d.norm();
  return n > 1e-9 ? Eigen::Vector2d(d / n) : Eigen::Vector2d(0, 1);
}

bool SceneConfig::past_finish(const Eigen::Vector2d& p) const {
  Eigen::Vector2d d = finish_b - finish_a;
  auto side = [&](const Eigen::Vector2d& q) {
    Eigen::Vector2d r = q - finish_a;
    return d.x() * r.y() - d.y() * r.x();
  };
  return side(p) * side(goal_xy) > 0;
}

double SceneConfig::clearance(const Eigen::Vector3d& p) const {
  double best = std::numeric_limits<double>::infinity();
  for (const auto& c : cylinders) {
    if (p.z() > ground_z_m + c.height_m) continue;
    best = std::min(best, (p.head<2>() - c.center_xy).norm() - c.radius_m);
  }
  for (const auto& b : boxes) {
    Eigen::Vector3d local = p - b.center;
    Eigen::Rotation2Dd r(-b.yaw_rad);
    Eigen::Vector2d lxy = r * local.head<2>();
    Eigen::Vector3d q(std::abs(lxy.x()) - b.size.x() / 2, std::abs(lxy.y()) - b.size.y() / 2,
                      std::abs(local.z()) - b.size.z() / 2);
    double outside = q.cwiseMax(0.0).norm();
    double inside = std::min(std::max(q.x(), std::max(q.y(), q.z())), 0.0);
    best = std::min(best, outside + inside);
  }
  return best;
}

std::vector<Eigen::Vector3d> SceneConfig::start_positions(int n, std::uint64_t seed) const {
  std::vector<Eigen::Vector3d> out;
  const double z = ground_z_m;
  const auto& s = start;
  if (s.formation == Formation::kExplicit) {
    if (static_cast<int>(s.positions.size()) < n)
      throw FieldError("scene.start.positions", std::to_string(s.positions.size()) + " positions",
                       "need one per drone (" + std::to_string(n) + ")");
    for (int i = 0; i < n; ++i) out.push_back(s.positions[i] + Eigen::Vector3d(0, 0, z));
  } else if (s.formation == Formation::kGrid) {
    int cols = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n))));
    int rows = (n + cols - 1) / cols;
    for (int i = 0; i < n; ++i) {
      double x = (i % cols - (cols - 1) / 2.0) * s.spacing_m;
      double y = (i / cols - (rows - 1) / 2.0) * s.spacing_m;
      out.emplace_back(s.center_xy.x() + x, s.center_xy.y() + y, z);
    }
  } else if (s.formation == Formation::kCluster) {
    // Hexagonal lattice points sorted by distance from the centre.
    std::vector<Eigen::Vector2d> pts;
    int rings = 1;
    while (3 * rings * (rings + 1) + 1 < n) ++rings;
    for (int q = -rings; q <= rings; ++q)
      for (int r = -rings; r <= rings; ++r) {
        if (std::abs(q + r) > rings) continue;
        pts.emplace_back(s.spacing_m * (q + r / 2.0), s.spacing_m * r * std::sqrt(3.0) / 2.0);
      }
    std::stable_sort(pts.begin(), pts.end(), [](const auto& a, const auto& b) {
      if (std::abs(a.norm() - b.norm()) > 1e-9) return a.norm() < b.norm();
      return std::atan2(a.y(), a.x()) < std::atan2(b.y(), b.x());
    });
    for (int i = 0; i < n; ++i)
      out.emplace_back(s.center_xy.x() + pts[i].x(), s.center_xy.y() + pts[i].y(), z);
  } else {
    std::mt19937_64 rng(seed ^ 0x5ca77e7ULL);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    int attempts = 0;
    while (static_cast<int>(out.size()) < n) {
      if (++attempts > 200000)
        throw FieldError("scene.start.radius_m", to_text(s.radius_m),
                         "too small to scatter " + std::to_string(n) + " drones at spacing_m");
      Eigen::Vector2d p(u(rng), u(rng));
      if (p.norm() > 1.0) continue;
      p = s.center_xy + p * s.radius_m;
      bool ok = true;
      for (const auto& q : out)
        if ((q.head<2>() - p).norm() < s.spacing_m) ok = false;
      if (ok) out.emplace_back(p.x(), p.y(), z);
    }
  }
  for (int i = 0; i < n; ++i) {
    if (clearance(out[i] + Eigen::Vector3d(0, 0, 0.1)) < 0.5)
      throw FieldError("scene.start",
                       "drone " + std::to_string(i) + " at (" + to_text(out[i].x()) + ", " +
                           to_text(out[i].y()) + ")",
                       "start position is inside or next to an obstacle");
  }
  return out;
}

}  // namespace ddswarm
