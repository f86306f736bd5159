#include "agent/law_frame.hpp"

#include <fmt/format.h>

#include <cmath>
#include <exception>

#include "common/config_error.hpp"

namespace ddswarm::agent {

LawStep step_law(law::SwarmLaw* law, const law::Observation& o, const LawInput& in,
                 const AgentConfig& c) {
  LawStep r;
  if (in.swarm_enabled && law) {
    law::Command cmd;
    try {
      cmd = law->step(o);
      if (!cmd.velocity_world.allFinite() || !std::isfinite(cmd.yaw_rate_rad_s))
        r.fault = fmt::format("answered a non-finite command (velocity {} {} {}, yaw rate {})",
                              cmd.velocity_world.x(), cmd.velocity_world.y(),
                              cmd.velocity_world.z(), cmd.yaw_rate_rad_s);
    } catch (const std::exception& e) {
      r.fault = one_line(std::string("threw: ") + e.what());
    } catch (...) {
      r.fault = "threw something that is not a std::exception";
    }
    if (r.fault.empty()) {
      Eigen::Vector3d other = cmd.velocity_world;
      if (in.swarm_horizontal_only) other.z() = in.mission_velocity.z();
      r.yaw_rate_rad_s = cmd.yaw_rate_rad_s;
      r.terms = frame_law(in, other - in.mission_velocity, other, law->uses_obstacle_term(), c);
      return r;
    }
  }
  // The swarm off: exactly evaluate_law's expression with C = 0.
  Eigen::Vector3d swarm = Eigen::Vector3d::Zero();
  r.terms = frame_law(in, swarm, swarm + in.mission_velocity, true, c);
  return r;
}

}  // namespace ddswarm::agent
