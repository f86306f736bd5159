#pragma once
// The edge between generated wire types and the project's plain structs:
// every conversion happens here, once.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "DistanceScan.h"
#include "Geometry.h"
#include "MissionAck.h"
#include "MissionCommand.h"
#include "Scene.h"
#include "common/mission.hpp"
#include "common/scene.hpp"

namespace ddswarm {

inline Eigen::Vector3d from_msg(const msg::Vec3& v) { return {v.x(), v.y(), v.z()}; }
inline msg::Vec3 to_msg(const Eigen::Vector3d& v) {
  msg::Vec3 m;
  m.x(v.x());
  m.y(v.y());
  m.z(v.z());
  return m;
}
inline Eigen::Quaterniond from_msg(const msg::Quat& q) { return {q.w(), q.x(), q.y(), q.z()}; }
inline msg::Quat to_msg(const Eigen::Quaterniond& q) {
  msg::Quat m;
  m.w(q.w());
  m.x(q.x());
  m.y(q.y());
  m.z(q.z());
  return m;
}

/// Why a mission command is unacceptable, or empty if it is fine: unknown
/// type, non-finite or absurd values. Shared by server and agents.
std::string mission_problem(const msg::MissionCommand& m);

/// Why a scan is unfit to fly from: its four sequences differ in length, or a
/// ray's yaw or elevation is not finite; empty when it is sound.
std::string scan_problem(const msg::DistanceScan& s);

MissionCommand from_msg(const msg::MissionCommand& m);
msg::MissionCommand to_msg(const MissionCommand& c);

msg::MissionAck to_msg(const MissionAck& a, std::uint64_t issuer_instance);

/// The world a Scene sample carries: ground, obstacles (meshes as entries,
/// their triangle counts, bounds and file hashes, not their triangles), bounds, finish line,
/// goal and the start formation's centre (the rest of StartConfig is the
/// server's, and start_positions carries where the drones stand).
SceneConfig from_msg(const msg::Scene& s);
/// A Scene sample with c's world in it; the server adds what only it knows
/// (name, seed, instance, rates, drones, sensors).
msg::Scene to_msg(const SceneConfig& c);

}  // namespace ddswarm
