#include "ground_station/trace.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <limits>
#include <mutex>
#include <stdexcept>

#include "common/convert.hpp"
#include "common/mission.hpp"
#include "common/participant.hpp"
#include "common/process.hpp"
#include "common/scenario.hpp"

namespace ddswarm::gs {

struct SwarmTrace::Impl {
  std::atomic<bool> stopping{false};  // stop()
  FILE* f;
  FILE* metrics_f = nullptr;
  int every;
  DdsConfig dds_cfg;
  SwarmMetricsOptions metrics;
  std::atomic<long> rows{0};
  std::atomic<long> metrics_rows{0};
  std::mutex mu;
  std::optional<std::uint64_t> last_tick;  // under mu
  std::unique_ptr<Participant> dds;
  Impl(const DdsConfig& d, const std::string& path, int e, const TraceMetrics& m)
      : f(std::fopen(path.c_str(), "w")), every(std::max(1, e)), dds_cfg(d), metrics(m.options) {
    if (!f) throw std::runtime_error("cannot write " + path + ": " + std::strerror(errno));
    if (!m.path.empty() && !(metrics_f = std::fopen(m.path.c_str(), "w"))) {
      const int err = errno;
      std::fclose(f);
      throw std::runtime_error("cannot write " + m.path + ": " + std::strerror(err));
    }
    std::fprintf(f, "tick,sim_time_s,drone,x,y,z,vx,vy,vz,phase,flags,collisions\n");
    if (metrics_f) std::fprintf(metrics_f, "%s\n", kTraceMetricsHeader);
    join();
  }
  /// A new participant and reader; the old one, if any, is closed first.
  void join() {
    dds.reset();  // the old participant leaves before the new one joins
    dds = std::make_unique<Participant>(dds_cfg, "ddswarm-trace");
    dds->reader<msg::SwarmState>([this](const msg::SwarmState& s, const fdds::SampleInfo&) {
      if (s.tick() % every) return;
      std::lock_guard<std::mutex> lock(mu);
      // A lockstep tick published again (a lost answer) is the same tick.
      if (last_tick == s.tick()) return;
      last_tick = s.tick();
      for (const auto& d : s.drones()) {
        std::fprintf(f, "%llu,%.3f,%u,%.4f,%.4f,%.4f,%.4f,%.4f,%.4f,%u,%u,%u\n",
                     static_cast<unsigned long long>(s.tick()), s.sim_time_s(), d.drone_id(),
                     d.position().x(), d.position().y(), d.position().z(), d.velocity().x(),
                     d.velocity().y(), d.velocity().z(), d.phase(), d.flags(),
                     d.collisions_obstacle() + d.collisions_drone() + d.collisions_ground());
        ++rows;
      }
      if (metrics_f) {
        std::fprintf(metrics_f, "%s\n", trace_metrics_row(s, metrics).c_str());
        ++metrics_rows;
      }
    });
  }
  ~Impl() {
    if (dds) dds->close();  // no callback may write to the file once it is closed
    std::lock_guard<std::mutex> lock(mu);
    std::fclose(f);
    if (metrics_f) std::fclose(metrics_f);
  }
};

SwarmTrace::SwarmTrace(const DdsConfig& dds, const std::string& path, int every,
                       const TraceMetrics& metrics)
    : impl_(std::make_unique<Impl>(dds, path, every, metrics)) {}
SwarmTrace::~SwarmTrace() = default;
long SwarmTrace::rows() const { return impl_->rows; }
long SwarmTrace::metrics_rows() const { return impl_->metrics_rows; }
void SwarmTrace::stop() { impl_->stopping = true; }
void SwarmTrace::run(double duration_s) {
  const double end = wall_seconds() + (duration_s > 0 ? duration_s : 1e9);
  LeaseWatch lease(impl_->dds_cfg.lease_duration_s, wall_seconds());
  while (!wait_for_stop(std::chrono::duration<double>(std::min(0.25, end - wall_seconds()))) &&
         !impl_->stopping && wall_seconds() < end) {
    if (const std::string why = lease.turn(wall_seconds()); !why.empty()) {
      spdlog::warn("ddswarm-gs trace: {}", why);
      settle_after_stop();
      impl_->join();
      lease.restart(wall_seconds());
    }
  }
}

std::string SwarmSnapshot::table() const {
  std::string out =
      fmt::format("tick {} (sim {:.2f} s), {} drones\n", tick, sim_time_s, drones.size());
  out += fmt::format("{:>5} {:>9} {:>9} {:>7} {:>7} {:>9} {:>5}  {:<9} {}\n", "drone", "x m", "y m",
                     "z m", "m/s", "nearest m", "coll", "phase", "flags");
  for (const auto& d : drones)
    out +=
        fmt::format("{:>5} {:>9.2f} {:>9.2f} {:>7.2f} {:>7.2f} {:>9.2f} {:>5}  {:<9} {}\n", d.id,
                    d.x, d.y, d.z, d.speed_mps, d.nearest_peer_m, d.collisions, d.phase, d.flags);
  out += fmt::format("pairwise distance: min {:.2f} m, max {:.2f} m\n", min_pair_m, max_pair_m);
  return out;
}

SwarmSnapshot snapshot_of(const msg::SwarmState& s) {
  SwarmSnapshot snap;
  snap.tick = s.tick();
  snap.sim_time_s = s.sim_time_s();
  std::vector<Eigen::Vector3d> pos;
  for (const auto& d : s.drones()) pos.push_back(from_msg(d.position()));
  snap.min_pair_m = pos.size() > 1 ? std::numeric_limits<double>::infinity() : 0;
  for (std::size_t i = 0; i < pos.size(); ++i) {
    const auto& d = s.drones()[i];
    DroneRow r;
    r.id = d.drone_id();
    r.x = pos[i].x();
    r.y = pos[i].y();
    r.z = pos[i].z();
    r.speed_mps = from_msg(d.velocity()).norm();
    r.nearest_peer_m = std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < pos.size(); ++j) {
      if (j == i) continue;
      double dist = (pos[i] - pos[j]).norm();
      r.nearest_peer_m = std::min(r.nearest_peer_m, dist);
      if (j > i) {
        snap.min_pair_m = std::min(snap.min_pair_m, dist);
        snap.max_pair_m = std::max(snap.max_pair_m, dist);
      }
    }
    if (pos.size() < 2) r.nearest_peer_m = 0;
    r.collisions =
        static_cast<int>(d.collisions_obstacle() + d.collisions_drone() + d.collisions_ground());
    r.phase = to_string(static_cast<Phase>(d.phase()));
    auto flag = [&](std::uint16_t bit, const char* name) {
      if (d.flags() & bit) r.flags += (r.flags.empty() ? "" : ",") + std::string(name);
    };
    flag(msg::DRONE_AIRBORNE, "airborne");
    flag(msg::DRONE_FAILSAFE, "failsafe");
    flag(msg::DRONE_OUT_OF_BOUNDS, "out-of-bounds");
    flag(msg::DRONE_PAST_FINISH, "past-finish");
    if (!(d.flags() & msg::DRONE_AGENT_LIVE))
      r.flags += (r.flags.empty() ? "" : ",") + std::string("no-agent");
    snap.drones.push_back(r);
  }
  return snap;
}

