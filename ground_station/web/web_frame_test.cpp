#include "ground_station/web/web_frame.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "common/mcap/mcap_writer.hpp"
#include "common/mesh_loader.hpp"
#include "common/swarm_state_cdr.hpp"
#include "common/topics.hpp"
#include "ddswarm_idl_text.hpp"
#include "ground_station/web/web_recording.hpp"

using namespace ddswarm;
using namespace ddswarm::gs::web;
using nlohmann::json;

namespace {

msg::SwarmState three_drones() {
  msg::SwarmState s;
  s.tick(42);
  s.sim_time_s(1.25);
  const double xs[3] = {0, 3, 0};
  const double ys[3] = {0, 0, 5};
  for (int i = 0; i < 3; ++i) {
    msg::DroneState d;
    d.drone_id(i);
    msg::Vec3 p;
    p.x(xs[i]);
    p.y(ys[i]);
    p.z(1.5);
    d.position(p);
    msg::Quat q;
    q.w(1);
    d.orientation(q);
    msg::Vec3 v;
    v.x(0.5);
    v.y(-0.25);
    d.velocity(v);
    d.motor_speed_rad_s({400.04f, 401.f, 402.f, 403.f});
    d.flags(msg::DRONE_AIRBORNE | msg::DRONE_AGENT_LIVE);
    d.phase(2);  // hold
    d.collisions_obstacle(1);
    d.collisions_drone(2);
    d.collisions_ground(3);
    s.drones().push_back(d);
  }
  msg::DistanceScan sc;
  sc.drone_id(1);
  sc.angle_body_rad({0.f, 1.5707964f});
  sc.elevation_body_rad({0.f, 0.3490659f});
  sc.range_m({2.5f, 8.f});
  sc.hit({1, 0});
  s.scans().push_back(sc);
  return s;
}

}  // namespace

TEST(WebFrame, FrameHasTheProtocolsFieldsAndValues) {
  auto j = json::parse(encode_frame(to_frame(three_drones()), false));
  EXPECT_EQ(j["type"], "frame");
  EXPECT_EQ(j["tick"], 42);
  EXPECT_DOUBLE_EQ(j["t"].get<double>(), 1.25);
  ASSERT_EQ(j["drones"].size(), 3u);
  const auto& d = j["drones"][1];
  EXPECT_EQ(d["id"], 1);
  EXPECT_EQ(d["p"], json::array({3, 0, 1.5}));
  EXPECT_EQ(d["q"], json::array({1, 0, 0, 0}));
  EXPECT_EQ(d["v"], json::array({0.5, -0.25, 0}));
  EXPECT_DOUBLE_EQ(d["w"][0].get<double>(), 400.0);  // rounded to 0.1 rad/s
  EXPECT_EQ(d["flags"], msg::DRONE_AIRBORNE | msg::DRONE_AGENT_LIVE);
  EXPECT_EQ(d["phase"], "hold");
  EXPECT_EQ(d["col"], json::array({1, 2, 3}));
  EXPECT_DOUBLE_EQ(d["nearest"].get<double>(), 3.0);
  EXPECT_DOUBLE_EQ(j["drones"][2]["nearest"].get<double>(), 5.0);
  EXPECT_FALSE(j.contains("rays"));
}

TEST(WebFrame, RaysOnlyWhenAskedAndEmptyForADroneWithoutAScan) {
  auto j = json::parse(encode_frame(to_frame(three_drones()), true));
  ASSERT_EQ(j["rays"].size(), 3u);
  EXPECT_TRUE(j["rays"][0]["a"].empty());
  EXPECT_EQ(j["rays"][1]["r"], json::array({2.5, 8}));
  EXPECT_EQ(j["rays"][1]["hit"], json::array({1, 0}));
  EXPECT_NEAR(j["rays"][1]["a"][1].get<double>(), 1.5708, 1e-9);
  EXPECT_NEAR(j["rays"][1]["e"][1].get<double>(), 0.3491, 1e-9);  // rad, up from the body plane
}

