#pragma once
// Decides whether a velocity command may be applied. Pure: no I/O, no clock.
// Every rejection has a reason that is counted in SimStatus; nothing
// rejected ever reaches a drone.
#include <Eigen/Core>
#include <cstdint>
#include <optional>

namespace ddswarm::sim {

enum class Verdict {
  kAccept,
  kNonFinite,   ///< NaN or inf anywhere
  kAbsurd,      ///< speed or yaw rate beyond any sane limit
  kUnknownId,   ///< drone id not in this scenario
  kImpostor,    ///< another agent instance already flies this drone
  kStaleTick,   ///< older than what is being collected
  kFutureTick,  ///< for a tick not yet published
  kRepeat,      ///< lockstep: the owner answers a tick published twice again; dropped
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
  std::uint64_t
      oldest_ok_tick;  ///< lockstep: published_tick; realtime: last applied tick of this drone
  std::uint64_t owner_instance;  ///< the live agent instance of this drone, 0 = none
  double max_speed_mps;
  /// Lockstep: the tick the owner's applied answer was for (none: no answer yet).
  std::optional<std::uint64_t> answered_tick = std::nullopt;
};

Verdict check_command(const CommandFacts& c, const GateContext& g);

}  // namespace ddswarm::sim
