#include "ground_station/web/web_server.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <utility>  // before Boost 1.74's asio: its awaitable.hpp uses std::exchange

#include <atomic>
#include <boost/asio.hpp>
#include <boost/beast.hpp>
#include <deque>
#include <map>

#include "common/config_error.hpp"

namespace ddswarm::gs::web {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace asio = boost::asio;
using tcp = asio::ip::tcp;

namespace {

constexpr std::size_t kMaxWsMessageBytes = 1 << 20;  // above: close with 1009
constexpr std::size_t kMaxQueuedMessages = 1024;     // a client this far behind is not reading
constexpr std::size_t kMaxClients = 64;
constexpr auto kHttpTimeout = std::chrono::seconds(30);
constexpr auto kUploadTimeout = std::chrono::seconds(300);

std::string lower(std::string_view s) {
  std::string o(s);
  for (auto& c : o) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return o;
}

std::optional<std::string> percent_decode(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] != '%') {
      out += s[i];
      continue;
    }
    if (i + 2 >= s.size()) return std::nullopt;
    auto hex = [](char c) -> int {
      if (c >= '0' && c <= '9') return c - '0';
      if (c >= 'a' && c <= 'f') return c - 'a' + 10;
      if (c >= 'A' && c <= 'F') return c - 'A' + 10;
      return -1;
    };
    int hi = hex(s[i + 1]), lo = hex(s[i + 2]);
    if (hi < 0 || lo < 0) return std::nullopt;
    out += static_cast<char>(hi * 16 + lo);
    i += 2;
  }
  return out;
}

std::string_view path_of(std::string_view target) {
  auto q = target.find_first_of("?#");
  return q == std::string_view::npos ? target : target.substr(0, q);
}

/// The value of `key` in the target's query string, decoded ("" if absent).
std::string query_param(std::string_view target, std::string_view key) {
  auto q = target.find('?');
  if (q == std::string_view::npos) return "";
  std::string_view rest = target.substr(q + 1);
  while (!rest.empty()) {
    auto amp = rest.find('&');
    std::string_view kv = rest.substr(0, amp);
    auto eq = kv.find('=');
    if (eq != std::string_view::npos && kv.substr(0, eq) == key) {
      std::string v(kv.substr(eq + 1));
      for (auto& c : v)
        if (c == '+') c = ' ';
      return percent_decode(v).value_or("");
    }
    if (amp == std::string_view::npos) break;
    rest = rest.substr(amp + 1);
  }
  return "";
}

/// Host header names this machine: localhost, 127.x.y.z or [::1], with an optional port.
bool loopback_host(std::string_view host) {
  std::string h = lower(host);
  if (!h.empty() && h[0] == '[') {
    auto close = h.find(']');
    return close != std::string::npos && h.substr(1, close - 1) == "::1";
  }
  h = h.substr(0, h.find(':'));
  if (h == "localhost") return true;
  beast::error_code ec;
  auto a = asio::ip::make_address_v4(h, ec);
  return !ec && a.is_loopback();
}

std::string json_error(std::string_view message) {
  std::string out = "{\"error\":\"";
  for (char c : message) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) < 0x20) c = ' ';
    out += c;
  }
  return out + "\"}";
}

}  // namespace

void WebServerConfig::validate() const {
  beast::error_code ec;
  auto a = asio::ip::make_address(address, ec);
  if (ec) throw FieldError("--web", address, "not an IP address");
  check_range("--web port", port, 0, 65535);
  if (!a.is_loopback() && !allow_remote)
    throw FieldError("--web", address,
                     "not a loopback address; the page can command the swarm, add "
                     "--web-allow-remote to serve other hosts");
  if (max_upload_bytes < (1u << 20))
    throw FieldError("--web-max-upload-mb", std::to_string(max_upload_bytes >> 20), "must be >= 1");
  std::error_code fec;
  if (!std::filesystem::is_directory(web_root, fec))
    throw FieldError("--web-root", web_root.string(), "not a directory");
}

