#include "common/convert.hpp"

#include <cmath>

namespace ddswarm {

std::string mission_problem(const msg::MissionCommand& m) {
  if (m.type() < 1 || m.type() > 8) return "unknown command type " + std::to_string(m.type());
  const double vals[] = {m.velocity().x(), m.velocity().y(), m.velocity().z(), m.duration_s(),
                         m.value(), m.epsilon_m()};
  for (double v : vals)
    if (!std::isfinite(v)) return "non-finite value";
  if (from_msg(m.velocity()).norm() > 50.0) return "velocity beyond 50 m/s";
  if (m.duration_s() < 0 || m.duration_s() > 86400) return "duration out of range";
  if (m.epsilon_m() < 0 || m.epsilon_m() > 1e4) return "epsilon out of range";
  auto type = static_cast<MissionType>(m.type());
  if (type == MissionType::kSetDistance && !(m.value() > 0.3 && m.value() <= 1000))
    return "distance must be in (0.3, 1000] m";
  if (type == MissionType::kTakeoff && !(m.value() >= 0 && m.value() <= 1000))
    return "altitude must be in [0, 1000] m";
  if (type == MissionType::kTask && !(m.value() >= 0 && m.value() <= 50))
    return "speed must be in [0, 50] m/s";
  if (m.target() < -1) return "target must be a drone id or -1";
  return {};
}

MissionCommand from_msg(const msg::MissionCommand& m) {
  MissionCommand c;
  c.seq = m.seq();
  c.type = static_cast<MissionType>(m.type());
  c.target = m.target();
  c.velocity = from_msg(m.velocity());
  c.duration_s = m.duration_s();
  c.value = m.value();
  c.leader_id = m.leader_id();
  c.epsilon_m = m.epsilon_m();
  c.issuer = m.issuer().to_string();
  return c;
}

msg::MissionCommand to_msg(const MissionCommand& c) {
  msg::MissionCommand m;
  m.seq(c.seq);
  m.type(static_cast<std::uint8_t>(c.type));
  m.target(c.target);
  m.velocity(to_msg(c.velocity));
  m.duration_s(c.duration_s);
  m.value(c.value);
  m.leader_id(c.leader_id);
  m.epsilon_m(c.epsilon_m);
  m.issuer(c.issuer.substr(0, 63));
  return m;
}

msg::MissionAck to_msg(const MissionAck& a, std::uint64_t issuer_instance) {
  msg::MissionAck m;
  m.drone_id(a.drone_id);
  m.seq(a.seq);
  m.issuer_instance(issuer_instance);
  m.accepted(a.accepted);
  m.reason(a.reason.substr(0, 127));
  m.phase(static_cast<std::uint8_t>(a.phase));
  m.tick(a.tick);
  return m;
}

}  // namespace ddswarm
