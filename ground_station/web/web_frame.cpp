#include "ground_station/web/web_frame.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

#include "common/convert.hpp"
#include "common/mission.hpp"
#include "common/swarm_state_cdr.hpp"

namespace ddswarm::gs::web {

using nlohmann::json;

namespace {

// ---- frame: written by hand (it is the hot path, ~25 numbers per drone) ----

/// Appends x rounded to `decimals`, without trailing zeros; null if not finite.
void put_num(std::string& out, double x, int decimals) {
  if (!std::isfinite(x)) {
    out += "null";
    return;
  }
  char buf[64];
  std::to_chars_result r;
  if (std::fabs(x) < 1e15) {
    r = std::to_chars(buf, buf + sizeof buf, x, std::chars_format::fixed, decimals);
  } else {
    r = std::to_chars(buf, buf + sizeof buf, x, std::chars_format::general, 17);
    out.append(buf, r.ptr);
    return;
  }
  char* end = r.ptr;
  if (decimals > 0) {
    while (end[-1] == '0') --end;
    if (end[-1] == '.') --end;
  }
  if (end - buf == 2 && buf[0] == '-' && buf[1] == '0') {  // "-0" after rounding
    out += '0';
    return;
  }
  out.append(buf, end);
}

void put_uint(std::string& out, std::uint64_t x) {
  char buf[24];
  auto r = std::to_chars(buf, buf + sizeof buf, x);
  out.append(buf, r.ptr);
}

template <std::size_t N, class T>
void put_array(std::string& out, const std::array<T, N>& a, int decimals) {
  out += '[';
  for (std::size_t i = 0; i < N; ++i) {
    if (i) out += ',';
    put_num(out, a[i], decimals);
  }
  out += ']';
}

const char* task_state(std::uint8_t phase) {
  switch (phase) {
    case msg::TASK_NONE:
      return "none";
    case msg::TASK_RUNNING:
      return "running";
    case msg::TASK_COMPLETE:
      return "complete";
    case msg::TASK_FAILED:
      return "failed";
  }
  return "unknown";
}

const char* contact_kind(std::uint8_t kind) {
  switch (kind) {
    case msg::CONTACT_OBSTACLE:
      return "obstacle";
    case msg::CONTACT_DRONE:
      return "drone";
    case msg::CONTACT_GROUND:
      return "ground";
  }
  return "unknown";
}

json vec(const msg::Vec3& v) { return json::array({v.x(), v.y(), v.z()}); }
json vec(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }
json vec(const Eigen::Vector2d& v) { return json::array({v.x(), v.y(), 0.0}); }

/// nlohmann writes NaN/inf as null; doubles that are finite keep full precision.
std::string dump(const json& j) { return j.dump(-1, ' ', false, json::error_handler_t::replace); }

}  // namespace

Frame to_frame(const msg::SwarmState& s) {
  Frame f;
  f.tick = s.tick();
  f.t = s.sim_time_s();
  f.drones.resize(s.drones().size());
  for (std::size_t i = 0; i < s.drones().size(); ++i) {
    const auto& d = s.drones()[i];
    auto& o = f.drones[i];
    o.id = d.drone_id();
    o.p = {float(d.position().x()), float(d.position().y()), float(d.position().z())};
    o.q = {float(d.orientation().w()), float(d.orientation().x()), float(d.orientation().y()),
           float(d.orientation().z())};
    o.v = {float(d.velocity().x()), float(d.velocity().y()), float(d.velocity().z())};
    o.w = d.motor_speed_rad_s();
    o.flags = d.flags();
    o.phase = d.phase();
    o.col = {d.collisions_obstacle(), d.collisions_drone(), d.collisions_ground()};
  }
  for (const auto& sc : s.scans()) {
    if (sc.drone_id() >= f.drones.size() || !scan_problem(sc).empty()) continue;
    auto& o = f.drones[sc.drone_id()];
    o.ray_angle = sc.angle_body_rad();
    o.ray_elevation = sc.elevation_body_rad();
    o.ray_range = sc.range_m();
    o.ray_hit = sc.hit();
  }
  return f;
}

std::vector<double> nearest_distances(const std::vector<Eigen::Vector3d>& pos) {
  const std::size_t n = pos.size();
  std::vector<double> best(n, std::numeric_limits<double>::infinity());
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) {
      const double d2 = (pos[i] - pos[j]).squaredNorm();
      if (d2 < best[i]) best[i] = d2;
      if (d2 < best[j]) best[j] = d2;
    }
  for (auto& b : best) b = std::isfinite(b) ? std::sqrt(b) : std::nan("");
  return best;
}

