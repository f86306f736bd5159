// libFuzzer: command validation, from the bytes a hostile participant could
// put on the wire. The first byte picks the message:
//   even: a VelocityCommand sample, deserialised as Fast DDS does it, then the
//         server's command gate (sim_server/command_gate) with a fuzzed context;
//   odd:  a MissionCommand sample, deserialised likewise, then mission_problem()
//         (server and agents) and, when it passes, the agent's MissionFsm in
//         idle and in hold.
// Invariants: deserialising never throws or crashes; whatever the gate accepts
// is finite, within the speed limit, for a known drone, its owner, and a tick
// in the window; whatever mission_problem() passes has a known type and
// finite values, and leaves the FSM's outputs finite.
#include <fuzzer/FuzzedDataProvider.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "agent/mission_fsm.hpp"
#include "common/convert.hpp"
#include "common/topics.hpp"
#include "sim_server/command_gate.hpp"
#include "tests/fuzz/fuzz_check.hpp"

using namespace ddswarm;

namespace {

template <class T>
bool deserialise(std::vector<std::uint8_t>& bytes, T& out) {
  eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<std::uint32_t>(bytes.size()));
  if (!bytes.empty()) std::memcpy(payload.data, bytes.data(), bytes.size());
  payload.length = static_cast<std::uint32_t>(bytes.size());
  typename Topic<T>::PubSub type;
  return type.deserialize(&payload, &out);
}

void velocity_command(FuzzedDataProvider& fdp) {
  sim::GateContext g{};
  g.num_drones = fdp.ConsumeIntegralInRange(1, 1024);
  g.published_tick = fdp.ConsumeIntegral<std::uint64_t>();
  g.oldest_ok_tick = fdp.ConsumeIntegralInRange<std::uint64_t>(0, g.published_tick);
  g.owner_instance = fdp.ConsumeBool() ? 0 : fdp.ConsumeIntegral<std::uint64_t>();
  g.max_speed_mps = fdp.ConsumeFloatingPointInRange(0.01, 1000.0);
  auto bytes = fdp.ConsumeRemainingBytes<std::uint8_t>();
  msg::VelocityCommand c;
  if (!deserialise(bytes, c)) return;  // refused by the wire layer: never reaches the gate
  sim::CommandFacts f{c.drone_id(), c.tick(), from_msg(c.velocity()), c.yaw_rate_rad_s(),
                      c.agent_instance()};
  const sim::Verdict v = sim::check_command(f, g);
  FUZZ_CHECK(sim::to_string(v) != nullptr);
  if (v != sim::Verdict::kAccept) return;
  FUZZ_CHECK(f.drone_id >= 0 && f.drone_id < g.num_drones);
  FUZZ_CHECK(f.velocity.allFinite() && std::isfinite(f.yaw_rate));
  FUZZ_CHECK(f.velocity.norm() <= g.max_speed_mps && std::abs(f.yaw_rate) <= 100.0);
  FUZZ_CHECK(g.owner_instance == 0 || f.instance == g.owner_instance);
  FUZZ_CHECK(f.tick >= g.oldest_ok_tick && f.tick <= g.published_tick);
}

void check_output(const agent::MissionOutput& out) {
  FUZZ_CHECK(out.mission_velocity.allFinite());
  FUZZ_CHECK(std::isfinite(out.altitude_target_m));
  FUZZ_CHECK(std::isfinite(out.inter_distance_m) && out.inter_distance_m > 0);
  FUZZ_CHECK(static_cast<int>(out.phase) <= static_cast<int>(Phase::kFailsafe));
}

void mission_command(FuzzedDataProvider& fdp) {
  const bool airborne = fdp.ConsumeBool();
  auto bytes = fdp.ConsumeRemainingBytes<std::uint8_t>();
  msg::MissionCommand m;
  if (!deserialise(bytes, m)) return;
  if (!mission_problem(m).empty()) return;  // rejected and counted by server and agents
  FUZZ_CHECK(m.type() >= 1 && m.type() <= 8);
  FUZZ_CHECK(std::isfinite(m.value()) && std::isfinite(m.duration_s()) &&
             std::isfinite(m.epsilon_m()));
  FUZZ_CHECK(from_msg(m.velocity()).allFinite());

  agent::AgentConfig cfg;
  SceneConfig scene;
  agent::MissionFsm fsm(0, cfg, scene);
  agent::Observation o;
  if (airborne) {  // take off and reach hold first, so airborne-only commands are exercised
    MissionCommand takeoff;
    takeoff.seq = 1;
    takeoff.type = MissionType::kTakeoff;
    takeoff.issuer = "fuzz-setup";
    fsm.apply(takeoff, o);
    for (int i = 0; i < 3; ++i) {
      auto out = fsm.step(o);
      o.sim_time_s += 0.02;
      o.on_ground = false;
      o.p_world.z() = out.altitude_target_m;
    }
  }
  MissionCommand c = from_msg(m);
  const MissionAck ack = fsm.apply(c, o);
  FUZZ_CHECK(ack.accepted || !ack.reason.empty());
  for (int i = 0; i < 5; ++i) {
    o.sim_time_s += 0.5;
    check_output(fsm.step(o));
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 4096) return -1;
  FuzzedDataProvider fdp(data, size);
  if (fdp.ConsumeIntegral<std::uint8_t>() % 2 == 0)
    velocity_command(fdp);
  else
    mission_command(fdp);
  return 0;
}
