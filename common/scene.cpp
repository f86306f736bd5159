#include "common/scene.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <random>

namespace ddswarm {
namespace {

bool finite(const Eigen::Vector3d& v) { return v.allFinite(); }

/// Squared distance from p to triangle (a, b, c): the closest-point regions
/// of Ericson, Real-Time Collision Detection (2005), sec. 5.1.5.
double distance2_to_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                             const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return ap.squaredNorm();
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return bp.squaredNorm();
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return (ap - ab * (d1 / (d1 - d3))).squaredNorm();
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return cp.squaredNorm();
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return (ap - ac * (d2 / (d2 - d6))).squaredNorm();
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return (bp - (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))).squaredNorm();
  const double denom = 1.0 / (va + vb + vc);
  return (ap - ab * (vb * denom) - ac * (vc * denom)).squaredNorm();
}

/// Distance from p to an axis-aligned box (0 inside).
double distance_to_aabb(const Eigen::Vector3d& p, const Eigen::Vector3d& lo,
                        const Eigen::Vector3d& hi) {
  return (lo - p).cwiseMax(p - hi).cwiseMax(0.0).norm();
}

}  // namespace

Eigen::Matrix3d MeshObstacle::rotation() const {
  constexpr double kDeg = 3.14159265358979323846 / 180.0;
  const auto about = [](double deg, const Eigen::Vector3d& axis) {
    return Eigen::AngleAxisd(deg * kDeg, axis).toRotationMatrix();
  };
  return about(yaw_deg, Eigen::Vector3d::UnitZ()) *
         about(rotation_deg.z(), Eigen::Vector3d::UnitZ()) *
         about(rotation_deg.y(), Eigen::Vector3d::UnitY()) *
         about(rotation_deg.x(), Eigen::Vector3d::UnitX());
}

void load(YamlSection s, SceneConfig& c) {
  FieldLoader load(s);
  SceneConfig::fields(c, load);
  s.finish();
}

void anchor_mesh_files(YAML::Node& root, const std::string& scenario_dir) {
  if (!root.IsMap() || !root["scene"] || !root["scene"].IsMap()) return;
  YAML::Node meshes = root["scene"]["meshes"];
  if (!meshes || !meshes.IsSequence()) return;
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    YAML::Node m = meshes[i];
    if (!m.IsMap() || !m["file"] || !m["file"].IsScalar()) continue;
    const std::filesystem::path file = m["file"].Scalar();
    if (file.empty() || file.is_absolute()) continue;
    m["file"] = std::filesystem::absolute(std::filesystem::path(scenario_dir) / file)
                    .lexically_normal()
                    .string();
  }
}

void SceneConfig::validate() const {
  FieldChecker check("scene");
  fields(*this, check);
  generate.validate();
  for (std::size_t i = 0; i < boxes.size(); ++i) {
    std::string p = "scene.boxes[" + std::to_string(i) + "]";
    for (int k = 0; k < 3; ++k) check_positive(p + ".size", boxes[i].size[k]);
  }
  if (meshes.size() > 64)
    throw FieldError("scene.meshes", std::to_string(meshes.size()) + " entries", "at most 64");
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    const MeshObstacle& m = meshes[i];
    const std::string p = "scene.meshes[" + std::to_string(i) + "]";
    if (m.file.empty()) throw FieldError(p + ".file", "\"\"", "must name a mesh file");
    if (m.file.size() > 255)
      throw FieldError(p + ".file", m.file.substr(0, 40) + "...", "must be at most 255 characters");
    for (unsigned char ch : m.file)
      if (ch < 0x20 || ch == 0x7f)
        throw FieldError(p + ".file", one_line(m.file), "must not hold control characters");
    if (!finite(m.position))
      throw FieldError(p + ".position", to_text(m.position.transpose()), "must be finite");
    if (!finite(m.rotation_deg))
      throw FieldError(p + ".rotation_deg", to_text(m.rotation_deg.transpose()), "must be finite");
    if (!std::isfinite(m.yaw_deg))
      throw FieldError(p + ".yaw_deg", to_text(m.yaw_deg), "must be finite");
    if (m.triangle_count > 0 && !(finite(m.bounds_min) && finite(m.bounds_max) &&
                                  (m.bounds_min.array() <= m.bounds_max.array()).all()))
      throw FieldError(p + ".bounds_max", to_text(m.bounds_max.transpose()),
                       "must be finite and at least bounds_min on every axis");
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
  for (const auto& m : meshes) {
    if (m.triangle_count == 0) continue;
    const double to_bounds = distance_to_aabb(p, m.bounds_min, m.bounds_max);
    if (!m.world) {
      best = std::min(best, to_bounds);
      continue;
    }
    if (to_bounds >= best) continue;  // no triangle can be nearer than the bounds
    double d2 = best * best;
    const auto& v = m.world->vertices;
    for (const auto& t : m.world->triangles)
      d2 = std::min(d2, distance2_to_triangle(p, v[t[0]].cast<double>(), v[t[1]].cast<double>(),
                                              v[t[2]].cast<double>()));
    best = std::min(best, std::sqrt(d2));
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