TEST(WebFrame, AMalformedScanDrawsNoRays) {
  auto s = three_drones();
  s.scans()[0].elevation_body_rad().pop_back();  // one elevation short
  auto j = json::parse(encode_frame(to_frame(s), true));
  EXPECT_TRUE(j["rays"][1]["a"].empty());
  s = three_drones();
  s.scans()[0].elevation_body_rad()[0] = NAN;
  j = json::parse(encode_frame(to_frame(s), true));
  EXPECT_TRUE(j["rays"][1]["r"].empty());
}

TEST(WebFrame, PositionsKeepATenthOfAMillimetre) {
  auto s = three_drones();
  msg::Vec3 p;
  p.x(-123.456789);
  p.y(0.00004);
  p.z(-0.00004);
  s.drones()[0].position(p);
  auto j = json::parse(encode_frame(to_frame(s), false));
  EXPECT_NEAR(j["drones"][0]["p"][0].get<double>(), -123.4568, 1e-4);
  EXPECT_EQ(j["drones"][0]["p"][1], 0);
  // Rounded to zero: written 0, not -0.
  EXPECT_EQ(encode_frame(to_frame(s), false).find("-0,"), std::string::npos);
}

TEST(WebFrame, NonFiniteNumbersAreNullNeverInvalidJson) {
  auto s = three_drones();
  msg::Vec3 p;
  p.x(std::nan(""));
  p.y(std::numeric_limits<double>::infinity());
  p.z(1e30);
  s.drones()[0].position(p);
  s.drones()[0].motor_speed_rad_s({std::nanf(""), 0, 0, 0});
  const std::string text = encode_frame(to_frame(s), false);
  auto j = json::parse(text);  // throws on NaN/Infinity literals
  EXPECT_TRUE(j["drones"][0]["p"][0].is_null());
  EXPECT_TRUE(j["drones"][0]["p"][1].is_null());
  EXPECT_NEAR(j["drones"][0]["p"][2].get<double>(), 1e30, 1e24);
  EXPECT_TRUE(j["drones"][0]["w"][0].is_null());
  EXPECT_EQ(text.find("nan"), std::string::npos);
  EXPECT_EQ(text.find("inf"), std::string::npos);

  msg::SimStatus st;
  st.real_time_factor(std::nan(""));
  auto js = json::parse(encode_status(st));
  EXPECT_TRUE(js["rtf"].is_null());
}

TEST(WebFrame, NearestIsNullForALoneDrone) {
  auto s = three_drones();
  s.drones().resize(1);
  auto j = json::parse(encode_frame(to_frame(s), false));
  EXPECT_TRUE(j["drones"][0]["nearest"].is_null());
  EXPECT_TRUE(json::parse(encode_frame(Frame{}, true))["drones"].empty());
}

TEST(WebFrame, NearestDistances) {
  std::vector<Eigen::Vector3d> p = {{0, 0, 0}, {1, 0, 0}, {10, 0, 0}, {10, 2, 0}};
  auto d = nearest_distances(p);
  EXPECT_DOUBLE_EQ(d[0], 1);
  EXPECT_DOUBLE_EQ(d[1], 1);
  EXPECT_DOUBLE_EQ(d[2], 2);
  EXPECT_DOUBLE_EQ(d[3], 2);
  EXPECT_TRUE(std::isnan(nearest_distances({{1, 2, 3}})[0]));
  EXPECT_TRUE(nearest_distances({}).empty());
}

