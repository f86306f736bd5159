#include "sim_server/failsafe_policy.hpp"

#include <algorithm>

namespace ddswarm::sim {

FailsafePolicy::FailsafePolicy(int drones, FailsafeRules rules)
    : rules_(rules), since_s_(static_cast<std::size_t>(drones), -1.0) {}

SetpointChoice FailsafePolicy::choose(int i, const CommandView& c, std::uint64_t tick,
                                      bool airborne, const VelocitySetpoint& applied) {
  SetpointChoice out;
  const double t = static_cast<double>(tick) * rules_.period_s;
  double& since = since_s_[i];
  const bool fresh =
      c.has_command && c.live &&
      (static_cast<double>(tick - std::min(tick, c.command_tick)) * rules_.period_s <=
       rules_.command_timeout_s);
  if (fresh) {
    if (since >= 0) out.change = SetpointChoice::Change::kResumed;
    since = -1;
    out.setpoint = c.setpoint;
    out.fresh = true;
    out.command_age_s =
        static_cast<float>((tick - std::min(tick, c.command_tick)) * rules_.period_s);
    return out;
  }
  if (since < 0) {
    if (!airborne && !applied.motors_on) {  // idle on the ground: not a failsafe
      out.setpoint = applied;
      return out;
    }
    since = t;
    out.change = SetpointChoice::Change::kEntered;
  }
  VelocitySetpoint sp;
  sp.motors_on = airborne || (t - since < rules_.land_after_s);
  if (t - since >= rules_.land_after_s) sp.v_world = {0, 0, -0.5};
  if (!airborne && t - since >= rules_.land_after_s) sp.motors_on = false;
  out.setpoint = sp;
  return out;
}

}  // namespace ddswarm::sim
