// web_client: a scripted WebSocket/HTTP client for the web bridge's
// multi-process test (tests/web_bridge_test.sh), standing in for a browser.
//
//   web_client get PORT TARGET                 prints the HTTP status code
//   web_client upload PORT FILE NAME           POSTs FILE to /api/recording, prints the JSON answer
//   web_client ws PORT STEP...                 one WebSocket connection, steps in order:
//     type=T          read until a message of type T (printed, shortened)
//     drones=N        read until a frame with N drones, all positions finite
//     airborne=N      read until a frame with at least N drones flagged airborne (bit 1) and z >
//     0.2 m frames=N        read N more frames; live frames must have increasing ticks send=JSON
//     send a text message binary          send a binary message big=BYTES       send a text message
//     of BYTES bytes ack=ID:ok|fail  read until the ack for command ID, check ok error=TEXT read
//     until an error whose message contains TEXT replay-t=A:B    read until a frame whose t lies in
//     [A, B] (sim s; A or B may be empty) replay=KEY:VAL  read until a replay message whose KEY
//     dumps as VAL (e.g. playing:false) abort           drop the TCP connection without a WebSocket
//     close, exit 0 close           WebSocket close
// Exits 1 on a failed check, 3 on --timeout (default 60 s, env WEB_CLIENT_TIMEOUT).
#include <utility>  // before Boost 1.74's asio (std::exchange)

#include <boost/asio.hpp>
#include <boost/beast.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
namespace asio = boost::asio;
using tcp = asio::ip::tcp;
using nlohmann::json;

namespace {

[[noreturn]] void fail(const std::string& what) {
  std::fprintf(stderr, "web_client: FAIL: %s\n", what.c_str());
  std::exit(1);
}

std::string shorten(const std::string& s, std::size_t n = 200) {
  return s.size() > n ? s.substr(0, n) + "..." : s;
}

tcp::socket connect(asio::io_context& io, const std::string& port) {
  tcp::socket s(io);
  s.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"),
                          static_cast<unsigned short>(std::stoi(port))));
  return s;
}

int do_get(const std::string& port, const std::string& target) {
  asio::io_context io;
  beast::tcp_stream stream(connect(io, port));
  http::request<http::empty_body> req{http::verb::get, target, 11};
  req.set(http::field::host, "127.0.0.1:" + port);
  http::write(stream, req);
  beast::flat_buffer buf;
  http::response<http::string_body> res;
  http::read(stream, buf, res);
  std::printf("%d %s\n", res.result_int(), std::string(res[http::field::content_type]).c_str());
  return 0;
}

int do_upload(const std::string& port, const std::string& file, const std::string& name) {
  std::ifstream in(file, std::ios::binary);
  if (!in) fail("cannot read " + file);
  std::stringstream ss;
  ss << in.rdbuf();
  asio::io_context io;
  beast::tcp_stream stream(connect(io, port));
  http::request<http::string_body> req{http::verb::post, "/api/recording?name=" + name, 11};
  req.set(http::field::host, "127.0.0.1:" + port);
  req.set(http::field::origin, "http://127.0.0.1:" + port);
  req.body() = ss.str();
  req.prepare_payload();
  http::write(stream, req);
  beast::flat_buffer buf;
  http::response_parser<http::string_body> parser;
  parser.body_limit(1 << 20);
  http::read(stream, buf, parser);
  std::printf("%s\n", parser.get().body().c_str());
  return parser.get().result_int() == 200 ? 0 : 1;
}

class Session {
 public:
  Session(asio::io_context& io, const std::string& port) : ws_(connect(io, port)) {
    ws_.handshake("127.0.0.1:" + port, "/ws");
    ws_.read_message_max(64 << 20);
  }

  json next() {
    beast::flat_buffer buf;
    ws_.read(buf);
    json j = json::parse(beast::buffers_to_string(buf.data()));
    const std::string type = j.value("type", "?");
    ++seen_[type];
    if (type == "error") std::printf("  error: %s\n", j["message"].get<std::string>().c_str());
    return j;
  }

  template <class Pred>
  json until(const std::string& type, Pred pred) {
    for (;;) {
      json j = next();
      if (j.value("type", "") == type && pred(j)) return j;
    }
  }

