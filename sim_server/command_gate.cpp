#include "sim_server/command_gate.hpp"

#include <cmath>

namespace ddswarm::sim {

const char* to_string(Verdict v) {
  switch (v) {
    case Verdict::kAccept:
      return "accepted";
    case Verdict::kNonFinite:
      return "non-finite value";
    case Verdict::kAbsurd:
      return "absurd value";
    case Verdict::kUnknownId:
      return "unknown drone id";
    case Verdict::kImpostor:
      return "drone already flown by another agent";
    case Verdict::kStaleTick:
      return "stale tick";
    case Verdict::kFutureTick:
      return "future tick";
    case Verdict::kRepeat:
      return "repeated answer";
  }
  return "?";
}

Verdict check_command(const CommandFacts& c, const GateContext& g) {
  if (c.drone_id < 0 || c.drone_id >= g.num_drones) return Verdict::kUnknownId;
  if (!c.velocity.allFinite() || !std::isfinite(c.yaw_rate)) return Verdict::kNonFinite;
  if (c.velocity.norm() > g.max_speed_mps || std::abs(c.yaw_rate) > 100.0) return Verdict::kAbsurd;
  if (g.owner_instance != 0 && c.instance != g.owner_instance) return Verdict::kImpostor;
  if (c.tick > g.published_tick) return Verdict::kFutureTick;
  if (c.tick < g.oldest_ok_tick)
    return c.tick == g.answered_tick ? Verdict::kRepeat : Verdict::kStaleTick;
  return Verdict::kAccept;
}

}  // namespace ddswarm::sim