void parse_listen_address(const std::string& text, WebServerConfig& c) {
  std::string addr, port;
  if (!text.empty() && text[0] == '[') {
    auto close = text.find("]:");
    if (close == std::string::npos)
      throw FieldError("--web", text, "expected ADDR:PORT, e.g. 127.0.0.1:8080");
    addr = text.substr(1, close - 1);
    port = text.substr(close + 2);
  } else {
    auto colon = text.rfind(':');
    if (colon == std::string::npos || text.find(':') != colon)
      throw FieldError("--web", text, "expected ADDR:PORT, e.g. 127.0.0.1:8080");
    addr = text.substr(0, colon);
    port = text.substr(colon + 1);
  }
  if (port.empty() || port.size() > 5 ||
      port.find_first_not_of("0123456789") != std::string::npos || std::stoi(port) > 65535)
    throw FieldError("--web", text, "port must be a number in [0, 65535]");
  beast::error_code ec;
  asio::ip::make_address(addr, ec);
  if (ec) throw FieldError("--web", text, "'" + addr + "' is not an IP address");
  c.address = addr;
  c.port = std::stoi(port);
}

std::filesystem::path default_web_root() { return DDSWARM_WEB_ROOT; }

std::optional<std::filesystem::path> resolve_static_path(const std::filesystem::path& root,
                                                         std::string_view target) {
  namespace fs = std::filesystem;
  auto path = percent_decode(path_of(target));
  if (!path || path->empty() || (*path)[0] != '/') return std::nullopt;
  if (path->find('\0') != std::string::npos || path->find('\\') != std::string::npos)
    return std::nullopt;
  std::vector<std::string> seg;
  std::size_t i = 1;
  while (i <= path->size()) {
    auto j = path->find('/', i);
    if (j == std::string::npos) j = path->size();
    std::string s = path->substr(i, j - i);
    if (s == "..") return std::nullopt;
    if (!s.empty() && s[0] == '.' && s != ".") return std::nullopt;  // hidden files
    if (!s.empty() && s != ".") seg.push_back(s);
    i = j + 1;
  }
  fs::path base = root;
  std::size_t first = 0;
  if (seg.size() >= 2 && seg[0] == "vendor" && seg[1] == "three") {
    base = root / "node_modules" / "three";
    first = 2;
  }
  std::error_code ec;
  const fs::path base_canon = fs::canonical(base, ec);
  if (ec) return std::nullopt;
  fs::path p = base_canon;
  for (std::size_t k = first; k < seg.size(); ++k) p /= seg[k];
  if (fs::is_directory(p, ec)) p /= "index.html";
  const fs::path canon = fs::canonical(p, ec);
  if (ec || !fs::is_regular_file(canon, ec)) return std::nullopt;
  auto rel = canon.lexically_relative(base_canon);
  if (rel.empty() || *rel.begin() == "..") return std::nullopt;
  return canon;
}

std::string mime_type(const std::filesystem::path& file) {
  static const std::map<std::string, std::string> types = {
      {".html", "text/html; charset=utf-8"},
      {".htm", "text/html; charset=utf-8"},
      {".js", "text/javascript; charset=utf-8"},
      {".mjs", "text/javascript; charset=utf-8"},
      {".css", "text/css; charset=utf-8"},
      {".json", "application/json"},
      {".map", "application/json"},
      {".svg", "image/svg+xml"},
      {".png", "image/png"},
      {".jpg", "image/jpeg"},
      {".jpeg", "image/jpeg"},
      {".gif", "image/gif"},
      {".ico", "image/x-icon"},
      {".webp", "image/webp"},
      {".wasm", "application/wasm"},
      {".txt", "text/plain; charset=utf-8"},
      {".md", "text/plain; charset=utf-8"},
      {".glb", "model/gltf-binary"},
      {".gltf", "model/gltf+json"},
      {".obj", "text/plain; charset=utf-8"},
      {".stl", "model/stl"},
      {".woff2", "font/woff2"},
      {".ktx2", "image/ktx2"},
      {".hdr", "application/octet-stream"},
  };
  auto it = types.find(lower(file.extension().string()));
  return it == types.end() ? "application/octet-stream" : it->second;
}