std::string encode_frame(const Frame& f, bool rays) {
  std::vector<Eigen::Vector3d> pos(f.drones.size());
  for (std::size_t i = 0; i < f.drones.size(); ++i)
    pos[i] = Eigen::Vector3d(f.drones[i].p[0], f.drones[i].p[1], f.drones[i].p[2]);
  const auto nearest = nearest_distances(pos);

  std::string out;
  out.reserve(64 + f.drones.size() * (rays ? 400 : 220));
  out += R"({"type":"frame","tick":)";
  put_uint(out, f.tick);
  out += R"(,"t":)";
  put_num(out, f.t, 6);
  out += R"(,"drones":[)";
  for (std::size_t i = 0; i < f.drones.size(); ++i) {
    const auto& d = f.drones[i];
    if (i) out += ',';
    out += R"({"id":)";
    put_uint(out, static_cast<std::uint64_t>(d.id));
    out += R"(,"p":)";
    put_array(out, d.p, 4);
    out += R"(,"q":)";
    put_array(out, d.q, 6);
    out += R"(,"v":)";
    put_array(out, d.v, 3);
    out += R"(,"w":)";
    put_array(out, d.w, 1);
    out += R"(,"flags":)";
    put_uint(out, d.flags);
    out += R"(,"phase":")";
    out += to_string(static_cast<Phase>(d.phase));
    out += R"(","col":[)";
    put_uint(out, d.col[0]);
    out += ',';
    put_uint(out, d.col[1]);
    out += ',';
    put_uint(out, d.col[2]);
    out += R"(],"nearest":)";
    put_num(out, nearest[i], 3);
    out += '}';
  }
  out += ']';
  if (rays) {
    out += R"(,"rays":[)";
    for (std::size_t i = 0; i < f.drones.size(); ++i) {
      const auto& d = f.drones[i];
      if (i) out += ',';
      out += R"({"a":[)";
      for (std::size_t k = 0; k < d.ray_angle.size(); ++k) {
        if (k) out += ',';
        put_num(out, d.ray_angle[k], 4);
      }
      out += R"(],"e":[)";
      for (std::size_t k = 0; k < d.ray_elevation.size(); ++k) {
        if (k) out += ',';
        put_num(out, d.ray_elevation[k], 4);
      }
      out += R"(],"r":[)";
      for (std::size_t k = 0; k < d.ray_range.size(); ++k) {
        if (k) out += ',';
        put_num(out, d.ray_range[k], 3);
      }
      out += R"(],"hit":[)";
      for (std::size_t k = 0; k < d.ray_hit.size(); ++k) {
        if (k) out += ',';
        out += d.ray_hit[k] ? '1' : '0';
      }
      out += "]}";
    }
    out += ']';
  }
  out += '}';
  return out;
}

std::string encode_hello(std::string_view source, std::string_view gs_name) {
  return dump(
      {{"type", "hello"}, {"version", kProtocolVersion}, {"source", source}, {"gs_name", gs_name}});
}

