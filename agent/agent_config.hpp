#pragma once
// The agent's parameters: YAML section `agent`.
//
// One struct per part (activation, sensor function) nested in AgentConfig.
// Every field has a default; validate() throws FieldError naming the dotted
// field, e.g. `agent.inter_distance_m = -4: must be > 0`. The shapes of the
// functions these parameters describe are documented in agent/swarm_law.hpp.
#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "common/agent_rejoin.hpp"
#include "common/config_fields.hpp"
#include "common/yaml_section.hpp"

namespace ddswarm::agent {

enum class ActivationType { kLinear, kCustom };

inline constexpr int kMaxNeighbours = 64;  ///< largest agent.activation.neighbours

/// The drone-to-drone activation f_rel(D_r), D_r = |d_i - d_j| - D_int
/// (thesis §2.4.1, Fig. 3/5). YAML `agent.activation`.
struct ActivationConfig {
  ActivationType type = ActivationType::kLinear;
  double attraction_gain = 0.25;
  double repulsion_gain = 1.0;
  double max_mps = 1.5;
  std::vector<Eigen::Vector2d> points;
  double cutoff_m = 0.0;
  int neighbours = 0;

  /// Every field once (common/config_fields.hpp); validate() adds the checks
  /// that relate fields, and the custom curve's.
  template <class Self, class V>
  static void fields(Self& c, V& v) {
    static const Choices<ActivationType> kTypes{{"linear", ActivationType::kLinear},
                                                {"custom", ActivationType::kCustom}};
    v.choice("type", c.type, kTypes, {"", any(), "the shape of f_rel"});
    v.field("attraction_gain", c.attraction_gain, {"1/s", positive(), "linear slope for D_r > 0"});
    v.field("repulsion_gain", c.repulsion_gain,
            {"1/s", positive(), "linear slope for D_r < 0; >= attraction_gain"});
    v.field("max_mps", c.max_mps, {"m/s", positive(), "saturation of |f_rel|, both types"});
    // D_r strictly increasing, through (0, 0), f < 0 where D_r < 0 and f > 0
    // where D_r > 0; held flat beyond the ends.
    v.field("points", c.points, {"m, m/s", any(), "custom: [[D_r, f], ...]"});
    v.field("cutoff_m", c.cutoff_m,
            {"m", non_negative(),
             "peers farther than this are ignored; 0 = none, else > inter_distance_m"});
    // The thesis's Eq. 3.2 is 0. [0, kMaxNeighbours].
    v.field("neighbours", c.neighbours,
            {"", any(), "only the k nearest peers (within cutoff_m) act; 0 = every peer"});
  }

  void validate() const;  ///< throws FieldError("agent.activation.…")
};

enum class SensorFunctionType { kFs1, kFs2, kLog, kCustom };

/// The obstacle reaction f_s(S) >= 0 (m/s) for one ray reading S (thesis
/// §2.5, §3.3 Fig. 7/8, §5 Fig. 19). YAML `agent.sensor_function`.
struct SensorFunctionConfig {
  SensorFunctionType type = SensorFunctionType::kFs1;
  double max_mps = 2.0;
  double log_gain_mps = 1.0;
  std::vector<Eigen::Vector2d> points;
  double safety_distance_m = 0.0;
  double slide_gain = 1.0;

  /// Every field once (common/config_fields.hpp); validate() adds the custom curve's checks.
  template <class Self, class V>
  static void fields(Self& c, V& v) {
    static const Choices<SensorFunctionType> kTypes{{"fs1", SensorFunctionType::kFs1},
                                                    {"fs2", SensorFunctionType::kFs2},
                                                    {"log", SensorFunctionType::kLog},
                                                    {"custom", SensorFunctionType::kCustom}};
    v.choice("type", c.type, kTypes, {"", any(), "the shape of f_s"});
    v.field("max_mps", c.max_mps, {"m/s", positive(), "fs1/fs2 plateau; log clamp"});
    v.field("log_gain_mps", c.log_gain_mps,
            {"m/s", positive(), "k in the log function k*ln(S_max/S)"});
    // S >= 0 strictly increasing, f >= 0, last f = 0 (its S is the function's
    // range); below the first S the first f holds.
    v.field("points", c.points, {"m, m/s", any(), "custom: [[S, f], ...]"});
    // The other terms lose their component toward the obstacle and the
    // repulsion is raised to agent.max_speed_mps.
    v.field(
        "safety_distance_m", c.safety_distance_m,
        {"m", non_negative(), "a hit closer than this makes obstacle repulsion dominate; 0 = off"});
    // ddswarm's addition to Eq. 3.3 (0 = the thesis's pure law): a drone dead
    // behind a pillar goes round it instead of stalling in a local minimum of
    // the potential field.
    v.field(
        "slide_gain", c.slide_gain,
        {"", in(0, 2),
         "the blocked part of the command is redirected along the obstacle's surface, times this"});
  }

