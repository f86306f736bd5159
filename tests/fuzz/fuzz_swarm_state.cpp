// libFuzzer: the swarm-state decoder (common/swarm_state_cdr), which every
// agent runs on every tick's sample from the wire. The first byte picks the input:
//   even: the rest is a payload as Fast DDS hands it over (encapsulation first);
//   odd:  the rest builds a SwarmState, which is encoded in the byte order it
//         names, and then has some of its bytes overwritten.
// Invariants: decoding never crashes, reads past the buffer or leaks; a
// sample it accepts has no sequence beyond its IDL bound, and the generated
// code accepts the same bytes and reads the same sample from them.
#include <fastcdr/exceptions/Exception.h>
#include <fuzzer/FuzzedDataProvider.h>

#include <cstring>
#include <vector>

#include "common/swarm_state_cdr.hpp"
#include "common/topics.hpp"
#include "tests/fuzz/fuzz_check.hpp"

using namespace ddswarm;

namespace {

msg::Vec3 vec(FuzzedDataProvider& f) {
  msg::Vec3 v;
  v.x(f.ConsumeFloatingPoint<double>());
  v.y(f.ConsumeFloatingPoint<double>());
  v.z(f.ConsumeFloatingPoint<double>());
  return v;
}

msg::SwarmState build(FuzzedDataProvider& f) {
  msg::SwarmState s;
  s.tick(f.ConsumeIntegral<std::uint64_t>());
  s.sim_time_s(f.ConsumeFloatingPoint<double>());
  for (int i = 0, n = f.ConsumeIntegralInRange(0, 24); i < n; ++i) {
    msg::DroneState d;
    d.drone_id(f.ConsumeIntegral<std::uint16_t>());
    d.tick(f.ConsumeIntegral<std::uint64_t>());
    d.position(vec(f));
    d.velocity(vec(f));
    d.flags(f.ConsumeIntegral<std::uint16_t>());
    d.phase(f.ConsumeIntegral<std::uint8_t>());
    d.command_age_s(f.ConsumeFloatingPoint<float>());
    s.drones().push_back(d);
    msg::DistanceScan sc;
    sc.drone_id(static_cast<std::uint16_t>(i));
    sc.max_range_m(f.ConsumeFloatingPoint<float>());
    for (int k = 0, rays = f.ConsumeIntegralInRange(0, 256); k < rays; ++k) {
      sc.angle_body_rad().push_back(f.ConsumeFloatingPoint<float>());
      sc.elevation_body_rad().push_back(f.ConsumeFloatingPoint<float>());
      sc.range_m().push_back(f.ConsumeFloatingPoint<float>());
      sc.hit().push_back(f.ConsumeIntegral<std::uint8_t>());
    }
    s.scans().push_back(sc);
    if (f.ConsumeBool()) {
      msg::Beacon b;
      b.drone_id(static_cast<std::uint16_t>(i));
      b.position(vec(f));
      s.beacons().push_back(b);
    }
  }
  for (int k = 0, n = f.ConsumeIntegralInRange(0, 8); k < n; ++k) {
    msg::MissionCommand c;
    c.seq(f.ConsumeIntegral<std::uint32_t>());
    c.type(f.ConsumeIntegral<std::uint8_t>());
    c.value(f.ConsumeFloatingPoint<double>());
    c.issuer() = f.ConsumeRandomLengthString(64).c_str();
    s.recent_commands().push_back(c);
  }
  return s;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 65536) return -1;
  FuzzedDataProvider fdp(data, size);
  std::vector<std::uint8_t> bytes;
  if (fdp.ConsumeIntegral<std::uint8_t>() % 2 == 0) {
    bytes = fdp.ConsumeRemainingBytes<std::uint8_t>();
  } else {
    const bool big = fdp.ConsumeBool();
    const int edits = fdp.ConsumeIntegralInRange(0, 4);
    std::vector<std::pair<std::size_t, std::uint8_t>> at;
    for (int k = 0; k < edits; ++k)
      at.emplace_back(fdp.ConsumeIntegral<std::uint16_t>(), fdp.ConsumeIntegral<std::uint8_t>());
    bytes = encode_swarm_state(build(fdp), big);
    for (const auto& [pos, b] : at)
      if (!bytes.empty()) bytes[pos % bytes.size()] = b;
  }
  msg::SwarmState fast;
  if (!decode_swarm_state(bytes.data(), bytes.size(), fast)) return 0;
  FUZZ_CHECK(fast.drones().size() <= 1024 && fast.scans().size() <= 1024 &&
             fast.beacons().size() <= 1024 && fast.recent_commands().size() <= 8);
  for (const auto& sc : fast.scans())
    FUZZ_CHECK(sc.angle_body_rad().size() <= 256 && sc.elevation_body_rad().size() <= 256 &&
               sc.range_m().size() <= 256 && sc.hit().size() <= 256);
  // The generated code reads the same bytes to the same sample.
  msg::SwarmStatePubSubType generated;
  eprosima::fastrtps::rtps::SerializedPayload_t p(static_cast<std::uint32_t>(bytes.size()));
  if (!bytes.empty()) std::memcpy(p.data, bytes.data(), bytes.size());
  p.length = static_cast<std::uint32_t>(bytes.size());
  msg::SwarmState slow;
  bool ok = false;
  try {
    ok = generated.deserialize(&p, &slow);
  } catch (const eprosima::fastcdr::exception::Exception&) {
  }
  FUZZ_CHECK(ok);
  FUZZ_CHECK(encode_swarm_state(fast, false) == encode_swarm_state(slow, false));
  return 0;
}