std::string encode_scene(const msg::Scene& s, const std::vector<MeshUrl>& mesh_urls) {
  const SceneConfig world = from_msg(s);
  json cyl = json::array(), box = json::array(), meshes = json::array();
  for (std::size_t i = 0; i < world.meshes.size(); ++i) {
    const MeshObstacle& m = world.meshes[i];
    const Eigen::Quaterniond q(m.rotation());
    const bool served = i < mesh_urls.size() && !mesh_urls[i].url.empty();
    meshes.push_back({{"file", m.file},
                      {"url", served ? json(mesh_urls[i].url) : json(nullptr)},
                      {"why", served                 ? ""
                              : i < mesh_urls.size() ? mesh_urls[i].why
                                                     : "not offered"},
                      {"p", vec(m.position)},
                      {"q", json::array({q.w(), q.x(), q.y(), q.z()})},
                      {"scale", m.scale},
                      {"bounds_min", vec(m.bounds_min)},
                      {"bounds_max", vec(m.bounds_max)},
                      {"triangles", m.triangle_count}});
  }
  const auto& w = s.wind();
  for (const auto& c : world.cylinders)
    cyl.push_back(
        {{"x", c.center_xy.x()}, {"y", c.center_xy.y()}, {"r", c.radius_m}, {"h", c.height_m}});
  for (const auto& b : world.boxes)
    box.push_back({{"c", vec(b.center)}, {"s", vec(b.size)}, {"yaw", b.yaw_rad}});
  return dump({{"type", "scene"},
               {"name", s.name().to_string()},
               {"seed", s.seed()},
               {"num_drones", s.num_drones()},
               {"mode", s.mode() == msg::MODE_LOCKSTEP ? "lockstep" : "realtime"},
               {"ground_z", world.ground_z_m},
               {"cylinders", std::move(cyl)},
               {"boxes", std::move(box)},
               {"meshes", std::move(meshes)},
               {"wind",
                {{"steady", vec(w.steady_mps())},
                 {"turbulence", w.turbulence()},
                 {"sigma", vec(w.turbulence_sigma_mps())},
                 {"gusts_per_minute", w.gusts_per_minute()},
                 {"gust_max", w.gust_max_mps()}}},
               {"bounds_min", vec(world.bounds_min)},
               {"bounds_max", vec(world.bounds_max)},
               {"finish_a", vec(world.finish_a)},
               {"finish_b", vec(world.finish_b)},
               {"goal", vec(world.goal_xy)},
               {"drone_radius", s.drone_radius_m()},
               {"arm_length", s.arm_length_m()},
               {"sensor_count", s.sensor_count()},
               {"sensor_range", s.sensor_max_range_m()}});
}

std::string encode_status(const msg::SimStatus& s) {
  const std::uint64_t rejected = std::uint64_t{s.rejected_non_finite()} + s.rejected_absurd() +
                                 s.rejected_unknown_id() + s.rejected_stale_tick() +
                                 s.rejected_future_tick() + s.rejected_impostor() +
                                 s.rejected_mission();
  return dump(
      {{"type", "status"},
       {"tick", s.tick()},
       {"t", s.sim_time_s()},
       {"rtf", s.real_time_factor()},
       {"state", s.state().to_string()},
       {"mode", s.mode() == msg::MODE_LOCKSTEP ? "lockstep" : "realtime"},
       {"num_drones", s.num_drones()},
       {"agents_live", s.agents_live()},
       {"live", s.live_agents()},
       {"airborne", s.airborne()},
       {"failsafe", s.failsafe()},
       {"collisions", {s.collisions_obstacle(), s.collisions_drone(), s.collisions_ground()}},
       {"rejected", rejected}});
}

std::string encode_task(const msg::TaskStatus& t) {
  const char* state = task_state(t.phase());
  return dump(
      {{"type", "task"},
       {"state", state},
       {"phase", state},
       {"elapsed", t.elapsed_s()},
       {"reason", t.reason().to_string()},
       {"speed", t.speed_mps()},
       {"epsilon", t.epsilon_m()},
       {"drones", t.drones()},
       {"past_finish", t.past_finish()},
       {"max_pair", t.max_pair_distance_m()},
       {"min_inter_drone", t.min_inter_drone_m()},
       {"min_clearance", t.min_clearance_m()},
       {"collisions", {t.collisions_obstacle(), t.collisions_drone(), t.collisions_ground()}}});
}