TEST(WebFrame, SceneStatusTaskCollisionAckFields) {
  msg::Scene sc;
  sc.name("thesis");
  sc.seed(7);
  sc.num_drones(6);
  sc.mode(msg::MODE_LOCKSTEP);
  msg::Cylinder c;
  c.x(1);
  c.y(2);
  c.radius_m(0.3);
  c.height_m(5);
  sc.cylinders().push_back(c);
  msg::Box b;
  b.yaw_rad(0.5);
  sc.boxes().push_back(b);
  sc.sensor_count(8);
  sc.sensor_max_range_m(10);
  auto j = json::parse(encode_scene(sc));
  EXPECT_EQ(j["type"], "scene");
  EXPECT_EQ(j["mode"], "lockstep");
  EXPECT_EQ(j["num_drones"], 6);
  EXPECT_EQ(j["cylinders"][0], json({{"x", 1}, {"y", 2}, {"r", 0.3}, {"h", 5}}));
  EXPECT_EQ(j["boxes"][0]["yaw"], 0.5);
  EXPECT_EQ(j["boxes"][0]["c"].size(), 3u);
  for (auto k : {"ground_z", "bounds_min", "bounds_max", "finish_a", "finish_b", "goal",
                 "drone_radius", "arm_length", "sensor_count", "sensor_range", "seed", "name"})
    EXPECT_TRUE(j.contains(k)) << k;

  msg::SimStatus st;
  st.tick(9);
  st.state("running");
  st.live_agents({0, 2});
  st.collisions_drone(4);
  st.rejected_absurd(2);
  st.rejected_mission(1);
  st.real_time_factor(1.5);
  j = json::parse(encode_status(st));
  EXPECT_EQ(j["type"], "status");
  EXPECT_EQ(j["live"], json::array({0, 2}));
  EXPECT_EQ(j["collisions"], json::array({0, 4, 0}));
  EXPECT_EQ(j["rejected"], 3);
  EXPECT_EQ(j["rtf"], 1.5);
  EXPECT_EQ(j["mode"], "realtime");
  EXPECT_EQ(j["state"], "running");

  msg::TaskStatus t;
  t.phase(msg::TASK_FAILED);
  t.reason("timeout");
  t.elapsed_s(12.5);
  j = json::parse(encode_task(t));
  EXPECT_EQ(j["state"], "failed");
  EXPECT_EQ(j["reason"], "timeout");
  EXPECT_EQ(j["elapsed"], 12.5);

  msg::CollisionEvent e;
  e.kind(msg::CONTACT_GROUND);
  e.other(-1);
  e.drone_id(3);
  j = json::parse(encode_collision(e, 5));
  EXPECT_EQ(j["kind"], "ground");
  EXPECT_EQ(j["other"], -1);
  EXPECT_EQ(j["drone"], 3);
  EXPECT_EQ(j["dropped"], 5);

  j = json::parse(encode_ack(12, "takeoff", true, "takeoff 6/6 acknowledged"));
  EXPECT_EQ(j, json({{"type", "ack"},
                     {"id", 12},
                     {"cmd", "takeoff"},
                     {"ok", true},
                     {"message", "takeoff 6/6 acknowledged"}}));
  j = json::parse(encode_hello("live", "gs"));
  EXPECT_EQ(j["version"], 1);
  EXPECT_EQ(j["source"], "live");
  j = json::parse(encode_error("bad \"quote\"\n", 3));
  EXPECT_EQ(j["message"], "bad \"quote\"\n");
  EXPECT_EQ(j["id"], 3);
}

// ---- client messages ----

namespace {
std::string error_of(std::string_view text) {
  auto p = parse_client_message(text);
  EXPECT_FALSE(p.request.has_value()) << text;
  EXPECT_FALSE(p.error.empty()) << text;
  return p.error;
}
}  // namespace

TEST(WebParse, ValidMessages) {
  auto p = parse_client_message(R"({"type":"subscribe","fps":20,"rays":true})");
  ASSERT_TRUE(p.request) << p.error;
  auto s = std::get<SubscribeRequest>(*p.request);
  EXPECT_EQ(s.fps, 20);
  EXPECT_TRUE(s.rays);

  p = parse_client_message(
      R"({"type":"command","id":7,"cmd":"move","v":[1,-2,0.5],"duration":30})");
  ASSERT_TRUE(p.request) << p.error;
  auto c = std::get<CommandRequest>(*p.request);
  EXPECT_EQ(c.id, 7);
  EXPECT_EQ(c.kind, CommandKind::kMove);
  EXPECT_EQ(c.v, Eigen::Vector3d(1, -2, 0.5));
  EXPECT_EQ(c.duration_s, 30);

  p = parse_client_message(R"({"type":"command","id":1,"cmd":"takeoff"})");
  ASSERT_TRUE(p.request) << p.error;
  EXPECT_EQ(std::get<CommandRequest>(*p.request).altitude_m, 0);
  for (auto text :
       {R"({"type":"command","id":2,"cmd":"land"})", R"({"type":"command","id":2,"cmd":"hold"})",
        R"({"type":"command","id":2,"cmd":"task","speed":0.8})",
        R"({"type":"command","id":2,"cmd":"distance","value":6})",
        R"({"type":"command","id":2,"cmd":"follow","leader":0})",
        R"({"type":"command","id":2,"cmd":"teleop","v":[0,1,0]})", R"({"type":"live"})",
        R"({"type":"open","recording":"r1"})", R"({"type":"replay","action":"seek","t":3.5})",
        R"({"type":"replay","action":"rate","rate":4})", R"({"type":"replay","action":"pause"})"}) {
    EXPECT_TRUE(parse_client_message(text).request)
        << text << ": " << parse_client_message(text).error;
  }
}