  void step(const std::string& s) {
    const auto eq = s.find('=');
    const std::string key = s.substr(0, eq), val = eq == std::string::npos ? "" : s.substr(eq + 1);
    std::printf("step %s\n", shorten(s, 120).c_str());
    std::fflush(stdout);
    if (key == "type") {
      json j = until(val, [](const json&) { return true; });
      std::printf("  %s\n", shorten(j.dump()).c_str());
    } else if (key == "drones") {
      const std::size_t n = std::stoul(val);
      json f = until("frame", [&](const json& j) { return j["drones"].size() == n; });
      for (const auto& d : f["drones"])
        for (const auto& x : d["p"])
          if (!x.is_number()) fail("a position is not a number: " + shorten(d.dump()));
      std::printf("  frame tick %llu with %zu drones\n", f["tick"].get<unsigned long long>(), n);
    } else if (key == "airborne") {
      const int n = std::stoi(val);
      json f = until("frame", [&](const json& j) {
        int up = 0;
        for (const auto& d : j["drones"])
          if ((d["flags"].get<int>() & 1) && d["p"][2].get<double>() > 0.2) ++up;
        return up >= n;
      });
      std::printf("  tick %llu: %d drones airborne, drone 0 at z %.2f m\n",
                  f["tick"].get<unsigned long long>(), n, f["drones"][0]["p"][2].get<double>());
    } else if (key == "frames") {
      const int n = std::stoi(val);
      long long last = -1;
      for (int i = 0; i < n; ++i) {
        json f = until("frame", [](const json&) { return true; });
        const long long tick = f["tick"].get<long long>();
        if (live_ && tick <= last)
          fail("frame tick went from " + std::to_string(last) + " to " + std::to_string(tick));
        last = tick;
      }
      std::printf("  %d frames, last tick %lld\n", n, last);
    } else if (key == "send") {
      ws_.text(true);
      ws_.write(asio::buffer(val));
      if (val.find("\"open\"") != std::string::npos) live_ = false;
      if (val.find("\"live\"") != std::string::npos) live_ = true;
    } else if (key == "binary") {
      ws_.binary(true);
      const std::string bytes = "\x01\x02\x03binary";
      ws_.write(asio::buffer(bytes));
    } else if (key == "big") {
      ws_.text(true);
      std::string text = R"({"type":"live","pad":")" + std::string(std::stoul(val), 'x') + "\"}";
      ws_.write(asio::buffer(text));
    } else if (key == "ack") {
      const auto colon = val.find(':');
      const long long id = std::stoll(val.substr(0, colon));
      const bool want_ok = val.substr(colon + 1) == "ok";
      json a = until("ack", [&](const json& j) { return j["id"].get<long long>() == id; });
      std::printf("  ack %lld: %s %s\n", id, a["ok"].get<bool>() ? "ok" : "FAILED",
                  a["message"].get<std::string>().c_str());
      if (a["ok"].get<bool>() != want_ok)
        fail("ack " + std::to_string(id) + " ok != " + (want_ok ? "true" : "false"));
    } else if (key == "error") {
      until("error", [&](const json& j) {
        return j["message"].get<std::string>().find(val) != std::string::npos;
      });
    } else if (key == "replay-t") {
      const auto colon = val.find(':');
      const std::string a = val.substr(0, colon), b = val.substr(colon + 1);
      const double lo = a.empty() ? -1e300 : std::stod(a), hi = b.empty() ? 1e300 : std::stod(b);
      json f = until("frame", [&](const json& j) {
        return j["t"].get<double>() >= lo && j["t"].get<double>() <= hi;
      });
      std::printf("  frame t %.3f s, %zu drones\n", f["t"].get<double>(), f["drones"].size());
    } else if (key == "replay") {
      const auto colon = val.find(':');
      const std::string k = val.substr(0, colon), v = val.substr(colon + 1);
      json r = until("replay", [&](const json& j) { return j.contains(k) && j[k].dump() == v; });
      std::printf("  %s\n", shorten(r.dump()).c_str());
    } else if (key == "abort") {
      beast::get_lowest_layer(ws_).close();  // no close frame: a browser tab killed mid-stream
      report();
      std::exit(0);
    } else if (key == "close") {
      ws_.close(websocket::close_code::normal);
    } else {
      fail("unknown step " + s);
    }
  }

  void report() const {
    std::printf("received:");
    for (const auto& [t, n] : seen_) std::printf(" %s %d", t.c_str(), n);
    std::printf("\n");
  }

 private:
  websocket::stream<tcp::socket> ws_;
  std::map<std::string, int> seen_;
  bool live_ = true;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: web_client get|upload|ws PORT ARGS... (see the source)\n");
    return 2;
  }
  const char* env = std::getenv("WEB_CLIENT_TIMEOUT");
  const double timeout_s = env ? std::atof(env) : 60;
  std::thread([timeout_s] {
    std::this_thread::sleep_for(std::chrono::duration<double>(timeout_s));
    std::fprintf(stderr, "web_client: FAIL: timeout after %.0f s\n", timeout_s);
    std::fflush(stdout);
    std::_Exit(3);
  }).detach();
  try {
    const std::string mode = argv[1], port = argv[2];
    if (mode == "get") return do_get(port, argv[3]);
    if (mode == "upload") return do_upload(port, argv[3], argc > 4 ? argv[4] : "recording.mcap");
    if (mode != "ws") fail("unknown mode " + mode);
    asio::io_context io;
    Session s(io, port);
    for (int i = 3; i < argc; ++i) s.step(argv[i]);
    s.report();
    std::fflush(stdout);
    return 0;
  } catch (const std::exception& e) {
    fail(e.what());
  }
}