std::string encode_collision(const msg::CollisionEvent& e, std::uint64_t dropped) {
  return dump({{"type", "collision"},
               {"tick", e.tick()},
               {"t", e.sim_time_s()},
               {"drone", e.drone_id()},
               {"kind", contact_kind(e.kind())},
               {"other", e.other()},
               {"where", vec(e.where())},
               {"dropped", dropped}});
}

std::string encode_ack(std::int64_t id, std::string_view cmd, bool ok, std::string_view message) {
  return dump({{"type", "ack"}, {"id", id}, {"cmd", cmd}, {"ok", ok}, {"message", message}});
}

std::string encode_error(std::string_view message, std::optional<std::int64_t> id) {
  json j = {{"type", "error"}, {"message", message}};
  if (id) j["id"] = *id;
  return dump(j);
}

std::string encode_replay(const ReplayInfo& r) {
  return dump({{"type", "replay"},
               {"name", r.name},
               {"start", r.start_s},
               {"duration", r.duration_s},
               {"t", r.t_s},
               {"playing", r.playing},
               {"rate", r.rate},
               {"frames", r.frames}});
}

const char* to_string(CommandKind k) {
  switch (k) {
    case CommandKind::kTakeoff:
      return "takeoff";
    case CommandKind::kMove:
      return "move";
    case CommandKind::kDistance:
      return "distance";
    case CommandKind::kLand:
      return "land";
    case CommandKind::kHold:
      return "hold";
    case CommandKind::kTask:
      return "task";
    case CommandKind::kFollow:
      return "follow";
    case CommandKind::kTeleop:
      return "teleop";
  }
  return "unknown";
}

// ---- parsing ----

namespace {

struct Bad {
  std::string message;
};

/// A value as the error names it: short JSON, "inf"/"nan" for what JSON cannot say.
std::string show(const json& v) {
  if (v.is_number_float() && !std::isfinite(v.get<double>()))
    return std::isnan(v.get<double>()) ? "nan" : "inf";
  std::string s = v.dump(-1, ' ', false, json::error_handler_t::replace);
  if (s.size() > 40) s = s.substr(0, 37) + "...";
  return s;
}

/// Reads the fields of one message, complaining in the protocol's words.
class Fields {
 public:
  Fields(const json& obj, std::string prefix) : obj_(obj), prefix_(std::move(prefix)) {}

  const json* find(const char* key) {
    used_.push_back(key);
    auto it = obj_.find(key);
    return it == obj_.end() ? nullptr : &*it;
  }

  double number(const char* key, double lo, double hi, std::optional<double> dflt) {
    const json* v = find(key);
    if (!v) {
      if (dflt) return *dflt;
      throw Bad{name(key) + ": missing"};
    }
    return check_number(*v, name(key), lo, hi);
  }

  std::int64_t integer(const char* key, std::int64_t lo, std::int64_t hi) {
    const json* v = find(key);
    if (!v) throw Bad{name(key) + ": missing"};
    double x = check_number(*v, name(key), static_cast<double>(lo), static_cast<double>(hi));
    if (x != std::floor(x)) throw Bad{name(key) + " = " + show(*v) + ": must be an integer"};
    return static_cast<std::int64_t>(x);
  }

  bool boolean(const char* key, bool dflt) {
    const json* v = find(key);
    if (!v) return dflt;
    if (!v->is_boolean()) throw Bad{name(key) + " = " + show(*v) + ": must be true or false"};
    return v->get<bool>();
  }