std::string trace_metrics_row(const msg::SwarmState& s, const SwarmMetricsOptions& o) {
  std::vector<Eigen::Vector3d> p, v;
  for (const auto& d : s.drones()) {
    if (d.flags() & msg::DRONE_FAILSAFE) continue;
    p.push_back(from_msg(d.position()));
    v.push_back(from_msg(d.velocity()));
  }
  const SwarmTickMetrics m = swarm_tick_metrics(p, v, o);
  return fmt::format("{},{:.3f},{},{:.4f},{:.4f},{:.4f},{},{},{:.4f}", s.tick(), s.sim_time_s(),
                     m.drones, m.order, m.mean_speed_mps, m.min_distance_m, m.near_pairs,
                     m.components, m.lambda2);
}

SwarmMetricsOptions scenario_metrics_options(const std::string& path) {
  SwarmMetricsOptions o;
  if (path.empty()) return o;
  const auto doc = load_scenario(path);
  doc.guard([&] {
    // Only these keys: the rest of sim: is the server's to check.
    YamlSection sim = doc.section("sim");
    FieldLoader load(sim);
    SwarmMetricsOptions::sim_fields(o, load);
    FieldChecker check("sim");
    SwarmMetricsOptions::sim_fields(o, check);
  });
  return o;
}

}  // namespace ddswarm::gs
