#include "ground_station/web/web_recording.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "common/mcap/mcap_reader.hpp"
#include "common/recorded_sample.hpp"
#include "common/topics.hpp"

namespace ddswarm::gs::web {

namespace {

std::uint64_t frame_bytes(const Frame& f) {
  std::uint64_t b = sizeof(Frame) + f.drones.size() * sizeof(DroneFrame);
  for (const auto& d : f.drones) b += d.ray_angle.size() * 13;
  return b;
}

enum class Kind { kNone, kState, kScene, kStatus, kTask, kCollision };

}  // namespace

std::size_t Recording::frame_at(double t) const {
  auto it = std::upper_bound(frames.begin(), frames.end(), t,
                             [](double x, const Frame& f) { return x < f.t; });
  return it == frames.begin() ? 0 : static_cast<std::size_t>(it - frames.begin()) - 1;
}

std::shared_ptr<Recording> load_recording(const std::string& path, const std::string& name,
                                          const RecordingLimits& limits) {
  mcap::Reader reader(path);
  std::map<std::uint16_t, Kind> kind;
  std::map<std::uint16_t, ScanLayout> layout;  // a recording made before scans had elevations
  for (const auto& [id, ch] : reader.channels()) {
    layout[id] = channel_scan_layout(reader, ch);
    Kind k = Kind::kNone;
    if (ch.topic == Topic<msg::SwarmState>::name) k = Kind::kState;
    if (ch.topic == Topic<msg::Scene>::name) k = Kind::kScene;
    if (ch.topic == Topic<msg::SimStatus>::name) k = Kind::kStatus;
    if (ch.topic == Topic<msg::TaskStatus>::name) k = Kind::kTask;
    if (ch.topic == Topic<msg::CollisionEvent>::name) k = Kind::kCollision;
    if (k != Kind::kNone && ch.message_encoding != "cdr")
      throw std::runtime_error(ch.topic + " is encoded as '" + ch.message_encoding + "', not cdr");
    kind[id] = k;
  }

  auto rec = std::make_shared<Recording>();
  rec->name = name;
  double min_dt = 1.0 / limits.max_frame_rate_hz;
  std::uint64_t bytes = 0;
  // The timeline is sim time, made monotonic: a server restarted within one
  // recording continues where the previous run ended.
  double offset = 0, last_sim = -1e300, now = std::nan(""), last_kept = -1e300;
  std::uint64_t undecodable = 0;
  msg::SwarmState state;
  reader.for_each_message([&](const mcap::MessageView& m) {
    ++rec->messages;
    auto it = kind.find(m.channel_id);
    if (it == kind.end()) return;
    switch (it->second) {
      case Kind::kNone:
        return;
      case Kind::kState: {
        if (!from_cdr(m.data, state, layout[m.channel_id])) {
          ++undecodable;
          return;
        }
        const double sim = state.sim_time_s();
        if (!std::isfinite(sim)) return;
        if (sim < last_sim) offset += last_sim - sim + 1e-3;
        last_sim = sim;
        now = sim + offset;
        if (now - last_kept < min_dt * 0.999) {
          ++rec->frames_skipped;
          return;
        }
        last_kept = now;
        Frame f = to_frame(state);
        f.t = now;
        bytes += frame_bytes(f);
        rec->frames.push_back(std::move(f));
        while (bytes > limits.max_bytes &&
               rec->frames.size() > 1) {  // halve the rate, keep every other frame
          std::vector<Frame> kept;
          bytes = 0;
          for (std::size_t i = 0; i < rec->frames.size(); i += 2) {
            bytes += frame_bytes(rec->frames[i]);
            kept.push_back(std::move(rec->frames[i]));
          }
          rec->frames_skipped += rec->frames.size() - kept.size();
          rec->frames = std::move(kept);
          min_dt *= 2;
        }
        return;
      }
      case Kind::kScene: {
        msg::Scene s;
        if (from_cdr(m.data, s)) rec->scene = std::move(s);
        return;
      }
      case Kind::kStatus: {
        msg::SimStatus s;
        if (from_cdr(m.data, s)) rec->status.push_back({now, std::move(s)});
        return;
      }
      case Kind::kTask: {
        msg::TaskStatus s;
        if (from_cdr(m.data, s)) rec->tasks.push_back({now, std::move(s)});
        return;
      }
      case Kind::kCollision: {
        msg::CollisionEvent s;
        if (from_cdr(m.data, s)) rec->collisions.push_back({now, std::move(s)});
        return;
      }
    }
  });
  if (rec->frames.empty())
    throw std::runtime_error(
        undecodable ? "its swarm state samples cannot be decoded"
                    : "it holds no swarm state (record the ddswarm/swarm_state topic)");
  // Samples before the first frame belong at its time.
  const double t0 = rec->frames.front().t;
  for (auto& s : rec->status)
    if (!std::isfinite(s.t)) s.t = t0;
  for (auto& s : rec->tasks)
    if (!std::isfinite(s.t)) s.t = t0;
  for (auto& s : rec->collisions)
    if (!std::isfinite(s.t)) s.t = t0;
  return rec;
}

}  // namespace ddswarm::gs::web
