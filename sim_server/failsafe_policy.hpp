#pragma once
// What the server flies a drone with for one control period: its agent's
// fresh command, or the failsafe when there is none (hover in place, land
// after a while: PX4's offboard-loss behaviour). Pure: no DDS, no clock, no
// I/O; times are sim time in s, counted from ticks.
#include <cstdint>
#include <vector>

#include "sim_server/flight_controller.hpp"
#include "sim_server/tick_barrier.hpp"

namespace ddswarm::sim {

struct FailsafeRules {
  double period_s = 0.02;          ///< s sim time per tick (1 / control_rate_hz)
  double command_timeout_s = 0.5;  ///< s sim time: an older command is not fresh
  double land_after_s = 5.0;       ///< s in failsafe before the drone descends and stops
};

/// One drone's setpoint for the coming period.
struct SetpointChoice {
  enum class Change {
    kNone,
    kResumed,  ///< a fresh command again: the drone leaves failsafe
    kEntered,  ///< no fresh command: the drone enters failsafe
  };
  VelocitySetpoint setpoint;  ///< world frame; what flies the period
  bool fresh = false;         ///< the agent's command flies (count it as applied)
  float command_age_s = 0;    ///< fresh: s sim time since the tick it answered
  Change change = Change::kNone;
};

class FailsafePolicy {
 public:
  FailsafePolicy(int drones, FailsafeRules rules);
  /// Drone i at `tick`: c is its command in force, airborne whether it is
  /// above the airborne height, applied what flew the period before. A drone
  /// idle on the ground with no fresh command keeps `applied` and is not in
  /// failsafe.
  SetpointChoice choose(int i, const CommandView& c, std::uint64_t tick, bool airborne,
                        const VelocitySetpoint& applied);
  /// Drone i is in failsafe (the server flies it).
  bool active(int i) const { return since_s_[i] >= 0; }

 private:
  FailsafeRules rules_;
  std::vector<double> since_s_;  ///< sim time entered failsafe, < 0 = not in failsafe
};

}  // namespace ddswarm::sim
