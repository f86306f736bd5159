// How long the web bridge takes to turn a SwarmState into the page's `frame`
// JSON (ground_station/web/web_frame.hpp): once per tick, shared by every page.
#include <benchmark/benchmark.h>

#include "bench/swarm_sample.hpp"
#include "ground_station/web/web_frame.hpp"

using namespace ddswarm;

namespace {

void BM_EncodeFrame(benchmark::State& st) {
  const auto s = bench_swarm(static_cast<int>(st.range(0)), 8);
  const bool rays = st.range(1) != 0;
  std::size_t bytes = 0;
  for (auto _ : st) {
    auto f = gs::web::to_frame(s);
    auto json = gs::web::encode_frame(f, rays);
    bytes = json.size();
    benchmark::DoNotOptimize(json);
  }
  st.counters["bytes"] = static_cast<double>(bytes);
}
BENCHMARK(BM_EncodeFrame)->ArgsProduct({{6, 128, 1024}, {0, 1}})->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
