#pragma once
// ddswarm's swarm-law interface: what one drone's law sees each control tick
// and what it answers. The one header a law, built in or plug-in, includes.
// Plain structs, Eigen and the standard library only.
//
// Frames and units. World frame ENU (x east, y north, z up), metres,
// seconds, metres per second. Body frame FLU (x forward, y left, z up);
// a ray's yaw is measured about body +z from body +x, its pitch up from the
// body's horizontal plane. Attitude is the rotation from body to world.
//
// The framework around a law (docs/laws.md):
//   - The mission state machine, takeoff and landing, altitude hold, the
//     speed limits and the failsafe are the framework's. The law is asked
//     only while the swarm flies (hold, move, task, swarm, follow, landing);
//     on the ground and while taking off the mission velocity flies alone.
//   - The law's velocity stands for the thesis's C + V_mission (Eq. 3.4): a
//     law that ignores the mission velocity hovers through the task.
//   - Unless the law opts out (SwarmLaw::uses_obstacle_term), the framework
//     adds the thesis's sensor term C_s (Eq. 3.3) with its safety distance
//     and slide, as agent.sensor_function configures it.
//   - With altitude hold on, the vertical part of the command is replaced by
//     the altitude loop; landing keeps the mission's descent. Then the
//     command is limited to agent.max_speed_mps.
//   - A law that throws or answers a non-finite number is faulted: its drone
//     hovers, then lands, and its agent reports the fault (AgentStatus).
//
// Determinism. A law gets its randomness from the Rng it is built with,
// seeded by the framework from scenario.seed and the drone's id: the same
// run draws the same numbers in-tree, as a plug-in and from Python.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <map>
#include <memory>
#include <numbers>
#include <set>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace ddswarm::law {

/// Bumped when anything in this header changes layout or meaning; a plug-in
/// built against another version is refused.
inline constexpr int kApiVersion = 1;

/// One other drone as this drone knows it (from the peer source: exact
/// truth, or the communication model's delayed, lossy, noisy messages).
struct Peer {
  int id = -1;                       ///< drone id
  Eigen::Vector3d p_world{0, 0, 0};  ///< m, ENU, position estimate
  /// m/s, ENU, velocity estimate; NaN in every component when the peer
  /// source carries none (exact truth has one; the communication model's
  /// messages carry positions only).
  Eigen::Vector3d v_world{0, 0, 0};
  double age_s = 0;  ///< s, sim time since the estimate was true (0 for exact truth)
};

/// One distance-sensor ray.
struct Ray {
  double range_m = 0;         ///< m, distance to the hit; meaningless when !hit
  bool hit = false;           ///< an obstacle within the sensor's range
  double yaw_body_rad = 0;    ///< rad, about body +z from body +x
  double pitch_body_rad = 0;  ///< rad, up from the body's horizontal plane (0: the thesis's ring)
};

/// Mission phases, as common/mission.hpp numbers them.
enum class Phase : std::uint8_t {
  kIdle = 0,
  kTakeoff = 1,
  kHold = 2,
  kMove = 3,
  kTask = 4,   ///< flying the thesis task toward the finish line
  kSwarm = 5,  ///< task: past the finish line, gathering at the goal
  kFollow = 6,
  kLanding = 7,
  kFailsafe = 8,
};

/// What the drone knows at one control tick. Spans live for the call only.
struct Observation {
  int drone_id = -1;
  std::uint64_t tick = 0;  ///< control tick (lockstep tick number)
  double sim_time_s = 0;   ///< s, simulation time of the sample
  double dt_s = 0.02;      ///< s, control period

  Eigen::Vector3d p_world{0, 0,
                          0};  ///< m, own position as this drone knows it (noisy with comm noise)
  Eigen::Vector3d v_world{0, 0, 0};                                  ///< m/s, own velocity
  Eigen::Quaterniond q_world_body = Eigen::Quaterniond::Identity();  ///< own attitude

  std::span<const Peer> peers;  ///< the peers this drone hears now (self excluded); may be empty
  std::span<const Ray> rays;    ///< this tick's scan; empty without sensors