  std::string string(const char* key, std::size_t max_len) {
    const json* v = find(key);
    if (!v) throw Bad{name(key) + ": missing"};
    if (!v->is_string()) throw Bad{name(key) + " = " + show(*v) + ": must be a string"};
    auto s = v->get<std::string>();
    if (s.empty() || s.size() > max_len)
      throw Bad{name(key) + " = " + show(*v) + ": must be 1 to " + std::to_string(max_len) +
                " characters"};
    return s;
  }

  Eigen::Vector3d vec3(const char* key, double lo, double hi) {
    const json* v = find(key);
    if (!v) throw Bad{name(key) + ": missing"};
    if (!v->is_array() || v->size() != 3)
      throw Bad{name(key) + " = " + show(*v) + ": must be [x, y, z]"};
    Eigen::Vector3d out;
    for (int i = 0; i < 3; ++i)
      out[i] = check_number((*v)[i], name(key) + "[" + std::to_string(i) + "]", lo, hi);
    return out;
  }

  /// Throws when a field was sent that this message does not have.
  void no_others() const {
    for (auto it = obj_.begin(); it != obj_.end(); ++it) {
      bool known = false;
      for (const auto& u : used_)
        if (it.key() == u) known = true;
      if (!known) throw Bad{name(it.key()) + ": unknown field"};
    }
  }

  std::string name(const std::string& key) const {
    return prefix_.empty() ? key : prefix_ + "." + key;
  }

 private:
  static double check_number(const json& v, const std::string& what, double lo, double hi) {
    if (!v.is_number()) throw Bad{what + " = " + show(v) + ": must be a number"};
    const double x = v.get<double>();
    if (!std::isfinite(x)) throw Bad{what + " = " + show(v) + ": must be finite"};
    if (x < lo || x > hi) throw Bad{fmt_range(what + " = " + show(v), lo, hi)};
    return x;
  }
  static std::string fmt_range(const std::string& head, double lo, double hi) {
    auto num = [](double x) {
      std::string s;
      put_num(s, x, 6);
      return s;
    };
    return head + ": must be in [" + num(lo) + ", " + num(hi) + "]";
  }

  const json& obj_;
  std::string prefix_;
  std::vector<std::string> used_;
};

ClientRequest parse_command(const json& j, std::optional<std::int64_t>& id_out) {
  Fields f(j, "command");
  f.find("type");
  CommandRequest c;
  c.id = f.integer("id", 0, (std::int64_t{1} << 53));
  id_out = c.id;
  const std::string cmd = f.string("cmd", 32);
  if (cmd == "takeoff") {
    c.kind = CommandKind::kTakeoff;
    c.altitude_m = f.number("altitude", 0, 1000, 0.0);
  } else if (cmd == "move") {
    c.kind = CommandKind::kMove;
    c.v = f.vec3("v", -50, 50);
    c.duration_s = f.number("duration", 0, 86400, std::nullopt);
  } else if (cmd == "distance") {
    c.kind = CommandKind::kDistance;
    c.value_m = f.number("value", 0.31, 1000, std::nullopt);
  } else if (cmd == "land") {
    c.kind = CommandKind::kLand;
  } else if (cmd == "hold") {
    c.kind = CommandKind::kHold;
  } else if (cmd == "task") {
    c.kind = CommandKind::kTask;
    c.speed_mps = f.number("speed", 0, 50, 0.0);
    c.epsilon_m = f.number("epsilon", 0, 10000, 0.0);
  } else if (cmd == "follow") {
    c.kind = CommandKind::kFollow;
    c.leader = static_cast<int>(f.integer("leader", 0, 1023));
  } else if (cmd == "teleop") {
    c.kind = CommandKind::kTeleop;
    c.v = f.vec3("v", -50, 50);
  } else {
    throw Bad{"command.cmd = " + show(json(cmd)) +
              ": unknown (expected takeoff, move, distance, land, hold, task, follow, teleop)"};
  }
  f.no_others();
  return c;
}

ClientRequest parse_object(const json& j, std::optional<std::int64_t>& id_out) {
  auto t = j.find("type");
  if (t == j.end()) throw Bad{"type: missing"};
  if (!t->is_string()) throw Bad{"type = " + show(*t) + ": must be a string"};
  const std::string type = t->get<std::string>();
  if (type == "command") return parse_command(j, id_out);
  Fields f(j, type);
  f.find("type");
  ClientRequest out;
  if (type == "subscribe") {
    SubscribeRequest s;
    s.fps = f.number("fps", 1, 60, 30.0);
    s.rays = f.boolean("rays", false);
    out = s;
  } else if (type == "open") {
    out = OpenRequest{f.string("recording", 64)};
  } else if (type == "live") {
    out = LiveRequest{};
  } else if (type == "replay") {
    ReplayRequest r;
    const std::string action = f.string("action", 16);
    if (action == "play") {
      r.action = ReplayRequest::Action::kPlay;
    } else if (action == "pause") {
      r.action = ReplayRequest::Action::kPause;
    } else if (action == "seek") {
      r.action = ReplayRequest::Action::kSeek;
      r.t_s = f.number("t", -1e12, 1e12, std::nullopt);
    } else if (action == "rate") {
      r.action = ReplayRequest::Action::kRate;
      r.rate = f.number("rate", 0.1, 16, std::nullopt);
    } else {
      throw Bad{"replay.action = " + show(json(action)) +
                ": unknown (expected play, pause, seek, rate)"};
    }
    out = r;
  } else {
    throw Bad{"type = " + show(*t) + ": unknown (expected subscribe, command, open, live, replay)"};
  }
  f.no_others();
  return out;
}

}  // namespace

