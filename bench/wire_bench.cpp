// Decoding one tick's swarm state, as each agent does every tick: the
// generated Fast CDR code against ddswarm's inline decoder
// (common/swarm_state_cdr.hpp), at the bench's swarm sizes. Each drone has a
// scan of 8 rays, as in the bench scenario. Prints µs per sample, bytes per
// second, and on each inline row the ratio x_faster (generated ÷ inline).
#include <benchmark/benchmark.h>
#include <fastcdr/Cdr.h>
#include <fastcdr/FastBuffer.h>

#include <chrono>
#include <random>
#include <vector>

#include "common/swarm_state_cdr.hpp"
#include "common/topics.hpp"

using namespace ddswarm;
using Payload = eprosima::fastrtps::rtps::SerializedPayload_t;

namespace {

msg::SwarmState swarm(int n) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-50, 50);
  auto vec = [&] {
    msg::Vec3 v;
    v.x(u(rng));
    v.y(u(rng));
    v.z(u(rng));
    return v;
  };
  msg::SwarmState s;
  s.tick(123456);
  s.sim_time_s(2469.12);
  for (int i = 0; i < n; ++i) {
    msg::DroneState d;
    d.drone_id(static_cast<std::uint16_t>(i));
    d.tick(123456);
    d.position(vec());
    d.velocity(vec());
    d.angular_velocity(vec());
    s.drones().push_back(d);
    msg::DistanceScan sc;
    sc.drone_id(static_cast<std::uint16_t>(i));
    sc.max_range_m(6);
    for (int k = 0; k < 8; ++k) {
      sc.angle_body_rad().push_back(0.785f * static_cast<float>(k));
      sc.range_m().push_back(static_cast<float>(u(rng) + 50) / 20);
      sc.hit().push_back(k % 2);
    }
    s.scans().push_back(sc);
  }
  return s;
}

struct Wire {
  explicit Wire(int n) : sample(swarm(n)), payload(type.getSerializedSizeProvider(&sample)()) {
    type.serialize(&sample, &payload);
  }
  msg::SwarmState sample;
  msg::SwarmStatePubSubType type;  // the generated type support
  Payload payload;
};

void BM_DecodeGenerated(benchmark::State& state) {
  Wire w(static_cast<int>(state.range(0)));
  msg::SwarmState out;
  for (auto _ : state) {
    w.type.deserialize(&w.payload, &out);
    benchmark::DoNotOptimize(out.drones().data());
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * w.payload.length);
}

/// Mean wall µs of `decode` over `reps` samples, after one to warm the caches.
template <class F>
double mean_us(F&& decode, int reps) {
  decode();
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 0; k < reps; ++k) decode();
  return std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count() /
         reps;
}

void BM_DecodeInline(benchmark::State& state) {
  Wire w(static_cast<int>(state.range(0)));
  msg::SwarmState out;
  for (auto _ : state) {
    decode_swarm_state(w.payload.data, w.payload.length, out);
    benchmark::DoNotOptimize(out.drones().data());
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations()) * w.payload.length);
  // The ratio, measured side by side here: generated µs / inline µs.
  const double gen = mean_us([&] { w.type.deserialize(&w.payload, &out); }, 500);
  const double fast =
      mean_us([&] { decode_swarm_state(w.payload.data, w.payload.length, out); }, 500);
  state.counters["x_faster"] = gen / fast;
}

}  // namespace

BENCHMARK(BM_DecodeGenerated)->Arg(6)->Arg(128)->Arg(512)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_DecodeInline)->Arg(6)->Arg(128)->Arg(512)->Unit(benchmark::kMicrosecond);
BENCHMARK_MAIN();