TEST(WebParse, NotJson) {
  EXPECT_EQ(error_of("takeoff now").rfind("not JSON", 0), 0u);
  EXPECT_EQ(error_of("").rfind("not JSON", 0), 0u);
  EXPECT_EQ(
      error_of(R"({"type":"command","id":1,"cmd":"takeoff","altitude":NaN})").rfind("not JSON", 0),
      0u);
  EXPECT_EQ(error_of(R"({"type":"subscribe")").rfind("not JSON", 0), 0u);
  EXPECT_EQ(error_of("\xff\xfe").rfind("not JSON", 0), 0u);
  EXPECT_EQ(error_of("[1,2]"), "message = [1,2]: must be a JSON object with a type");
}

TEST(WebParse, UnknownTypeAndCommand) {
  EXPECT_EQ(error_of(R"({"fps":3})"), "type: missing");
  EXPECT_EQ(error_of(R"({"type":5})"), "type = 5: must be a string");
  EXPECT_EQ(error_of(R"({"type":"explode"})"),
            R"(type = "explode": unknown (expected subscribe, command, open, live, replay))");
  EXPECT_EQ(error_of(R"({"type":"command","id":1,"cmd":"selfdestruct"})")
                .rfind(R"(command.cmd = "selfdestruct": unknown)", 0),
            0u);
  EXPECT_EQ(error_of(R"({"type":"replay","action":"rewind"})")
                .rfind(R"(replay.action = "rewind": unknown)", 0),
            0u);
}

TEST(WebParse, NonFiniteAndWrongTypes) {
  // JSON cannot say NaN; a literal overflowing a double is refused by the parser.
  EXPECT_EQ(error_of(R"({"type":"command","id":1,"cmd":"takeoff","altitude":1e999})"),
            "not JSON: number overflow parsing '1e999'");
  EXPECT_EQ(error_of(R"({"type":"command","id":1,"cmd":"takeoff","altitude":"high"})"),
            R"(command.altitude = "high": must be a number)");
  EXPECT_EQ(error_of(R"({"type":"command","id":1,"cmd":"move","v":[1,null,0],"duration":3})"),
            "command.v[1] = null: must be a number");
  EXPECT_EQ(error_of(R"({"type":"command","id":1,"cmd":"move","v":[1,0],"duration":3})"),
            "command.v = [1,0]: must be [x, y, z]");
  EXPECT_EQ(error_of(R"({"type":"subscribe","rays":"yes"})"),
            R"(subscribe.rays = "yes": must be true or false)");
  EXPECT_EQ(error_of(R"({"type":"command","id":1.5,"cmd":"land"})"),
            "command.id = 1.5: must be an integer");
  EXPECT_EQ(error_of(R"({"type":"open","recording":7})"), "open.recording = 7: must be a string");
}