  Phase phase = Phase::kHold;
  Eigen::Vector3d mission_velocity{0, 0, 0};  ///< m/s, ENU, what the mission asks (V_mission)
  /// m, ENU, the task's goal point (z = the cruise altitude); NaN outside
  /// the task phases (task, swarm).
  Eigen::Vector3d goal_world{NAN, NAN, NAN};
  double inter_distance_m = 4.0;   ///< m, D_int in force
  double altitude_target_m = 2.0;  ///< m, world z the altitude loop holds
  double max_speed_mps = 3.0;      ///< m/s, the framework's limit on the command
};

/// A law's answer for one tick.
struct Command {
  Eigen::Vector3d velocity_world{0, 0, 0};  ///< m/s, ENU; stands for C + V_mission
  double yaw_rate_rad_s = 0;                ///< rad/s; 0 holds the heading
};

/// A parameter the law refused: which, the value as written, and why.
class ParamError : public std::invalid_argument {
 public:
  ParamError(std::string field, const std::string& value, const std::string& reason)
      : std::invalid_argument(field + " = " + value + ": " + reason),
        field_(std::move(field)),
        value_(value),
        reason_(reason) {}
  const std::string& field() const { return field_; }
  const std::string& value() const { return value_; }
  const std::string& reason() const { return reason_; }

 private:
  std::string field_, value_, reason_;
};

/// A law's parameters: `agent.law.params`, a flat mapping of names to
/// scalars (numbers, booleans, strings) as written in the scenario. A law
/// reads each with a default and a range; the framework then refuses every
/// name no law read (finish), so a typo never passes silently.
class Params {
 public:
  Params() = default;
  /// prefix: the dotted path shown in errors, e.g. "agent.law.params".
  Params(std::string prefix, std::map<std::string, std::string> values)
      : prefix_(std::move(prefix)), values_(std::move(values)) {}

  bool has(const std::string& key) const { return values_.count(key) != 0; }

