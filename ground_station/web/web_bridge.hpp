#pragma once
// `ddswarm-gs --web`: the swarm in the browser (docs/web_view.md).
//
// Joins the DDS domain, serves the page, and streams the swarm to each open
// page over a WebSocket. DDS callbacks only swap a pointer to the latest
// sample; each page's pacing timer sends the newest frame when its previous
// write has completed, so a slow page sees fewer frames and costs the swarm
// nothing. Commands from the pages run one at a time on a worker thread
// through DdsCommander, exactly as the CLI sends them.
#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <memory>
#include <string>

#include "common/dds_config.hpp"
#include "ground_station/gs_config.hpp"
#include "ground_station/web/web_server.hpp"

namespace ddswarm::gs::web {

struct WebBridgeOptions {
  WebServerConfig server;
  GroundStationConfig gs;
  TaskConfig task;  ///< defaults for the task command
  DdsConfig dds;
  double duration_s = 0;  ///< s wall; 0 = until SIGINT/SIGTERM
  /// What a Scene's relative mesh file names are relative to: the folder of
  /// the ground station's --config (the server's are relative to its scenario's).
  std::filesystem::path mesh_dir = ".";
};

/// What the bridge did, for its closing line and the tests.
struct WebBridgeCounts {
  std::uint64_t clients = 0;      ///< WebSockets opened
  std::uint64_t frames_sent = 0;  ///< frames handed to a client
  std::uint64_t frames_replaced =
      0;  ///< frames dropped because the client had not taken the previous one
  std::uint64_t malformed = 0;     ///< client messages answered with `error`
  std::uint64_t rate_limited = 0;  ///< client messages dropped over the rate limit
  std::uint64_t commands = 0;      ///< commands run through DdsCommander
  std::uint64_t uploads = 0;       ///< recordings indexed
  std::string line() const;
};

class WebBridge {
 public:
  /// Validates the options, joins DDS and listens; throws naming what failed.
  explicit WebBridge(const WebBridgeOptions& options);
  ~WebBridge();
  WebBridge(const WebBridge&) = delete;
  WebBridge& operator=(const WebBridge&) = delete;

  std::string url() const;
  /// Serves until stop(), stop_requested() or the duration; closes every page cleanly.
  WebBridgeCounts run();
  /// Ends run() from any thread (within 0.1 s), as SIGINT would.
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ddswarm::gs::web