  void validate() const;  ///< throws FieldError("agent.sensor_function.…")
};

/// The built-in swarm laws (docs/laws.md).
enum class LawType { kThesis, kReynolds, kOlfatiSaber, kVasarhelyi, kPlugin, kPython };

/// Which law a drone flies: YAML `agent.law` (or an override's `law`).
struct LawConfig {
  LawType type = LawType::kThesis;
  /// plugin: the law's shared library (DDSWARM_LAW_PLUGIN); a relative path
  /// is taken from the working directory.
  std::string library;
  /// python: the law's .py file (relative paths from the working directory)
  /// and its class (docs/laws.md, "A law in Python").
  std::string module, class_name;
  /// Who avoids obstacles: the law's own choice (`auto`), the law alone from
  /// the rays (`law`: no framework term C_s), or the framework (`framework`:
  /// the law sees no rays, C_s acts), so obstacle strategies can be compared.
  enum class Obstacles { kAuto, kLaw, kFramework } obstacles = Obstacles::kAuto;
  /// `params`: name -> scalar as written; each law reads and checks its own
  /// (thesis takes none: the agent section's activation and sensor_function
  /// configure it).
  std::map<std::string, std::string> params;
  std::string path = "agent.law";  ///< where it was read, for error messages
  /// Fault injection, for testing what a swarm does when a law breaks: from
  /// fault_after_s (s, sim; 0 = never) on, the law throws (`throw`) or
  /// answers NaN (`nan`) instead of its command. [0, 3600].
  enum class Fault { kNone, kNaN, kThrow } fault = Fault::kNone;
  double fault_after_s = 0;

  /// The fields read from YAML (params is read apart: each law checks its own).
  template <class Self, class V>
  static void fields(Self& c, V& v) {
    static const Choices<LawType> kTypes{{"thesis", LawType::kThesis},
                                         {"reynolds", LawType::kReynolds},
                                         {"olfati_saber", LawType::kOlfatiSaber},
                                         {"vasarhelyi", LawType::kVasarhelyi},
                                         {"plugin", LawType::kPlugin},
                                         {"python", LawType::kPython}};
    static const Choices<Obstacles> kObstacles{
        {"auto", Obstacles::kAuto}, {"law", Obstacles::kLaw}, {"framework", Obstacles::kFramework}};
    static const Choices<Fault> kFaults{
        {"none", Fault::kNone}, {"nan", Fault::kNaN}, {"throw", Fault::kThrow}};
    v.choice("type", c.type, kTypes, {"", any(), "the law"});
    v.field("library", c.library, {"", any(), "plugin: the law's shared library"});
    v.field("module", c.module, {"", any(), "python: the law's .py file"});
    v.field("class", c.class_name, {"", any(), "python: the law's class"});
    v.choice("obstacles", c.obstacles, kObstacles, {"", any(), "who avoids obstacles"});
    v.choice("fault", c.fault, kFaults,
             {"", any(), "fault injection: the law throws or answers NaN"});
    v.field("fault_after_s", c.fault_after_s,
            {"s (sim)", in(0, 3600), "when the injected fault begins"});
  }

  void validate() const;  ///< builds the law once: throws FieldError("agent.law.params.…")
  /// The thesis's law with nothing wrapped around it (no injected fault, obstacles as it chooses).
  bool plain_thesis() const {
    return type == LawType::kThesis && fault == Fault::kNone && obstacles == Obstacles::kAuto;
  }
  /// "thesis", "reynolds", ... or "plugin libmylaw.so" (the library's file name).
  std::string name() const;
};

/// A law for some drones: YAML `agent.overrides: [{ids: 3-5, law: {...}}]`.
struct LawOverride {
  std::string ids_text;  ///< as written, e.g. "3-5,7"
  std::vector<int> ids;  ///< parsed; each < scenario.drones (checked by the agent)
  LawConfig law;
};

const char* to_string(LawType t);

struct AgentConfig {
  LawConfig law;                       ///< every drone's law unless an override names it
  std::vector<LawOverride> overrides;  ///< later entries win; an id in two entries is refused
  /// The law drone id flies.
  const LawConfig& law_for(int id) const;