bool same_origin(std::string_view origin, std::string_view host) {
  if (origin.empty()) return true;  // not a browser: nothing to protect from
  std::string o = lower(origin);
  for (const char* scheme : {"http://", "https://"}) {
    if (o.rfind(scheme, 0) == 0) {
      std::string rest = o.substr(std::string_view(scheme).size());
      while (!rest.empty() && rest.back() == '/') rest.pop_back();
      return !rest.empty() && rest == lower(host);
    }
  }
  return false;  // "null" and anything else
}

// ---------------------------------------------------------------------------

class WsSession;

// What the sessions share (the server's thread only, apart from the counters).
struct ServerCore {
  WebServerConfig cfg;
  WebHooks hooks;
  asio::io_context io{1};
  tcp::acceptor acceptor{io};
  std::filesystem::path root;
  std::map<std::uint64_t, std::weak_ptr<WsSession>> clients;
  std::uint64_t next_id = 1;
  int uploads = 0;
  bool stopping = false;
  struct {
    std::atomic<std::uint64_t> http_requests{0}, http_errors{0}, ws_opened{0}, ws_closed{0},
        too_big{0};
  } n;
};

struct WebServer::Impl : ServerCore {
  void accept();
  void shutdown();
};

class WsSession final : public WebClient, public std::enable_shared_from_this<WsSession> {
 public:
  WsSession(ServerCore& srv, tcp::socket&& s, std::uint64_t id)
      : srv_(srv), ws_(std::move(s)), tick_(srv.io), id_(id) {
    beast::error_code ec;
    auto ep = beast::get_lowest_layer(ws_).socket().remote_endpoint(ec);
    remote_ = ec ? "?" : ep.address().to_string() + ":" + std::to_string(ep.port());
  }

  void start(http::request<http::empty_body> req) {
    ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    ws_.read_message_max(kMaxWsMessageBytes);
    ws_.text(true);
    beast::get_lowest_layer(ws_).expires_never();
    ws_.async_accept(req, [self = shared_from_this()](beast::error_code ec) {
      if (ec) return self->finish();
      self->opened_ = true;
      self->srv_.n.ws_opened++;
      self->srv_.clients[self->id_] = self;
      if (self->srv_.hooks.on_open) self->srv_.hooks.on_open(self);
      self->schedule_tick(std::chrono::steady_clock::now());
      self->read();
    });
  }

  std::uint64_t id() const override { return id_; }
  std::string remote() const override { return remote_; }

  void send(std::shared_ptr<const std::string> text) override {
    if (finished_ || closing_) return;
    queue_.push_back(std::move(text));
    if (queue_.size() > kMaxQueuedMessages) return close();
    write();
  }

  bool offer_frame(std::shared_ptr<const std::string> text) override {
    if (finished_ || closing_) return true;
    const bool replaced = frame_ != nullptr;
    frame_ = std::move(text);
    write();
    return !replaced;
  }

  void set_tick_hz(double hz) override {
    if (hz > 0) period_ = std::chrono::duration<double>(1.0 / hz);
  }

  void close() override {
    if (finished_ || closing_) return;
    closing_ = true;
    queue_.clear();
    frame_.reset();
    if (!writing_) start_close();
  }

  /// Ends the session: stops its timer and tells the bridge (idempotent).
  void finish() {
    if (finished_) return;
    finished_ = true;
    tick_.cancel();
    beast::error_code ig;
    beast::get_lowest_layer(ws_).socket().close(ig);
    if (!opened_) return;
    srv_.clients.erase(id_);
    srv_.n.ws_closed++;
    if (srv_.hooks.on_close) srv_.hooks.on_close(shared_from_this());
  }

