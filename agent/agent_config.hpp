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

#include "common/yaml_section.hpp"

namespace ddswarm::agent {

enum class ActivationType { kLinear, kCustom };

inline constexpr int kMaxNeighbours = 64;  ///< largest agent.activation.neighbours

/// The drone-to-drone activation f_rel(D_r), D_r = |d_i - d_j| - D_int
/// (thesis §2.4.1, Fig. 3/5). YAML `agent.activation`.
struct ActivationConfig {
  ActivationType type = ActivationType::kLinear;  ///< linear | custom
  double attraction_gain = 0.25;                  ///< 1/s, linear slope for D_r > 0; > 0
  double repulsion_gain = 1.0;  ///< 1/s, linear slope for D_r < 0; >= attraction_gain
  double max_mps = 1.5;         ///< m/s, |f_rel| saturation (both types); > 0
  /// custom: [[D_r m, f m/s], ...], D_r strictly increasing, through (0, 0),
  /// f < 0 where D_r < 0 and f > 0 where D_r > 0; held flat beyond the ends.
  std::vector<Eigen::Vector2d> points;
  double cutoff_m = 0.0;  ///< m, peers farther than this are ignored; 0 = no cutoff; else > D_int
  /// Topological neighbourhood: only the k nearest peers (within cutoff_m)
  /// act on a drone; 0 = every peer (the thesis's Eq. 3.2). [0, kMaxNeighbours].
  int neighbours = 0;

  void validate() const;  ///< throws FieldError("agent.activation.…")
};

enum class SensorFunctionType { kFs1, kFs2, kLog, kCustom };

/// The obstacle reaction f_s(S) >= 0 (m/s) for one ray reading S (thesis
/// §2.5, §3.3 Fig. 7/8, §5 Fig. 19). YAML `agent.sensor_function`.
struct SensorFunctionConfig {
  SensorFunctionType type = SensorFunctionType::kFs1;  ///< fs1 | fs2 | log | custom
  double max_mps = 2.0;                                ///< m/s, fs1/fs2 plateau and log clamp; > 0
  double log_gain_mps = 1.0;  ///< m/s, k in the log function k*ln(S_max/S); > 0
  /// custom: [[S m, f m/s], ...], S >= 0 strictly increasing, f >= 0, last f = 0
  /// (its S is the function's range); below the first S the first f holds.
  std::vector<Eigen::Vector2d> points;
  /// m, 0 = off. A hit closer than this makes obstacle repulsion dominate:
  /// the other terms lose their component toward the obstacle and the
  /// repulsion is raised to agent.max_speed_mps. >= 0.
  double safety_distance_m = 0.0;
  /// Slide along obstacles (ddswarm's addition to Eq. 3.3, 0 = the thesis's pure
  /// law): when the obstacle term opposes the rest of the command, that blocked
  /// part is redirected along the obstacle's surface, scaled by this gain, so a
  /// drone dead behind a pillar goes round it instead of stalling in a local
  /// minimum of the potential field. [0, 2].
  double slide_gain = 1.0;

  void validate() const;  ///< throws FieldError("agent.sensor_function.…")
};

/// The built-in swarm laws (docs/laws.md).
enum class LawType { kThesis, kReynolds, kOlfatiSaber, kVasarhelyi, kPlugin, kPython };

/// Which law a drone flies: YAML `agent.law` (or an override's `law`).
struct LawConfig {
  LawType type = LawType::kThesis;  ///< thesis | reynolds | olfati_saber | vasarhelyi | plugin | python
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

  double inter_distance_m = 4.0;  ///< m, D_int, wanted drone-to-drone distance; > 0
  ActivationConfig activation;
  SensorFunctionConfig sensor_function;
  double max_speed_mps = 3.0;  ///< m/s, limit on the commanded speed (horizontal and total); > 0
  bool altitude_hold = true;   ///< hold cruise altitude (replaces vertical R&A) while airborne
  double altitude_gain = 1.0;  ///< 1/s, vertical P gain toward the altitude target; > 0
  double altitude_tolerance_m = 0.1;  ///< m, takeoff is done within this of its altitude; > 0
  double min_altitude_m = 0.5;        ///< m above ground, lowest cruise altitude (move/hold); > 0
  double takeoff_altitude_m = 2.0;    ///< m above ground, default takeoff/cruise altitude; >= min
  double takeoff_speed_mps = 1.0;     ///< m/s, climb rate limit; (0, max_speed]
  double landing_speed_mps = 0.5;  ///< m/s, descent rate, altitude-hold sink limit; (0, max_speed]
  double task_speed_mps = 0.8;     ///< m/s, task speed when the command gives 0; (0, max_speed]
  double goal_gain = 0.3;         ///< 1/s, task gathering: pull toward the goal point, (0, 5]
  double teleop_timeout_s = 1.0;   ///< s (sim), leader's teleop velocity drops to 0 after this; > 0
  double server_timeout_s = 1.0;   ///< s (wall): no server sample this long = server lost (logged once, flagged in heartbeats); > 0
  double rejoin_after_s = 40.0;  ///< s (wall): no scene this long after joining: leave DDS and join
                                 ///< again as a new participant (0 = never)
  /// s (wall), under DDS Security: the server announced itself this long ago
  /// and its authentication handshake with this agent has not ended (Fast
  /// DDS 2.9 sometimes leaves one so for good): the agent joins again as a
  /// new participant (0 = never). Up to 1.5 times as long,
  /// spread by process (kRejoinSpread); twice as long after each such join
  /// in a row, at most 8 times.
  double handshake_timeout_s = 10.0;
  /// A join waits rejoin_after_s for the scene, and up to this share longer,
  /// different in every process: when a whole swarm missed the server, its
  /// agents must not all re-join at once.
  static constexpr double kRejoinSpread = 0.5;
  /// The longest a first join waits for the scene before joining again.
  double longest_scene_wait_s() const { return rejoin_after_s * (1.0 + kRejoinSpread); }
  /// Fault injection: the share of the server's swarm-state samples this
  /// agent drops on arrival, as if lost on the way; [0, 0.5]. Real time flies
  /// on the next sample; lockstep waits sim.lockstep_resend_s for the tick again.
  double state_loss = 0.0;

  void validate() const;  ///< throws FieldError("agent.…")
};

/// Reads section `agent` (and its `activation`, `sensor_function` children);
/// unknown keys throw ConfigError with file and line. Does not validate.
void load(YamlSection s, AgentConfig& c);
void load(YamlSection s, ActivationConfig& c);
void load(YamlSection s, SensorFunctionConfig& c);
void load(YamlSection s, LawConfig& c);

}  // namespace ddswarm::agent
