#pragma once
// Records the swarm's DDS traffic to MCAP (ROS 2 / Foxglove's log format):
// one channel per topic, the IDL as an omgidl schema, CDR payloads with
// receive (log) and source (publish) times, compressed chunks and a summary.
#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "common/dds_config.hpp"

namespace ddswarm::gs {

struct RecorderOptions {
  std::string path;                  ///< output .mcap
  std::vector<std::string> topics;   ///< topic names to record; empty = every ddswarm topic
  std::string compression = "zstd";  ///< zstd | lz4 | none
  std::uint64_t chunk_bytes =
      1 << 20;  ///< uncompressed bytes per chunk (what a crash can lose at most)
};

struct RecorderCounts {
  std::map<std::string, std::uint64_t> messages;  ///< per topic, written
  std::uint64_t bytes = 0;                        ///< file size
  std::size_t max_queue = 0;                      ///< most samples waiting for the disk at once
  /// per topic, only where it is not 0: samples a writer sent after the
  /// recorder joined that never reached it (gaps in the writer's sequence
  /// numbers: best-effort losses, or a KEEP_LAST writer that replaced them
  /// before they were delivered); they are not in the file
  std::map<std::string, std::uint64_t> missed;
  /// times the recorder left DDS and joined again, having been stopped or
  /// starved for longer than its lease (dds.lease_duration_s)
  int rejoins = 0;
  /// samples received a second time after joining again (the writers'
  /// transient-local history), kept once
  std::uint64_t duplicates = 0;
};

class Recorder {
 public:
  /// Opens the file (throws std::runtime_error naming it when it cannot be
  /// written) and subscribes. Unknown topic names throw std::invalid_argument.
  Recorder(const DdsConfig& dds, RecorderOptions options);
  ~Recorder();
  /// Records until stop(), stop_requested() or duration_s (<= 0: forever);
  /// then writes every received sample, the summary and the footer. Throws on
  /// a write error (disk full): the message names the file.
  RecorderCounts run(double duration_s);
  /// Ends run() from any thread, as SIGINT would.
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// `ddswarm-record info`: topics, message counts, start, end, duration; with
/// messages, one line per message: log time (ns), topic, bytes, FNV-1a hash of the payload.
std::string describe_recording(const std::string& path, bool messages = false);

/// The most samples a second a replay writes of one topic that joining
/// readers may take by data-sharing, when asked to play faster than
/// recorded: Fast DDS 2.9.1 may crash such a reader when the writer writes
/// 100,000+ samples a second; 10,000 a second never did in any trial, and is
/// over three times the most ddswarm publishes (docs/dds.md).
inline constexpr double kReplayMaxSamplesPerS = 10000;

/// The rate a replay runs at: asked, unless asked > 1 would write a topic
/// whose peak (its most samples in one second of the recording) is
/// peak_per_s faster than kReplayMaxSamplesPerS; then the highest rate that
/// does not, but never under 1, the pace the recording ran at live.
double replay_rate(double asked, double peak_per_s);

/// ddswarm-replay: republishes a recording with its original timing scaled
/// by rate (> 0); loops when asked.
class Replay {
 public:
  Replay(DdsConfig dds, std::string path, double rate, bool loop, std::vector<std::string> topics);
  /// Publishes until the end (looping: until stop() or stop_requested());
  /// returns messages published. A rate that replay_rate holds is said on
  /// stderr, with the rate it runs at. Throws, before publishing anything,
  /// when a live server's scene is on the domain.
  std::uint64_t run();
  /// Ends run() from any thread, as SIGINT would.
  void stop() { stop_ = true; }

 private:
  bool stopping() const;
  DdsConfig dds_;
  std::string path_;
  double rate_;
  bool loop_;
  std::vector<std::string> topics_;
  std::atomic<bool> stop_{false};
};

/// Replay(...).run().
std::uint64_t replay(const DdsConfig& dds, const std::string& path, double rate, bool loop,
                     const std::vector<std::string>& topics);

}  // namespace ddswarm::gs