TEST(WebParse, MissingAndOutOfRange) {
  EXPECT_EQ(error_of(R"({"type":"command","cmd":"land"})"), "command.id: missing");
  EXPECT_EQ(error_of(R"({"type":"command","id":1})"), "command.cmd: missing");
  EXPECT_EQ(error_of(R"({"type":"command","id":1,"cmd":"move","v":[1,0,0]})"),
            "command.duration: missing");
  EXPECT_EQ(error_of(R"({"type":"command","id":1,"cmd":"distance","value":0.1})"),
            "command.value = 0.1: must be in [0.31, 1000]");
  EXPECT_EQ(error_of(R"({"type":"command","id":1,"cmd":"move","v":[51,0,0],"duration":1})"),
            "command.v[0] = 51: must be in [-50, 50]");
  EXPECT_EQ(error_of(R"({"type":"command","id":1,"cmd":"takeoff","altitude":-1})"),
            "command.altitude = -1: must be in [0, 1000]");
  EXPECT_EQ(error_of(R"({"type":"subscribe","fps":0})"), "subscribe.fps = 0: must be in [1, 60]");
  EXPECT_EQ(error_of(R"({"type":"subscribe","fps":1000})"),
            "subscribe.fps = 1000: must be in [1, 60]");
  EXPECT_EQ(error_of(R"({"type":"replay","action":"rate","rate":100})"),
            "replay.rate = 100: must be in [0.1, 16]");
  EXPECT_EQ(error_of(R"({"type":"command","id":-1,"cmd":"land"})")
                .rfind("command.id = -1: must be in [0,", 0),
            0u);
  EXPECT_EQ(error_of(R"({"type":"command","id":1,"cmd":"follow","leader":2000})"),
            "command.leader = 2000: must be in [0, 1023]");
}

TEST(WebParse, UnknownFieldsAreNamed) {
  EXPECT_EQ(error_of(R"({"type":"command","id":1,"cmd":"takeoff","altitute":3})"),
            "command.altitute: unknown field");
  EXPECT_EQ(error_of(R"({"type":"live","now":true})"), "live.now: unknown field");
}

TEST(WebParse, CommandErrorsCarryTheIdWhenReadable) {
  auto p = parse_client_message(R"({"type":"command","id":9,"cmd":"takeoff","altitude":-5})");
  EXPECT_FALSE(p.request);
  ASSERT_TRUE(p.id);
  EXPECT_EQ(*p.id, 9);
  EXPECT_EQ(json::parse(encode_error(p.error, p.id))["id"], 9);
}

