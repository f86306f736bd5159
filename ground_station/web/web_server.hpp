#pragma once
// The web view's transport: HTTP (static files, the recording upload) and a
// WebSocket per page at /ws, on Boost.Beast over one Asio thread. It knows
// nothing of the swarm: the bridge (web_bridge.hpp) handles what arrives
// through WebHooks. Every hook and every WebClient method runs on the server's
// thread; post() is the way in from other threads.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>

namespace ddswarm::gs::web {

struct WebServerConfig {
  std::string address = "127.0.0.1";  ///< listen address (IPv4 or IPv6 literal)
  int port = 8080;                    ///< TCP port, [0, 65535]; 0 = any free port
  std::filesystem::path web_root;     ///< the page's files (index.html, node_modules/three)
  bool allow_remote = false;          ///< listen on a non-loopback address
  std::uint64_t max_upload_bytes = 512ull << 20;  ///< largest recording upload, bytes, >= 1 MiB
  /// Throws ConfigError naming the field and value (e.g. a non-loopback address without
  /// allow_remote).
  void validate() const;
};

/// Parses "ADDR:PORT" ("[v6]:PORT" for IPv6) into address and port; throws
/// ConfigError "--web = <text>: ..." when it is not one.
void parse_listen_address(const std::string& text, WebServerConfig& c);

/// The compile-time default web root (the source tree's ground_station/web/www).
std::filesystem::path default_web_root();

/// Maps a request target to a file under root: "/" is index.html, "/vendor/three/X"
/// is node_modules/three/X. Percent-escapes are decoded; "..", backslashes, NUL and
/// anything resolving outside root give nullopt. The file must exist.
std::optional<std::filesystem::path> resolve_static_path(const std::filesystem::path& root,
                                                         std::string_view target);

/// The Content-Type for a file name, e.g. "text/javascript; charset=utf-8".
std::string mime_type(const std::filesystem::path& file);

/// True when a request's Origin (if any) names the same host:port as its Host header.
bool same_origin(std::string_view origin, std::string_view host);

/// One open WebSocket. Methods: server thread only.
class WebClient {
 public:
  virtual ~WebClient() = default;
  virtual std::uint64_t id() const = 0;
  virtual std::string remote() const = 0;
  /// Queues a text message (sent in order, one write in flight). A client whose
  /// queue passes a bound (it stopped reading) is closed.
  virtual void send(std::shared_ptr<const std::string> text) = 0;
  /// Offers the newest frame: it replaces a frame not yet written, so a slow
  /// client gets fewer frames, never older ones. Returns false if one was replaced.
  virtual bool offer_frame(std::shared_ptr<const std::string> text) = 0;
  /// Calls WebHooks::on_tick at this rate (Hz, > 0) until the client closes.
  virtual void set_tick_hz(double hz) = 0;
  /// Closes the connection (WebSocket close, code 1001).
  virtual void close() = 0;
};

struct WebHooks {
  std::function<void(const std::shared_ptr<WebClient>&)> on_open;
  /// A complete message; binary = it was a binary frame.
  std::function<void(const std::shared_ptr<WebClient>&, std::string_view, bool binary)> on_message;
  std::function<void(const std::shared_ptr<WebClient>&)> on_tick;
  std::function<void(const std::shared_ptr<WebClient>&)> on_close;
  /// An uploaded recording in a temporary file (removed after respond()).
  /// respond(http_status, json_body) may be called from any thread, once.
  std::function<void(const std::filesystem::path& file, const std::string& name,
                     std::function<void(int, std::string)> respond)>
      on_upload;
  /// A file served besides the page's: the file for a request path under
  /// "/mesh/" (the bridge's MeshFiles), or nullopt (HTTP 404).
  std::function<std::optional<std::filesystem::path>(std::string_view path)> on_mesh;
};

class WebServer {
 public:
  /// Binds and listens; throws std::runtime_error naming the address when it cannot.
  WebServer(WebServerConfig cfg, WebHooks hooks);
  ~WebServer();
  WebServer(const WebServer&) = delete;
  WebServer& operator=(const WebServer&) = delete;

  /// The port listened on (the chosen one when the config asked for 0).
  int port() const;
  /// "http://ADDR:PORT/".
  std::string url() const;
  /// Serves on the calling thread, checking should_stop every 100 ms; then
  /// closes every client and returns within about a second.
  void run(const std::function<bool()>& should_stop);
  /// Runs fn on the server thread (thread-safe).
  void post(std::function<void()> fn);

  struct Counters {
    std::uint64_t http_requests = 0, http_errors = 0, ws_opened = 0, ws_closed = 0, too_big = 0;
  };
  Counters counters() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ddswarm::gs::web