  /// A real number in [lo, hi]; def when absent. Throws ParamError.
  double number(const std::string& key, double def, double lo = -HUGE_VAL, double hi = HUGE_VAL) {
    const std::string* text = take(key);
    if (!text) return def;
    std::size_t used = 0;
    double v = 0;
    try {
      v = std::stod(*text, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != text->size() || !std::isfinite(v))
      throw ParamError(field(key), *text, "must be a finite number");
    if (v < lo || v > hi)
      throw ParamError(field(key), *text, "must be in [" + num(lo) + ", " + num(hi) + "]");
    return v;
  }

  /// A whole number in [lo, hi]; def when absent. Throws ParamError.
  int integer(const std::string& key, int def, int lo, int hi) {
    const std::string* text = take(key);
    if (!text) return def;
    std::size_t used = 0;
    long v = 0;
    try {
      v = std::stol(*text, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != text->size())
      throw ParamError(field(key), *text, "must be a whole number");
    if (v < lo || v > hi)
      throw ParamError(field(key), *text,
                       "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return static_cast<int>(v);
  }

  /// true/false; def when absent. Throws ParamError.
  bool flag(const std::string& key, bool def) {
    const std::string* text = take(key);
    if (!text) return def;
    if (*text == "true") return true;
    if (*text == "false") return false;
    throw ParamError(field(key), *text, "must be true or false");
  }

  /// Any text; def when absent.
  std::string text(const std::string& key, const std::string& def) {
    const std::string* t = take(key);
    return t ? *t : def;
  }

  /// One of choices; def when absent. Throws ParamError.
  std::string choice(const std::string& key, const std::string& def,
                     const std::vector<std::string>& choices) {
    const std::string* text = take(key);
    if (!text) return def;
    std::string all;
    for (const auto& c : choices) {
      if (c == *text) return c;
      all += (all.empty() ? "" : "|") + c;
    }
    throw ParamError(field(key), *text, "must be one of " + all);
  }

  /// Throws ParamError for the first parameter no getter read, naming the
  /// ones that were read (the law's parameters).
  void finish() const {
    for (const auto& [key, value] : values_) {
      if (read_.count(key)) continue;
      std::string known;
      auto add = [&](const std::string& k) {
        if (k.rfind("ddswarm:", 0) != 0)
          known += (known.empty() ? "" : ", ") + k;  // the framework's own
      };
      for (const auto& k : read_) add(k);
      for (const auto& k : asked_)
        if (!read_.count(k)) add(k);
      throw ParamError(field(key), value,
                       "unknown parameter" + (known.empty() ? std::string(" (this law takes none)")
                                                            : " (this law takes " + known + ")"));
    }
  }

  const std::map<std::string, std::string>& values() const { return values_; }
  const std::string& prefix() const { return prefix_; }

 private:
  const std::string* take(const std::string& key) {
    auto it = values_.find(key);
    if (it == values_.end()) {
      asked_.insert(key);
      return nullptr;
    }
    read_.insert(key);
    return &it->second;
  }
  std::string field(const std::string& key) const { return prefix_ + "." + key; }
  static std::string num(double v) {
    if (std::isinf(v)) return v < 0 ? "-inf" : "inf";
    std::string s = std::to_string(v);
    while (s.size() > 1 && s.back() == '0') s.pop_back();
    if (!s.empty() && s.back() == '.') s.pop_back();
    return s;
  }

  std::string prefix_ = "agent.law.params";
  std::map<std::string, std::string> values_;
  std::set<std::string> read_, asked_;
};

/// The framework's random numbers for one drone's law: xoshiro256**, seeded
/// by SplitMix64, with uniforms from the top 53 bits and normals by
/// Box-Muller, so a seed gives the same numbers with any standard library.
class Rng {
 public:
  explicit Rng(std::uint64_t seed = 0) {
    for (auto& s : s_) s = splitmix(seed);
  }
  std::uint64_t next() {
    const std::uint64_t r = rotl(s_[1] * 5, 7) * 9;
    const std::uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return r;
  }
  /// Uniform in [0, 1).
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  /// Uniform in [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  /// Normal with mean 0 and standard deviation 1.
  double normal() {
    const double u1 = 1.0 - uniform();  // (0, 1]: log(u1) is finite
    const double u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
  }

 private:
  static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  static std::uint64_t splitmix(std::uint64_t& x) {
    std::uint64_t z = (x += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  std::uint64_t s_[4];
};

/// One drone's swarm law. Built once per drone (and again when a new
/// server's scene resets the mission); step() is called once per control
/// tick while the swarm flies, from one thread.
class SwarmLaw {
 public:
  virtual ~SwarmLaw() = default;
  /// The command for this tick. Throwing, or answering NaN or infinity,
  /// faults the law (its drone lands).
  virtual Command step(const Observation& o) = 0;
  /// False: the law handles obstacles itself from o.rays, and the framework
  /// adds no sensor term C_s.
  virtual bool uses_obstacle_term() const { return true; }
};

/// What a law is built from.
struct LawContext {
  int drone_id = -1;
  int num_drones = 0;              ///< drones in the scenario
  double inter_distance_m = 4.0;   ///< m, agent.inter_distance_m (D_int at start)
  double max_speed_mps = 3.0;      ///< m/s, agent.max_speed_mps
  double control_period_s = 0.02;  ///< s, the server's control period
};

/// What a plug-in's factory is: make one drone's law, or throw ParamError.
using MakeLaw = std::unique_ptr<SwarmLaw> (*)(Params& p, Rng rng, const LawContext& ctx);

}  // namespace ddswarm::law

/// Exports a law from a plug-in library (agent.law.type: plugin). In one
/// .cpp of the library, with make_fn a function of type law::MakeLaw:
///
///   std::unique_ptr<ddswarm::law::SwarmLaw> make(ddswarm::law::Params& p,
///                                                ddswarm::law::Rng rng,
///                                                const ddswarm::law::LawContext& ctx);
///   DDSWARM_LAW_PLUGIN(make)
///
/// The agent checks ddswarm_law_api_version against its own kApiVersion and
/// refuses a plug-in built against another.
#define DDSWARM_LAW_PLUGIN(make_fn)                                                 \
  extern "C" __attribute__((visibility("default"))) int ddswarm_law_api_version() { \
    return ::ddswarm::law::kApiVersion;                                             \
  }                                                                                 \
  extern "C" __attribute__((visibility("default"))) ::ddswarm::law::MakeLaw         \
  ddswarm_law_factory() {                                                           \
    return &(make_fn);                                                              \
  }
