// Decoding one tick's swarm state, as each agent does every tick: the
// generated Fast CDR code against ddswarm's inline decoder
// (common/swarm_state_cdr.hpp), at the bench's swarm sizes. Each drone has a
// scan of 8 rays, as in the bench scenario. Prints µs per sample, bytes per
// second, and on each inline row the ratio x_faster (generated ÷ inline).
#include <benchmark/benchmark.h>

#include <chrono>

#include "bench/swarm_sample.hpp"
#include "common/swarm_state_cdr.hpp"
#include "common/topics.hpp"

using namespace ddswarm;
using Payload = eprosima::fastrtps::rtps::SerializedPayload_t;

namespace {

struct Wire {
  explicit Wire(int n)
      : sample(bench_swarm(n, 8)), payload(type.getSerializedSizeProvider(&sample)()) {
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
