#include "common/world_gen.hpp"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <vector>

#include "common/scene.hpp"

namespace ddswarm {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// A splitmix64 stream with its own uniform draw, so a world is the same on
/// every standard library (std::uniform_real_distribution is
/// implementation-defined).
class Draw {
 public:
  Draw(std::uint64_t seed, std::uint64_t salt) : s_(seed ^ (salt * 0x9e3779b97f4a7c15ULL)) {
    next();
  }
  std::uint64_t next() {
    std::uint64_t z = (s_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  double uniform(double lo, double hi) {
    return lo + (hi - lo) * (static_cast<double>(next() >> 11) * 0x1.0p-53);
  }

 private:
  std::uint64_t s_;
};

/// The course's frame: origin at the start centre, x toward the goal.
struct Course {
  Eigen::Vector2d origin, along, across;
  explicit Course(const SceneConfig& s)
      : origin(s.start.center_xy), along(s.task_direction()), across(-along.y(), along.x()) {}
  Eigen::Vector2d at(double s, double t) const { return origin + s * along + t * across; }
};

/// A wall as a box from a to b (xy, the wall's own axis), z from z0 to z1 above the ground.
Box wall_box(const SceneConfig& scene, const Eigen::Vector2d& a, const Eigen::Vector2d& b,
             double thickness, double z0, double z1) {
  const Eigen::Vector2d mid = 0.5 * (a + b), d = b - a;
  Box box;
  box.center = Eigen::Vector3d(mid.x(), mid.y(), scene.ground_z_m + 0.5 * (z0 + z1));
  box.size = Eigen::Vector3d(d.norm(), thickness, z1 - z0);
  box.yaw_rad = std::atan2(d.y(), d.x());
  return box;
}

bool kept_out(const SceneConfig& scene, const Eigen::Vector2d& p, double r) {
  return (p - scene.start.center_xy).norm() < r || (p - scene.goal_xy).norm() < r;
}

void check_ordered(const std::string& field, const Eigen::Vector2d& v) {
  if (!(v.x() > 0 && v.y() >= v.x()))
    throw FieldError(field, "[" + to_text(v.x()) + ", " + to_text(v.y()) + "]",
                     "must be [min, max] with 0 < min <= max");
}

void check_area(const std::string& prefix, const Eigen::Vector2d& lo, const Eigen::Vector2d& hi) {
  if (!(hi.x() > lo.x() && hi.y() > lo.y()))
    throw FieldError(prefix + ".area_max", "[" + to_text(hi.x()) + ", " + to_text(hi.y()) + "]",
                     "must exceed area_min on both axes");
}

int urban(const UrbanConfig& u, Draw& d, SceneConfig& scene) {
  const double pitch = u.block_m + u.street_m;
  int made = 0;
  for (double x = u.area_min.x() + 0.5 * u.street_m; x + u.block_m <= u.area_max.x() + 1e-9;
       x += pitch)
    for (double y = u.area_min.y() + 0.5 * u.street_m; y + u.block_m <= u.area_max.y() + 1e-9;
         y += pitch) {
      const double sx = u.block_m * d.uniform(u.fill_min, 1.0),
                   sy = u.block_m * d.uniform(u.fill_min, 1.0);
      const double h = d.uniform(u.height_m.x(), u.height_m.y());
      const Eigen::Vector2d c(x + 0.5 * u.block_m + d.uniform(-0.5, 0.5) * (u.block_m - sx),
                              y + 0.5 * u.block_m + d.uniform(-0.5, 0.5) * (u.block_m - sy));
      if (kept_out(scene, c, u.keep_out_m + 0.5 * std::hypot(sx, sy))) continue;
      Box b;
      b.center = Eigen::Vector3d(c.x(), c.y(), scene.ground_z_m + 0.5 * h);
      b.size = Eigen::Vector3d(sx, sy, h);
      scene.boxes.push_back(b);
      ++made;
    }
  return made;
}

int walls(const WallsConfig& w, Draw& d, SceneConfig& scene) {
  const Course course(scene);
  const double half = 0.5 * w.length_m;
  int made = 0;
  for (int k = 0; k < w.count; ++k) {
    const double s = w.first_at_m + k * w.spacing_m;
    // Openings at seeded places along the wall, apart from one another.
    std::vector<double> centres;
    for (int tries = 0; static_cast<int>(centres.size()) < w.openings && tries < 10000; ++tries) {
      const double c = d.uniform(-half + 0.5 * w.opening_width_m, half - 0.5 * w.opening_width_m);
      bool apart = true;
      for (double o : centres) apart &= std::abs(o - c) >= w.opening_width_m + w.thickness_m;
      if (apart) centres.push_back(c);
    }
    std::sort(centres.begin(), centres.end());
    auto add = [&](double t0, double t1, double z0, double z1) {
      if (t1 - t0 < 1e-6 || z1 - z0 < 1e-6) return;
      scene.boxes.push_back(
          wall_box(scene, course.at(s, t0), course.at(s, t1), w.thickness_m, z0, z1));
      ++made;
    };
    double from = -half;
    for (double c : centres) {
      const double a = c - 0.5 * w.opening_width_m, b = c + 0.5 * w.opening_width_m;
      add(from, a, 0, w.height_m);
      if (w.window_height_m > 0) {  // a window: wall below its sill and above its lintel
        add(a, b, 0, w.window_bottom_m);
        add(a, b, w.window_bottom_m + w.window_height_m, w.height_m);
      }
      from = b;
    }
    add(from, half, 0, w.height_m);
  }
  return made;
}

int corridor(const CorridorConfig& c, Draw& d, SceneConfig& scene) {
  const Course course(scene);
  const int legs = c.bends + 1;
  const double theta = c.bend_deg * kPi / 180.0;
  // The centre line: legs of equal progress along the course, their angle to
  // it alternating (the first side seeded), so the corridor keeps to the axis.
  const double first = c.bends > 0 && d.next() % 2 ? -1.0 : 1.0;
  std::vector<Eigen::Vector2d> centre{course.at(c.start_at_m, 0)};
  std::vector<Eigen::Vector2d> heading;
  for (int k = 0; k < legs; ++k) {
    const double a = c.bends == 0 ? 0.0 : (k % 2 ? -first : first) * theta;
    const Eigen::Vector2d h = std::cos(a) * course.along + std::sin(a) * course.across;
    heading.push_back(h);
    centre.push_back(centre.back() + (c.length_m / legs) / std::cos(a) * h);
  }
  // Each wall follows the centre line at an offset, mitred at the bends.
  int made = 0;
  for (double side : {-1.0, 1.0}) {
    const double off = side * 0.5 * (c.width_m + c.thickness_m);
    std::vector<Eigen::Vector2d> line;
    auto normal = [&](int k) { return Eigen::Vector2d(-heading[k].y(), heading[k].x()); };
    line.push_back(centre.front() + off * normal(0));
    for (int j = 1; j < legs; ++j) {
      const Eigen::Vector2d n = normal(j - 1) + normal(j);
      line.push_back(centre[j] + off * n / (1.0 + normal(j - 1).dot(normal(j))));
    }
    line.push_back(centre.back() + off * normal(legs - 1));
    for (int k = 0; k < legs; ++k) {
      // Longer by the thickness, so the outer corner of a bend is closed.
      const Eigen::Vector2d dir = (line[k + 1] - line[k]).normalized();
      const double grow = 0.5 * c.thickness_m;
      scene.boxes.push_back(wall_box(scene, line[k] - (k > 0 ? grow : 0.0) * dir,
                                     line[k + 1] + (k + 1 < legs ? grow : 0.0) * dir, c.thickness_m,
                                     0, c.wall_height_m));
      ++made;
    }
  }
  return made;
}

/// Poisson-disc sampling by dart throwing on a grid: pillars at least
/// min_gap_m apart (surface to surface) and clear of everything already in
/// the scene; it stops at the density asked for, or when 60 darts per
/// pillar found no room (the area is full).
int forest(const ForestConfig& f, Draw& d, SceneConfig& scene, int* wanted) {
  const Eigen::Vector2d size = f.area_max - f.area_min;
  *wanted = static_cast<int>(std::lround(f.density_per_100m2 * size.x() * size.y() / 100.0));
  const double cell = 2 * f.radius_m.y() + f.min_gap_m;
  auto key = [&](const Eigen::Vector2d& p) {
    const auto ix = static_cast<std::int64_t>(std::floor((p.x() - f.area_min.x()) / cell));
    const auto iy = static_cast<std::int64_t>(std::floor((p.y() - f.area_min.y()) / cell));
    return std::make_pair(ix, iy);
  };
  struct PairHash {
    std::size_t operator()(const std::pair<std::int64_t, std::int64_t>& k) const {
      return std::hash<std::int64_t>()(k.first * 73856093 ^ k.second * 19349663);
    }
  };
  std::unordered_map<std::pair<std::int64_t, std::int64_t>, std::vector<Cylinder>, PairHash> grid;
  const SceneConfig before = scene;  // what the forest must keep clear of
  int placed = 0;
  const long tries = 60L * std::max(*wanted, 1);
  for (long t = 0; t < tries && placed < *wanted; ++t) {
    Cylinder c;
    c.radius_m = d.uniform(f.radius_m.x(), f.radius_m.y());
    c.height_m = d.uniform(f.height_m.x(), f.height_m.y());
    c.center_xy = Eigen::Vector2d(d.uniform(f.area_min.x(), f.area_max.x()),
                                  d.uniform(f.area_min.y(), f.area_max.y()));
    if (kept_out(scene, c.center_xy, f.keep_out_m + c.radius_m)) continue;
    const Eigen::Vector3d at(c.center_xy.x(), c.center_xy.y(), scene.ground_z_m + 0.5);
    if (!before.cylinders.empty() || !before.boxes.empty() || !before.meshes.empty())
      if (before.clearance(at) < c.radius_m + f.min_gap_m) continue;
    const auto [ix, iy] = key(c.center_xy);
    bool clear = true;
    for (std::int64_t dx = -1; dx <= 1 && clear; ++dx)
      for (std::int64_t dy = -1; dy <= 1 && clear; ++dy) {
        auto it = grid.find({ix + dx, iy + dy});
        if (it == grid.end()) continue;
        for (const auto& o : it->second)
          if ((o.center_xy - c.center_xy).norm() < o.radius_m + c.radius_m + f.min_gap_m) {
            clear = false;
            break;
          }
      }
    if (!clear) continue;
    grid[{ix, iy}].push_back(c);
    scene.cylinders.push_back(c);
    ++placed;
  }
  return placed;
}

}  // namespace

void WorldGenConfig::validate() const {
  const std::string p = "scene.generate";
  if (forest.density_per_100m2 > 0) {
    check_ordered(p + ".forest.radius_m", forest.radius_m);
    check_ordered(p + ".forest.height_m", forest.height_m);
    check_area(p + ".forest", forest.area_min, forest.area_max);
  }
  if (walls.count > 0) {
    if (walls.openings * (walls.opening_width_m + walls.thickness_m) > walls.length_m)
      throw FieldError(p + ".walls.opening_width_m", to_text(walls.opening_width_m),
                       fmt::format("{} openings this wide do not fit in a wall {} m long",
                                   walls.openings, to_text(walls.length_m)));
    if (walls.window_height_m > 0 &&
        walls.window_bottom_m + walls.window_height_m >= walls.height_m)
      throw FieldError(
          p + ".walls.window_height_m", to_text(walls.window_height_m),
          fmt::format("a window from {} m up this tall does not fit in a wall {} m high",
                      to_text(walls.window_bottom_m), to_text(walls.height_m)));
  }
  if (urban.block_m > 0) {
    check_ordered(p + ".urban.height_m", urban.height_m);
    check_area(p + ".urban", urban.area_min, urban.area_max);
    if (urban.area_max.x() - urban.area_min.x() < urban.block_m + urban.street_m ||
        urban.area_max.y() - urban.area_min.y() < urban.block_m + urban.street_m)
      throw FieldError(p + ".urban.block_m", to_text(urban.block_m),
                       "no block and street fit in the area");
  }
}

std::string WorldGenReport::summary() const {
  std::vector<std::string> parts;
  if (buildings) parts.push_back(fmt::format("{} buildings", buildings));
  if (wall_boxes) parts.push_back(fmt::format("walls of {} boxes", wall_boxes));
  if (corridor_boxes) parts.push_back(fmt::format("a corridor of {} boxes", corridor_boxes));
  if (pillars_wanted)
    parts.push_back(fmt::format("a forest of {} pillars (of {} wanted)", pillars, pillars_wanted));
  std::string s;
  for (const auto& x : parts) s += (s.empty() ? "" : ", ") + x;
  return s.empty() ? "nothing" : s;
}

WorldGenReport generate_world(const WorldGenConfig& g, std::uint64_t scenario_seed,
                              SceneConfig& scene) {
  const std::uint64_t seed = g.seed ? g.seed : scenario_seed;
  WorldGenReport r;
  // One stream per kind: adding walls leaves the forest's draws as they were.
  if (g.urban.block_m > 0) {
    Draw d(seed, 1);
    r.buildings = urban(g.urban, d, scene);
  }
  if (g.walls.count > 0) {
    Draw d(seed, 2);
    r.wall_boxes = walls(g.walls, d, scene);
  }
  if (g.corridor.length_m > 0) {
    Draw d(seed, 3);
    r.corridor_boxes = corridor(g.corridor, d, scene);
  }
  if (g.forest.density_per_100m2 > 0) {  // last: clear of everything else
    Draw d(seed, 4);
    r.pillars = forest(g.forest, d, scene, &r.pillars_wanted);
  }
  return r;
}

}  // namespace ddswarm
