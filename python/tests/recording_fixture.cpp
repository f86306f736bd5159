// Writes an MCAP recording as ddswarm-record does (the project's CDR types,
// the IDL as schema), with content the Python tests can predict:
//   ddswarm/swarm_state: ticks 0..T-1 every 20 ms, drone k at
//     (k, 0.01 * tick, 2) m, velocity (0, 0.5, 0), yaw-free attitude, 8 rays
//     of range 1 + k + 0.1 * ray; drones 0..N-1, drone N-1 only from tick 10;
//   ddswarm/status: every 10th tick, its tick and the live agents 0..N-1;
//   ddswarm/task: once, at the end, complete in 81.06 s.
// With --ring64 the swarm state is written as recordings made before scans
// carried elevations were: that IDL as schema, each scan yaw, range and hit.
// With --crash-after-chunks K it ends without closing the file once K
// chunks are complete, as a killed recorder does; it prints the swarm-state
// samples a reader must then find ("swarm_state=N").
#include <CLI/CLI.hpp>

#include <cstdlib>
#include <iostream>

#include "common/mcap/mcap_writer.hpp"
#include "common/swarm_state_cdr.hpp"
#include "common/topics.hpp"
#include "ddswarm_idl_text.hpp"

using namespace ddswarm;

namespace {
template <class T>
std::vector<std::uint8_t> to_cdr(const T& sample) {
  typename Topic<T>::PubSub type;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(
      type.getSerializedSizeProvider(const_cast<T*>(&sample))());
  if (!type.serialize(const_cast<T*>(&sample), &payload))
    throw std::runtime_error("cannot serialize");
  return std::vector<std::uint8_t>(payload.data, payload.data + payload.length);
}
/// That IDL: today's without the elevations.
std::string ring64_idl() {
  std::string idl = kIdlText;
  const auto at = idl.find("  sequence<float, 256> elevation_body_rad;");
  idl.erase(at, idl.find('\n', at) + 1 - at);
  return idl;
}
template <class T>
std::uint16_t channel(mcap::Writer& w, const std::string& idl = kIdlText) {
  typename Topic<T>::PubSub type;
  return w.add_channel(w.add_schema(type.getName(), "omgidl", idl), Topic<T>::name, "cdr", {});
}
msg::Vec3 vec(double x, double y, double z) {
  msg::Vec3 v;
  v.x(x);
  v.y(y);
  v.z(z);
  return v;
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Write a recording with known content for the Python package's tests"};
  std::string out;
  int ticks = 300, drones = 4;
  unsigned crash_after_chunks = 0;
  bool ring64 = false;
  app.add_option("output", out)->required();
  app.add_option("--ticks", ticks);
  app.add_option("--drones", drones);
  app.add_option("--crash-after-chunks", crash_after_chunks);
  app.add_flag("--ring64", ring64);
  CLI11_PARSE(app, argc, argv);
  mcap::WriterOptions opt;
  opt.chunk_size_bytes = 16 * 1024;
  mcap::Writer w(out, opt);
  const auto c_state = channel<msg::SwarmState>(w, ring64 ? ring64_idl() : kIdlText),
             c_status = channel<msg::SimStatus>(w), c_task = channel<msg::TaskStatus>(w);
  std::uint64_t states = 0, durable = 0, chunks = 0;
  for (int tick = 0; tick < ticks; ++tick) {
    const std::uint64_t t_ns = 1'000'000'000ull + static_cast<std::uint64_t>(tick) * 20'000'000ull;
    msg::SwarmState s;
    s.tick(tick);
    s.sim_time_s(0.02 * tick);
    for (int k = 0; k < drones; ++k) {
      if (k == drones - 1 && tick < 10) continue;
      msg::DroneState d;
      d.drone_id(k);
      d.tick(tick);
      d.position(vec(k, 0.01 * tick, 2));
      d.velocity(vec(0, 0.5, 0));
      msg::Quat q;
      q.w(1);
      d.orientation(q);
      d.flags(msg::DRONE_AIRBORNE | msg::DRONE_AGENT_LIVE);
      d.phase(4);
      s.drones().push_back(d);
      msg::DistanceScan sc;
      sc.drone_id(k);
      for (int r = 0; r < 8; ++r) {
        sc.range_m().push_back(static_cast<float>(1 + k + 0.1 * r));
        sc.hit().push_back(r % 2);
        sc.angle_body_rad().push_back(static_cast<float>(r * 0.785398));
        sc.elevation_body_rad().push_back(0.0f);
      }
      s.scans().push_back(sc);
    }
    const auto bytes = ring64 ? encode_swarm_state(s, false, ScanLayout::kRing64) : to_cdr(s);
    w.write(c_state, t_ns, t_ns, bytes.data(), bytes.size());
    ++states;
    if (w.chunks_written() != chunks) {
      chunks = w.chunks_written();
      durable = states;  // the write closed a chunk, which holds every sample so far
      if (chunks == crash_after_chunks) {
        std::cout << "swarm_state=" << durable << std::endl;
        std::_Exit(0);
      }
    }
    if (tick % 10 == 0) {
      msg::SimStatus st;
      st.tick(tick);
      st.num_drones(drones);
      for (int k = 0; k < drones; ++k) st.live_agents().push_back(k);
      st.state("running");
      const auto b = to_cdr(st);
      w.write(c_status, t_ns, t_ns, b.data(), b.size());
    }
  }
  msg::TaskStatus task;
  task.phase(msg::TASK_COMPLETE);
  task.elapsed_s(81.06);
  task.reason("complete");
  const auto b = to_cdr(task);
  w.write(c_task, 9'000'000'000ull, 9'000'000'000ull, b.data(), b.size());
  w.close();
  std::cout << "swarm_state=" << states << std::endl;
}