 private:
  void read() {
    ws_.async_read(buf_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec) {
        if (ec == websocket::error::message_too_big) self->srv_.n.too_big++;
        return self->finish();
      }
      if (self->finished_) return;
      const auto data = self->buf_.cdata();
      std::string_view text(static_cast<const char*>(data.data()), data.size());
      if (self->srv_.hooks.on_message)
        self->srv_.hooks.on_message(self, text, !self->ws_.got_text());
      self->buf_.consume(self->buf_.size());
      self->read();
    });
  }

  void write() {
    if (writing_ || finished_) return;
    if (closing_) return start_close();
    if (!queue_.empty()) {
      current_ = std::move(queue_.front());
      queue_.pop_front();
    } else if (frame_) {
      current_ = std::move(frame_);
      frame_.reset();
    } else {
      return;
    }
    writing_ = true;
    ws_.async_write(asio::buffer(*current_),
                    [self = shared_from_this()](beast::error_code ec, std::size_t) {
                      self->writing_ = false;
                      self->current_.reset();
                      if (ec) return self->finish();
                      self->write();
                    });
  }

  void start_close() {
    if (close_started_ || finished_) return;
    close_started_ = true;
    ws_.async_close(websocket::close_code::going_away,
                    [self = shared_from_this()](beast::error_code) { self->finish(); });
  }

  void schedule_tick(std::chrono::steady_clock::time_point last) {
    auto next = last + std::chrono::duration_cast<std::chrono::steady_clock::duration>(period_);
    const auto now = std::chrono::steady_clock::now();
    if (next < now) next = now;  // fell behind: do not burst
    tick_.expires_at(next);
    tick_.async_wait([self = shared_from_this(), next](beast::error_code ec) {
      if (ec || self->finished_ || self->closing_) return;
      if (self->srv_.hooks.on_tick) self->srv_.hooks.on_tick(self);
      self->schedule_tick(next);
    });
  }

  ServerCore& srv_;
  websocket::stream<beast::tcp_stream> ws_;
  beast::flat_buffer buf_;
  asio::steady_timer tick_;
  std::chrono::duration<double> period_{1.0 / 30};
  std::uint64_t id_;
  std::string remote_;
  std::deque<std::shared_ptr<const std::string>> queue_;
  std::shared_ptr<const std::string> frame_, current_;
  bool writing_ = false, closing_ = false, close_started_ = false, finished_ = false,
       opened_ = false;
};

