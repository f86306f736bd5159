#include "common/convert.hpp"

#include <cmath>

namespace ddswarm {

std::string mission_problem(const msg::MissionCommand& m) {
  if (m.type() < 1 || m.type() > 8) return "unknown command type " + std::to_string(m.type());
  const double vals[] = {m.velocity().x(), m.velocity().y(), m.velocity().z(),
                         m.duration_s(),   m.value(),        m.epsilon_m()};
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

std::string scan_problem(const msg::DistanceScan& s) {
  const std::size_t n = s.range_m().size();
  if (s.angle_body_rad().size() != n || s.elevation_body_rad().size() != n || s.hit().size() != n)
    return "its sequences differ in length (yaw " + std::to_string(s.angle_body_rad().size()) +
           ", elevation " + std::to_string(s.elevation_body_rad().size()) + ", range " +
           std::to_string(n) + ", hit " + std::to_string(s.hit().size()) + ")";
  for (std::size_t k = 0; k < n; ++k)
    if (!std::isfinite(s.angle_body_rad()[k]) || !std::isfinite(s.elevation_body_rad()[k]))
      return "ray " + std::to_string(k) + "'s direction is not finite";
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

namespace {
msg::Vec3 xy(const Eigen::Vector2d& p) { return to_msg(Eigen::Vector3d(p.x(), p.y(), 0)); }
}  // namespace

SceneConfig from_msg(const msg::Scene& s) {
  SceneConfig c;
  c.ground_z_m = s.ground_z_m();
  for (const auto& cy : s.cylinders())
    c.cylinders.push_back({Eigen::Vector2d(cy.x(), cy.y()), cy.radius_m(), cy.height_m()});
  for (const auto& b : s.boxes())
    c.boxes.push_back({from_msg(b.center()), from_msg(b.size()), b.yaw_rad()});
  for (const auto& m : s.meshes()) {
    MeshObstacle o;
    o.file = m.file().to_string();
    o.position = from_msg(m.position());
    o.rotation_deg = from_msg(m.rotation_deg());
    o.yaw_deg = m.yaw_deg();
    o.scale = m.scale();
    o.bounds_min = from_msg(m.bounds_min());
    o.bounds_max = from_msg(m.bounds_max());
    o.triangle_count = m.triangle_count();
    o.content_hash = m.content_hash();
    c.meshes.push_back(std::move(o));
  }
  c.bounds_min = from_msg(s.bounds_min());
  c.bounds_max = from_msg(s.bounds_max());
  c.finish_a = from_msg(s.finish_a()).head<2>();
  c.finish_b = from_msg(s.finish_b()).head<2>();
  c.goal_xy = from_msg(s.goal()).head<2>();
  c.start.center_xy = from_msg(s.start_center()).head<2>();
  return c;
}

msg::Scene to_msg(const SceneConfig& c) {
  msg::Scene s;
  s.ground_z_m(c.ground_z_m);
  for (const auto& cy : c.cylinders) {
    msg::Cylinder m;
    m.x(cy.center_xy.x());
    m.y(cy.center_xy.y());
    m.radius_m(cy.radius_m);
    m.height_m(cy.height_m);
    s.cylinders().push_back(m);
  }
  for (const auto& b : c.boxes) {
    msg::Box m;
    m.center(to_msg(b.center));
    m.size(to_msg(b.size));
    m.yaw_rad(b.yaw_rad);
    s.boxes().push_back(m);
  }
  for (const auto& o : c.meshes) {
    msg::Mesh m;
    m.file(o.file.substr(0, 255));
    m.position(to_msg(o.position));
    m.rotation_deg(to_msg(o.rotation_deg));
    m.yaw_deg(o.yaw_deg);
    m.scale(o.scale);
    m.bounds_min(to_msg(o.bounds_min));
    m.bounds_max(to_msg(o.bounds_max));
    m.triangle_count(o.triangle_count);
    m.content_hash(o.content_hash);
    s.meshes().push_back(m);
  }
  s.bounds_min(to_msg(c.bounds_min));
  s.bounds_max(to_msg(c.bounds_max));
  s.finish_a(xy(c.finish_a));
  s.finish_b(xy(c.finish_b));
  s.goal(xy(c.goal_xy));
  s.start_center(xy(c.start.center_xy));
  return s;
}

}  // namespace ddswarm
