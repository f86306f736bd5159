#include "common/swarm_metrics.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <numeric>

namespace ddswarm {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Union-find over drone indices, for the range graph's components.
struct Components {
  std::vector<int> parent;
  int count;
  explicit Components(int n) : parent(n), count(n) { std::iota(parent.begin(), parent.end(), 0); }
  int root(int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  void join(int a, int b) {
    a = root(a);
    b = root(b);
    if (a == b) return;
    parent[std::max(a, b)] = std::min(a, b);
    --count;
  }
};

/// λ₂ of the Laplacian L (n >= 2). Symmetric, so the eigenvalues come
/// ascending; the smallest is 0 (up to rounding), the next is λ₂.
double second_eigenvalue(const Eigen::MatrixXd& laplacian) {
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(laplacian, Eigen::EigenvaluesOnly);
  return std::max(0.0, es.eigenvalues()(1));
}

Eigen::MatrixXd range_laplacian(std::span<const Eigen::Vector3d> p, double range_m) {
  const auto n = static_cast<Eigen::Index>(p.size());
  Eigen::MatrixXd l = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = i + 1; j < n; ++j)
      if ((p[i] - p[j]).norm() <= range_m) {
        l(i, j) = l(j, i) = -1;
        l(i, i) += 1;
        l(j, j) += 1;
      }
  return l;
}

}  // namespace

double velocity_order(std::span<const Eigen::Vector3d> v, double still_speed_mps) {
  const std::size_t n = v.size();
  if (n < 2) return kNaN;
  // Σ_{i≠j} u_i·u_j = |Σ u_i|² - Σ |u_i|², with u_i the unit velocity (0 when
  // still): O(N) instead of the N(N-1) pairs.
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  double self = 0;
  for (const auto& vi : v) {
    const double s = vi.norm();
    if (!(s >= still_speed_mps) || s == 0) continue;
    sum += vi / s;
    self += 1;
  }
  const double pairs = static_cast<double>(n) * static_cast<double>(n - 1);
  return std::clamp((sum.squaredNorm() - self) / pairs, -1.0, 1.0);
}

double algebraic_connectivity(std::span<const Eigen::Vector3d> p, double range_m) {
  if (p.size() < 2) return kNaN;
  return second_eigenvalue(range_laplacian(p, range_m));
}

SwarmTickMetrics swarm_tick_metrics(std::span<const Eigen::Vector3d> p,
                                    std::span<const Eigen::Vector3d> v,
                                    const SwarmMetricsOptions& o) {
  assert(p.size() == v.size());
  SwarmTickMetrics m;
  const int n = static_cast<int>(p.size());
  m.drones = n;
  if (n == 0) return m;
  double speed = 0;
  for (const auto& vi : v) speed += vi.norm();
  m.mean_speed_mps = speed / n;
  m.order = velocity_order(v, o.still_speed_mps);
  const double release_m = o.near_miss_m * kNearMissRelease;
  Components graph(n);
  for (int i = 0; i < n; ++i) {
    for (int j = i + 1; j < n; ++j) {
      // The referee's own distance (TaskReport.min_inter_drone_m and the
      // swarm condition) comes from here: keep it (p_i - p_j).norm().
      const double d = (p[i] - p[j]).norm();
      m.max_distance_m = std::max(m.max_distance_m, d);
      m.min_distance_m = std::min(m.min_distance_m, d);
      if (d < release_m) m.close.push_back({i, j, d, d < o.near_miss_m});
      if (d < o.near_miss_m) ++m.near_pairs;
      if (d <= o.range_m) graph.join(i, j);
    }
  }
  m.components = graph.count;
  if (n < 2) return m;
  if (m.components > 1)
    m.lambda2 = 0;
  else if (n <= o.lambda2_max_drones)
    m.lambda2 = second_eigenvalue(range_laplacian(p, o.range_m));
  return m;
}

SwarmMetricsAccumulator::SwarmMetricsAccumulator(const SwarmMetricsOptions& o) : o_(o) { reset(); }

void SwarmMetricsAccumulator::reset() {
  s_ = SwarmTaskMetrics{};
  s_.range_m = o_.range_m;
  s_.near_miss_m = o_.near_miss_m;
  ticks_ = 0;
  order_sum_ = speed_sum_ = 0;
  order_ticks_ = speed_ticks_ = 0;
  approaching_.clear();
}

void SwarmMetricsAccumulator::add(const SwarmTickMetrics& m, std::span<const int> ids) {
  assert(ids.size() == static_cast<std::size_t>(m.drones));
  ++ticks_;
  if (std::isfinite(m.order)) {
    order_sum_ += m.order;
    ++order_ticks_;
    s_.order_mean = order_sum_ / static_cast<double>(order_ticks_);
    s_.order_min = std::fmin(s_.order_min, m.order);  // fmin: NaN (none yet) loses
  }
  if (std::isfinite(m.mean_speed_mps)) {
    speed_sum_ += m.mean_speed_mps;
    ++speed_ticks_;
    s_.speed_mean_mps = speed_sum_ / static_cast<double>(speed_ticks_);
  }
  s_.components_max = std::max(s_.components_max, m.components);
  if (!std::isnan(m.lambda2)) s_.lambda2_min = std::fmin(s_.lambda2_min, m.lambda2);

  // A pair approaches from the tick it comes nearer than near_miss_m until it
  // is kNearMissRelease times that apart again (it is then not in m.close).
  std::vector<std::pair<int, int>> now;
  for (const ClosePair& c : m.close) {
    const std::pair<int, int> key = std::minmax(ids[c.k], ids[c.l]);
    const bool was = std::binary_search(approaching_.begin(), approaching_.end(), key);
    if (c.near && !was) ++s_.near_misses;
    if (c.near || was) now.push_back(key);
  }
  std::sort(now.begin(), now.end());
  approaching_ = std::move(now);
}

}  // namespace ddswarm