TEST(WebParse, HugeAndDeeplyNestedMessages) {
  std::string big = R"({"type":"live","x":")" + std::string(kMaxClientMessageBytes, 'a') + "\"}";
  EXPECT_EQ(error_of(big),
            "message of " + std::to_string(big.size()) + " bytes: over the 64 KiB limit");
  std::string deep = std::string(30000, '[') +
                     std::string(30000, ']');  // under the limit, must not overflow the stack
  EXPECT_EQ(error_of(deep), "message nested 30000 deep: over the limit of 8");
  // Brackets inside strings are text, not nesting.
  EXPECT_EQ(error_of(R"({"type":"live","x":"[[[[[[[[[[[[[[[[[["})").rfind("message nested", 0),
            std::string::npos);
}

// The meshes a Scene names are served only when this machine has the very
// file the server loaded; the scene message says where, or why not, and
// carries the wind.
TEST(WebFrame, MeshFilesAreServedOnlyWithTheServersBytes) {
  namespace fs = std::filesystem;
  const fs::path dir =
      fs::temp_directory_path() / ("ddswarm_mesh_files_" + std::to_string(::getpid()));
  fs::create_directories(dir / "meshes");
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  std::ofstream(dir / "meshes" / "a.obj") << obj;
  std::ofstream(dir / "meshes" / "b.obj") << obj << "\n";  // not the server's bytes
  msg::Scene sc;
  const auto add = [&](const std::string& file, std::uint64_t hash) {
    msg::Mesh m;
    m.file(file);
    m.scale(2);
    m.yaw_deg(90);
    m.triangle_count(1);
    m.content_hash(hash);
    m.bounds_max().x(2);
    sc.meshes().push_back(m);
  };
  const std::uint64_t a_hash = file_hash(dir / "meshes" / "a.obj");
  add("meshes/a.obj", a_hash);
  add("meshes/b.obj", a_hash);
  add("meshes/absent.obj", a_hash);
  add((dir / "meshes" / "a.obj").string(), a_hash);  // absolute
  add("meshes/a.ply", a_hash);
  sc.wind().steady_mps().x(3);
  sc.wind().turbulence(true);
  sc.wind().turbulence_sigma_mps().z(0.3);
  sc.wind().gusts_per_minute(2);
  sc.wind().gust_max_mps(3);

  MeshFiles files(dir);
  const auto urls = files.offer(sc);
  ASSERT_EQ(urls.size(), 5u);
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(a_hash));
  EXPECT_EQ(urls[0].url, std::string("/mesh/") + hex + ".obj");
  EXPECT_EQ(urls[1].url, "");
  EXPECT_EQ(urls[1].why, "differs from the server's");
  EXPECT_EQ(urls[2].why, "no such file here");
  EXPECT_EQ(urls[3].url, urls[0].url);
  EXPECT_EQ(urls[4].why, "not a mesh file");
  EXPECT_EQ(files.find(urls[0].url), dir / "meshes" / "a.obj");
  EXPECT_FALSE(files.find("/mesh/0000000000000000.obj"));
  EXPECT_FALSE(files.find("/mesh/../meshes/a.obj"));

  const json j = json::parse(encode_scene(sc, urls));
  ASSERT_EQ(j["meshes"].size(), 5u);
  EXPECT_EQ(j["meshes"][0]["url"], urls[0].url);
  EXPECT_TRUE(j["meshes"][1]["url"].is_null());
  EXPECT_EQ(j["meshes"][1]["why"], "differs from the server's");
  EXPECT_EQ(j["meshes"][0]["scale"], 2);
  EXPECT_EQ(j["meshes"][0]["triangles"], 1);
  EXPECT_NEAR(j["meshes"][0]["q"][0].get<double>(), std::sqrt(0.5), 1e-12);  // 90 deg about z
  EXPECT_NEAR(j["meshes"][0]["q"][3].get<double>(), std::sqrt(0.5), 1e-12);
  EXPECT_EQ(j["meshes"][0]["bounds_max"], json({2, 0, 0}));
  EXPECT_EQ(j["wind"]["steady"], json({3, 0, 0}));
  EXPECT_EQ(j["wind"]["turbulence"], true);
  EXPECT_EQ(j["wind"]["sigma"][2], 0.3);
  EXPECT_EQ(j["wind"]["gusts_per_minute"], 2);
  EXPECT_EQ(j["wind"]["gust_max"], 3);
  fs::remove_all(dir);
}

// A recording made before scans carried elevations: its schema has no
// DistanceScan.elevation_body_rad and its bytes none. The web view's replay
// reads its frames, the rays level.
TEST(WebRecording, ARecordingFromBeforeScanElevationsReplaysWithLevelRays) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("ddswarm_old_" + std::to_string(getpid()) + ".mcap"))
                               .string();
  std::string idl = kIdlText;
  const auto at = idl.find("  sequence<float, 256> elevation_body_rad;");
  ASSERT_NE(at, std::string::npos);
  idl.erase(at, idl.find('\n', at) + 1 - at);
  {
    mcap::Writer w(path);
    const auto ch = w.add_channel(w.add_schema("ddswarm::msg::SwarmState", "omgidl", idl),
                                  Topic<msg::SwarmState>::name, "cdr");
    for (int k = 0; k < 3; ++k) {
      auto s = three_drones();
      s.sim_time_s(1.0 + k);
      const auto bytes = encode_swarm_state(s, false, ScanLayout::kRing64);
      w.write(ch, 1'000'000'000ull * (k + 1), 1'000'000'000ull * (k + 1), bytes.data(),
              bytes.size());
    }
    w.close();
  }
  const auto rec = load_recording(path, "old.mcap");
  std::filesystem::remove(path);
  ASSERT_EQ(rec->frames.size(), 3u);
  const auto& d = rec->frames[2].drones[1];
  EXPECT_EQ(d.ray_range, std::vector<float>({2.5f, 8.f}));
  EXPECT_EQ(d.ray_elevation, std::vector<float>({0.f, 0.f}));
}