  double inter_distance_m = 4.0;
  ActivationConfig activation;
  SensorFunctionConfig sensor_function;
  double max_speed_mps = 3.0;
  bool altitude_hold = true;
  double altitude_gain = 1.0;
  double altitude_tolerance_m = 0.1;
  double min_altitude_m = 0.5;
  double takeoff_altitude_m = 2.0;
  double takeoff_speed_mps = 1.0;
  double landing_speed_mps = 0.5;
  double task_speed_mps = 0.8;
  double goal_gain = 0.3;
  double teleop_timeout_s = 1.0;
  double server_timeout_s = 1.0;
  double rejoin_after_s = kDefaultRejoinAfterS;
  double handshake_timeout_s = 10.0;
  double state_loss = 0.0;

  /// The agent's own fields, once (common/config_fields.hpp); law,
  /// overrides, activation and sensor_function are sections of their own.
  /// validate() adds the checks that relate fields.
  template <class Self, class V>
  static void fields(Self& c, V& v) {
    v.field("inter_distance_m", c.inter_distance_m,
            {"m", positive(), "D_int, wanted drone-to-drone distance"});
    v.field("max_speed_mps", c.max_speed_mps,
            {"m/s", positive(), "limit on the commanded speed (horizontal, then total)"});
    v.field("altitude_hold", c.altitude_hold,
            {"", any(), "hold the cruise altitude (replaces vertical R&A) while airborne"});
    v.field("altitude_gain", c.altitude_gain,
            {"1/s", positive(), "vertical P gain toward the altitude target"});
    v.field("altitude_tolerance_m", c.altitude_tolerance_m,
            {"m", positive(), "takeoff is done within this of its altitude"});
    v.field("min_altitude_m", c.min_altitude_m,
            {"m", positive(), "lowest cruise altitude above ground"});
    v.field(
        "takeoff_altitude_m", c.takeoff_altitude_m,
        {"m", positive(), "default takeoff and cruise altitude above ground; >= min_altitude_m"});
    v.field("takeoff_speed_mps", c.takeoff_speed_mps,
            {"m/s", positive(), "climb-rate limit of the altitude loop; <= max_speed_mps"});
    v.field("landing_speed_mps", c.landing_speed_mps,
            {"m/s", positive(),
             "landing descent rate, sink limit of the altitude loop; <= max_speed_mps"});
    v.field("task_speed_mps", c.task_speed_mps,
            {"m/s", positive(), "task speed when a task command carries 0; <= max_speed_mps"});
    v.field("goal_gain", c.goal_gain, {"1/s", in(1e-6, 5), "past the finish: pull toward goal_xy"});
    v.field(
        "teleop_timeout_s", c.teleop_timeout_s,
        {"s (sim)", positive(), "follow mode: the leader's teleop velocity drops to 0 after this"});
    v.field("server_timeout_s", c.server_timeout_s,
            {"s (wall)", positive(),
             "no server sample this long: server lost (logged, flagged in heartbeats)"});
    // Up to kRejoinSpread longer, spread by process.
    v.field("rejoin_after_s", c.rejoin_after_s,
            {"s (wall)", zero_or(2, 3600),
             "no scene this long after joining: join again as a new participant; 0 = never"});
    // Fast DDS 2.9 sometimes leaves a handshake pending for good. Up to
    // kRejoinSpread longer, spread by process; twice as long after each such
    // join in a row, at most 8 times.
    v.field("handshake_timeout_s", c.handshake_timeout_s,
            {"s (wall)", zero_or(2, 3600),
             "DDS Security: the server's handshake with this agent has not ended this long after "
             "it announced "
             "itself: join again; 0 = never"});
    // Real time flies on the next sample; lockstep waits sim.lockstep_resend_s for the tick again.
    v.field("state_loss", c.state_loss,
            {"share", in(0, 0.5),
             "fault injection: the share of swarm-state samples dropped on arrival"});
  }

  /// A join waits rejoin_after_s for the scene, and up to this share longer
  /// (common/agent_rejoin.hpp, which the launcher reads too).
  static constexpr double kRejoinSpread = ddswarm::kRejoinSpread;
  /// The longest a first join waits for the scene before joining again.
  double longest_scene_wait_s() const { return ddswarm::longest_scene_wait_s(rejoin_after_s); }
  void validate() const;  ///< throws FieldError("agent.…")
};

/// Reads section `agent` (and its `activation`, `sensor_function` children);
/// unknown keys throw ConfigError with file and line. Does not validate.
void load(YamlSection s, AgentConfig& c);
void load(YamlSection s, ActivationConfig& c);
void load(YamlSection s, SensorFunctionConfig& c);
void load(YamlSection s, LawConfig& c);

}  // namespace ddswarm::agent
