#pragma once
// The web view's wire format (docs/web_view.md, protocol version 1): the
// swarm's DDS samples as JSON text for the page, and the page's messages
// checked and parsed into typed requests. Pure: no I/O, no threads.
// World frame ENU, metres, seconds, quaternions [w, x, y, z].
#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "CollisionEvent.h"
#include "Scene.h"
#include "SimStatus.h"
#include "SwarmState.h"
#include "TaskStatus.h"
#include "ground_station/web/mesh_files.hpp"

namespace ddswarm::gs::web {

constexpr int kProtocolVersion = 1;
/// Client messages above this size are answered with `error` (bytes).
constexpr std::size_t kMaxClientMessageBytes = 64 * 1024;
constexpr int kMaxClientNesting = 8;  ///< arrays/objects inside each other; the protocol needs 3

/// One drone as the page draws it.
struct DroneFrame {
  int id = 0;
  std::array<float, 3> p{};            ///< m, world ENU, body centre
  std::array<float, 4> q{1, 0, 0, 0};  ///< body to world, [w, x, y, z]
  std::array<float, 3> v{};            ///< m/s, world
  std::array<float, 4> w{};            ///< rad/s, rotor speeds
  std::uint16_t flags = 0;             ///< DroneState.flags bits
  std::uint8_t phase = 0;              ///< common/mission.hpp Phase
  std::array<std::uint32_t, 3> col{};  ///< contacts begun: obstacle, drone, ground
  std::vector<float> ray_angle;        ///< rad, body yaw of each ray (empty: no scan)
  std::vector<float> ray_elevation;    ///< rad, elevation of each ray, up from the body x-y plane
  std::vector<float> ray_range;        ///< m, measured range
  std::vector<std::uint8_t> ray_hit;   ///< 1 if something is within range
};

/// The swarm at one tick.
struct Frame {
  std::uint64_t tick = 0;
  double t = 0;                    ///< s, sim time
  std::vector<DroneFrame> drones;  ///< index = drone id
};

/// The edge: a SwarmState (drones and their latest scans) as a Frame. A
/// malformed scan (scan_problem: sequences of different lengths, a ray
/// pointing nowhere) gives its drone no rays.
Frame to_frame(const msg::SwarmState& s);

/// For each position, the distance (m) to the nearest other one; NaN when it is alone.
std::vector<double> nearest_distances(const std::vector<Eigen::Vector3d>& positions);

/// `frame`; rays only when asked for. Non-finite numbers become null.
std::string encode_frame(const Frame& f, bool rays);
/// `hello`: source is "live" or "replay".
std::string encode_hello(std::string_view source, std::string_view gs_name);
/// `scene`; mesh_urls: where each of s's meshes is served (MeshFiles::offer),
/// in s's order (missing entries: not served).
std::string encode_scene(const msg::Scene& s, const std::vector<MeshUrl>& mesh_urls = {});
std::string encode_status(const msg::SimStatus& s);
std::string encode_task(const msg::TaskStatus& t);
/// dropped: collision events this client has missed so far (rate limit).
std::string encode_collision(const msg::CollisionEvent& e, std::uint64_t dropped);
std::string encode_ack(std::int64_t id, std::string_view cmd, bool ok, std::string_view message);
/// id: the command's id when the bad message was a command whose id was readable.
std::string encode_error(std::string_view message, std::optional<std::int64_t> id = std::nullopt);

/// What a `replay` message tells about the recording a client plays.
struct ReplayInfo {
  std::string name;
  double start_s = 0;     ///< sim s of the first frame
  double duration_s = 0;  ///< sim s
  double t_s = 0;         ///< sim s, current
  bool playing = false;
  double rate = 1;
  std::size_t frames = 0;
};
std::string encode_replay(const ReplayInfo& r);

// ---- Page -> bridge ----

struct SubscribeRequest {
  double fps = 30;    ///< frames per second, [1, 60]
  bool rays = false;  ///< include sensor rays in frames
};

enum class CommandKind { kTakeoff, kMove, kDistance, kLand, kHold, kTask, kFollow, kTeleop };
const char* to_string(CommandKind k);

/// A mission command, checked against the CLI's ranges.
struct CommandRequest {
  std::int64_t id = 0;  ///< the client's, echoed in the ack
  CommandKind kind = CommandKind::kHold;
  double altitude_m = 0;       ///< takeoff; 0 = agents' default
  Eigen::Vector3d v{0, 0, 0};  ///< m/s ENU (move, teleop)
  double duration_s = 0;       ///< move
  double value_m = 0;          ///< distance: new D_int
  double speed_mps = 0;        ///< task; 0 = scenario default
  double epsilon_m = 0;        ///< task; 0 = scenario default
  int leader = 0;              ///< follow
};

struct OpenRequest {
  std::string recording;  ///< id from POST /api/recording
};
struct LiveRequest {};
struct ReplayRequest {
  enum class Action { kPlay, kPause, kSeek, kRate } action = Action::kPlay;
  double t_s = 0;   ///< seek: sim s
  double rate = 1;  ///< rate: [0.1, 16]
};

using ClientRequest =
    std::variant<SubscribeRequest, CommandRequest, OpenRequest, LiveRequest, ReplayRequest>;

/// A parsed client message: request set, or error (one line naming the field and value).
struct ParsedMessage {
  std::optional<ClientRequest> request;
  std::string error;
  std::optional<std::int64_t> id;  ///< a command's id, when readable (for the error reply)
};

/// Checks and parses one text message from the page. Never throws.
ParsedMessage parse_client_message(std::string_view text);

}  // namespace ddswarm::gs::web