class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(ServerCore& srv, tcp::socket&& s) : srv_(srv), stream_(std::move(s)) {}

  void read() {
    header_.emplace();
    header_->header_limit(16 * 1024);
    // The header parser enforces its own body limit (1 MiB by default) when it
    // reads Content-Length: let uploads through to our --web-max-upload-mb check.
    header_->body_limit(srv_.cfg.max_upload_bytes);
    stream_.expires_after(kHttpTimeout);
    http::async_read_header(stream_, buf_, *header_,
                            [self = shared_from_this()](beast::error_code ec, std::size_t) {
                              if (ec) return self->close();
                              self->srv_.n.http_requests++;
                              self->route();
                            });
  }

 private:
  using Request = http::request<http::empty_body>;

  void route() {
    const Request& req = header_->get();
    const std::string target(req.target());
    const std::string_view path = path_of(target);
    version_ = req.version();
    api_ = path.rfind("/api/", 0) == 0;
    const std::string origin(req[http::field::origin]);
    const std::string host(req[http::field::host]);
    const bool trusted =
        same_origin(origin, host) && (srv_.cfg.allow_remote || loopback_host(host));

    if (websocket::is_upgrade(req)) {
      if (path != "/ws") return error(http::status::not_found, "no WebSocket here; use /ws");
      if (!trusted) return error(http::status::forbidden, "cross-origin WebSocket refused");
      if (srv_.clients.size() >= kMaxClients)
        return error(http::status::service_unavailable, "too many clients");
      if (srv_.stopping) return error(http::status::service_unavailable, "shutting down");
      auto ws = std::make_shared<WsSession>(srv_, stream_.release_socket(), srv_.next_id++);
      ws->start(header_->release());
      return;
    }
    if (path == "/api/recording") {
      if (req.method() != http::verb::post)
        return error(http::status::method_not_allowed, "POST a recording here");
      if (!trusted) return error(http::status::forbidden, "cross-origin upload refused");
      return upload(target);
    }
    if (!header_->is_done()) return error(http::status::bad_request, "unexpected request body");
    if (req.method() != http::verb::get && req.method() != http::verb::head)
      return error(http::status::method_not_allowed, "only GET and HEAD");
    auto file = path.rfind("/mesh/", 0) == 0
                    ? (srv_.hooks.on_mesh ? srv_.hooks.on_mesh(path) : std::nullopt)
                    : resolve_static_path(srv_.root, target);
    if (!file) return error(http::status::not_found, "not found");
    beast::error_code ec;
    http::file_body::value_type body;
    body.open(file->c_str(), beast::file_mode::scan, ec);
    if (ec) return error(http::status::not_found, "not found");
    const auto size = body.size();
    const bool keep = req.keep_alive();
    const unsigned version = req.version();
    const std::string type = mime_type(*file);
    if (req.method() == http::verb::head) {
      http::response<http::empty_body> res{http::status::ok, version};
      headers(res, type, keep);
      res.content_length(size);
      return respond(std::move(res));
    }
    http::response<http::file_body> res{std::piecewise_construct, std::make_tuple(std::move(body)),
                                        std::make_tuple(http::status::ok, version)};
    headers(res, type, keep);
    res.content_length(size);
    respond(std::move(res));
  }

  template <class R>
  static void headers(R& res, const std::string& type, bool keep) {
    res.set(http::field::server, "ddswarm-gs");
    res.set(http::field::content_type, type);
    res.set(http::field::cache_control, "no-cache");
    res.set("X-Content-Type-Options", "nosniff");
    res.keep_alive(keep);
  }

  void upload(const std::string& target) {
    if (srv_.uploads > 0)
      return error(http::status::service_unavailable, "another recording is being read; try again");
    if (auto len = header_->content_length(); len && *len > srv_.cfg.max_upload_bytes)
      return error(http::status::payload_too_large, too_big_message());
    std::string name = query_param(target, "name");
    name = std::filesystem::path(name).filename().string();
    if (name.empty() || name.size() > 128) name = "recording.mcap";
    char tmpl[] = "/tmp/ddswarm-web-upload-XXXXXX";
    int fd = mkstemp(tmpl);
    if (fd < 0) return error(http::status::internal_server_error, "cannot create a temporary file");
    ::close(fd);
    file_ = tmpl;
    body_.emplace(std::move(*header_));
    body_->body_limit(srv_.cfg.max_upload_bytes);
    beast::error_code ec;
    body_->get().body().open(file_.c_str(), beast::file_mode::write, ec);
    if (ec) {
      remove_file();
      return error(http::status::internal_server_error, "cannot write a temporary file");
    }
    srv_.uploads++;
    stream_.expires_after(kUploadTimeout);
    http::async_read(
        stream_, buf_, *body_,
        [self = shared_from_this(), name](beast::error_code ec, std::size_t) {
          self->body_->get().body().close();
          if (ec) {
            self->srv_.uploads--;
            self->remove_file();
            if (ec == http::error::body_limit)
              return self->error(http::status::payload_too_large, self->too_big_message());
            return self->close();
          }
          const bool keep = self->body_->get().keep_alive();
          const unsigned version = self->body_->get().version();
          auto respond = [self, keep, version](int status, std::string json) {
            asio::post(
                self->srv_.io, [self, keep, version, status, json = std::move(json)]() mutable {
                  self->srv_.uploads--;
                  self->remove_file();
                  http::response<http::string_body> res{static_cast<http::status>(status), version};
                  headers(res, "application/json", keep);
                  res.body() = std::move(json);
                  res.prepare_payload();
                  self->respond(std::move(res));
                });
          };
          if (!self->srv_.hooks.on_upload)
            return respond(500, json_error("uploads are not handled"));
          self->srv_.hooks.on_upload(self->file_, name, std::move(respond));
        });
  }

  std::string too_big_message() const {
    return "recording over the " + std::to_string(srv_.cfg.max_upload_bytes >> 20) +
           " MiB limit (--web-max-upload-mb)";
  }

  void remove_file() {
    if (file_.empty()) return;
    std::error_code ec;
    std::filesystem::remove(file_, ec);
    file_.clear();
  }

  void error(http::status status, std::string_view message) {
    srv_.n.http_errors++;
    http::response<http::string_body> res{status, version_};
    headers(res, api_ ? "application/json" : "text/plain; charset=utf-8", false);
    res.body() = api_ ? json_error(message) : std::string(message) + "\n";
    res.prepare_payload();
    respond(std::move(res));
  }

  template <class Body>
  void respond(http::response<Body>&& res) {
    auto sp = std::make_shared<http::response<Body>>(std::move(res));
    stream_.expires_after(kHttpTimeout);
    http::async_write(stream_, *sp,
                      [self = shared_from_this(), sp](beast::error_code ec, std::size_t) {
                        if (ec || !sp->keep_alive()) return self->close();
                        self->read();
                      });
  }

  void close() {
    remove_file();
    beast::error_code ig;
    stream_.socket().shutdown(tcp::socket::shutdown_send, ig);
  }

  ServerCore& srv_;
  beast::tcp_stream stream_;
  beast::flat_buffer buf_;
  std::optional<http::request_parser<http::empty_body>> header_;
  std::optional<http::request_parser<http::file_body>> body_;
  std::string file_;
  unsigned version_ = 11;
  bool api_ = false;
};