ParsedMessage parse_client_message(std::string_view text) {
  ParsedMessage out;
  if (text.size() > kMaxClientMessageBytes) {
    out.error = "message of " + std::to_string(text.size()) + " bytes: over the " +
                std::to_string(kMaxClientMessageBytes / 1024) + " KiB limit";
    return out;
  }
  // Refuse deep nesting before parsing: nlohmann's dump and the checks below
  // recurse, and a hostile page could send 30,000 '[' (stack overflow under
  // ASan). No message of the protocol nests deeper than 3.
  {
    int depth = 0, deepest = 0;
    bool in_string = false, escaped = false;
    for (char c : text) {
      if (in_string) {
        if (escaped)
          escaped = false;
        else if (c == '\\')
          escaped = true;
        else if (c == '"')
          in_string = false;
      } else if (c == '"') {
        in_string = true;
      } else if (c == '[' || c == '{') {
        deepest = std::max(deepest, ++depth);
      } else if (c == ']' || c == '}') {
        --depth;
      }
    }
    if (deepest > kMaxClientNesting) {
      out.error = "message nested " + std::to_string(deepest) + " deep: over the limit of " +
                  std::to_string(kMaxClientNesting);
      return out;
    }
  }
  json j;
  try {
    j = json::parse(text);
  } catch (const json::exception& e) {  // parse errors, numbers overflowing a double
    // Say where it broke without echoing the whole message.
    std::string what = e.what();
    auto p = what.find("] ");
    out.error = "not JSON: " + (p == std::string::npos ? what : what.substr(p + 2));
    if (out.error.size() > 160) out.error = out.error.substr(0, 157) + "...";
    return out;
  }
  if (!j.is_object()) {
    out.error = "message = " + show(j) + ": must be a JSON object with a type";
    return out;
  }
  try {
    out.request = parse_object(j, out.id);
  } catch (const Bad& b) {
    out.error = b.message;
    out.request.reset();
  } catch (const std::exception& e) {  // e.g. a number that does not fit
    out.error = std::string("invalid message: ") + e.what();
    out.request.reset();
  }
  return out;
}

}  // namespace ddswarm::gs::web
