#pragma once
// A recording (MCAP, as ddswarm-record writes it) indexed for the web view:
// the frames of its SwarmState samples on a sim-time timeline, and its Scene,
// SimStatus, TaskStatus and CollisionEvent samples placed on the same timeline.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ground_station/web/web_frame.hpp"

namespace ddswarm::gs::web {

template <class T>
struct Timed {
  double t = 0;  ///< s, on the recording's timeline (sim time)
  T sample;
};

struct Recording {
  std::string id;             ///< what `open` names
  std::string name;           ///< the uploaded file's name
  std::vector<Frame> frames;  ///< ordered by t (Frame::t is the timeline time)
  std::optional<msg::Scene> scene;
  std::vector<Timed<msg::SimStatus>> status;
  std::vector<Timed<msg::TaskStatus>> tasks;
  std::vector<Timed<msg::CollisionEvent>> collisions;
  std::uint64_t messages = 0;  ///< messages in the file
  std::uint64_t frames_skipped =
      0;  ///< SwarmState samples left out to stay within the memory bound
  double start() const { return frames.empty() ? 0 : frames.front().t; }
  double duration() const { return frames.empty() ? 0 : frames.back().t - frames.front().t; }
  /// Index of the last frame at or before t (0 if t is before the first).
  std::size_t frame_at(double t) const;
};

struct RecordingLimits {
  double max_frame_rate_hz = 60;           ///< frames kept per sim second at most
  std::uint64_t max_bytes = 256ull << 20;  ///< memory for frames; the rate is halved until they fit
};

/// Reads and indexes an MCAP file. Throws std::runtime_error with a one-line
/// reason (not MCAP, no swarm state, corrupt chunk).
std::shared_ptr<Recording> load_recording(const std::string& path, const std::string& name,
                                          const RecordingLimits& limits = {});

}  // namespace ddswarm::gs::web