void WebServer::Impl::accept() {
  acceptor.async_accept([this](beast::error_code ec, tcp::socket s) {
    if (stopping) return;
    if (!ec) std::make_shared<HttpSession>(*this, std::move(s))->read();
    accept();
  });
}

void WebServer::Impl::shutdown() {
  stopping = true;
  beast::error_code ig;
  acceptor.close(ig);
  auto copy = clients;
  for (auto& [id, w] : copy)
    if (auto c = w.lock()) c->close();
}

WebServer::WebServer(WebServerConfig cfg, WebHooks hooks) : impl_(std::make_unique<Impl>()) {
  cfg.validate();
  impl_->cfg = cfg;
  impl_->hooks = std::move(hooks);
  impl_->root = std::filesystem::canonical(cfg.web_root);
  const std::string where = cfg.address + ":" + std::to_string(cfg.port);
  beast::error_code ec;
  tcp::endpoint ep(asio::ip::make_address(cfg.address), static_cast<unsigned short>(cfg.port));
  auto& a = impl_->acceptor;
  a.open(ep.protocol(), ec);
  if (!ec) a.set_option(asio::socket_base::reuse_address(true), ec);
  if (!ec) a.bind(ep, ec);
  if (!ec) a.listen(asio::socket_base::max_listen_connections, ec);
  if (ec) throw std::runtime_error("cannot listen on " + where + ": " + ec.message());
  impl_->accept();
}

WebServer::~WebServer() = default;

int WebServer::port() const { return impl_->acceptor.local_endpoint().port(); }

std::string WebServer::url() const {
  const auto ep = impl_->acceptor.local_endpoint();
  const std::string host =
      ep.address().is_v6() ? "[" + ep.address().to_string() + "]" : ep.address().to_string();
  return "http://" + host + ":" + std::to_string(ep.port()) + "/";
}

void WebServer::run(const std::function<bool()>& should_stop) {
  auto& io = impl_->io;
  asio::steady_timer check(io), deadline(io);
  std::function<void()> arm = [&] {
    check.expires_after(std::chrono::milliseconds(100));
    check.async_wait([&](beast::error_code ec) {
      if (ec) return;
      if (!should_stop()) return arm();
      impl_->shutdown();
      deadline.expires_after(std::chrono::seconds(1));
      deadline.async_wait([&](beast::error_code) { io.stop(); });
    });
  };
  arm();
  io.run();
  // Whatever did not close in time: tell the bridge, so nothing outlives the io_context.
  auto copy = impl_->clients;
  for (auto& [id, w] : copy)
    if (auto c = w.lock()) c->finish();
}

void WebServer::post(std::function<void()> fn) { asio::post(impl_->io, std::move(fn)); }

WebServer::Counters WebServer::counters() const {
  return {impl_->n.http_requests, impl_->n.http_errors, impl_->n.ws_opened, impl_->n.ws_closed,
          impl_->n.too_big};
}

}  // namespace ddswarm::gs::web
