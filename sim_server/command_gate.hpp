#pragma once
// Decides whether a velocity command may be applied. Pure: no I/O, no clock.
// Every rejection has a reason that is counted in SimStatus; nothing
// rejected ever reaches a drone.
#include <Eigen/Core>
#include <cstdint>

namespace ddswarm::sim {

enum class Verdict {
  kAccept,
  kNonFinite,    ///< NaN or inf anywhere
  kAbsurd,       ///< speed or yaw rate beyond any sane limit
  kUnknownId,    ///< drone id not in this scenario
  kImpostor,     ///< another agent instance already flies this drone
  kStaleTick,    ///< older than what is being collected
  kFutureTick,   ///< for a tick not yet published
};

const char* to_string(Verdict v);

struct CommandFacts {
  int drone_id;
  std::uint64_t tick;
  Eigen::Vector3d velocity;
  double yaw_rate;
  std::uint64_t instance;
};

struct GateContext {
  int num_drones;
  std::uint64_t published_tick;  ///< newest tick published
  std::uint64_t oldest_ok_tick;  ///< lockstep: published_tick; realtime: last applied tick of this drone
  std::uint64_t owner_instance;  ///< the live agent instance of this drone, 0 = none
  double max_speed_mps;
};

Verdict check_command(const CommandFacts& c, const GateContext& g);

/// While no live agent at all has been heard within agent_timeout_s, an agent
/// is declared lost only after this many timeouts.
constexpr double kSilentSwarmTimeouts = 3.0;

/// How long (wall s) a live agent may stay silent before the server declares
/// it lost: agent_timeout_s, or kSilentSwarmTimeouts times that while every
/// live agent is silent, since then the silence may be the server's own (Fast
/// DDS stalled its receive threads for over a second while it dropped a killed
/// agent's participant, and every other agent was declared lost with it).
/// newest_heard_s: when any live agent was last heard.
double agent_silence_limit(double now_s, double newest_heard_s, double agent_timeout_s);

}  // namespace ddswarm::sim
