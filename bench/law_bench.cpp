// What a swarm law costs per tick, per drone: the built-in laws in C++ and
// the same Reynolds-style boids in Python (examples/python_law/boids.py,
// through the Python-law plug-in), at 6 and 64 peers and the thesis's 8 rays.
// The ratio Python / C++ is printed as a counter (docs/laws.md).
//
//   build/release/bin/law_bench            (./scripts/build release)
#include <benchmark/benchmark.h>

#include <random>

#include "agent/law_registry.hpp"

using namespace ddswarm;
using namespace ddswarm::agent;

namespace {

struct Tick {
  std::vector<law::Peer> peers;
  std::vector<law::Ray> rays;
  law::Observation o;
  explicit Tick(int n_peers) {
    std::mt19937_64 g(1);
    std::uniform_real_distribution<double> u(-10, 10);
    for (int j = 0; j < n_peers; ++j)
      peers.push_back({j + 1, Eigen::Vector3d(u(g), u(g), 2), Eigen::Vector3d(0.5, 0, 0), 0});
    for (int k = 0; k < 8; ++k) rays.push_back({4.0 + k % 3, k % 2 == 0, k * 0.785, 0});
    o.p_world = {0, 0, 2};
    o.v_world = {0.6, 0, 0};
    o.peers = peers;
    o.rays = rays;
    o.phase = law::Phase::kTask;
    o.mission_velocity = {0, 0.8, 0};
  }
};

LawConfig config(const std::string& type) {
  LawConfig c;
  if (type == "thesis") c.type = LawType::kThesis;
  if (type == "reynolds") c.type = LawType::kReynolds;
  if (type == "olfati_saber") c.type = LawType::kOlfatiSaber;
  if (type == "vasarhelyi") c.type = LawType::kVasarhelyi;
  if (type == "python") {
    c.type = LawType::kPython;
    c.module = DDSWARM_SOURCE_DIR "/examples/python_law/boids.py";
    c.class_name = "Boids";
  }
  return c;
}

void law_step(benchmark::State& state, const std::string& type) {
  Tick t(static_cast<int>(state.range(0)));
  law::LawContext ctx;
  auto l = make_law(config(type), ctx, law::Rng(1), AgentConfig{});
  for (auto _ : state) {
    ++t.o.tick;
    benchmark::DoNotOptimize(l->step(t.o));
  }
  state.counters["peers"] = static_cast<double>(state.range(0));
}

}  // namespace

BENCHMARK_CAPTURE(law_step, thesis, std::string("thesis"))->Arg(6)->Arg(64);
BENCHMARK_CAPTURE(law_step, reynolds, std::string("reynolds"))->Arg(6)->Arg(64);
BENCHMARK_CAPTURE(law_step, olfati_saber, std::string("olfati_saber"))->Arg(6)->Arg(64);
BENCHMARK_CAPTURE(law_step, vasarhelyi, std::string("vasarhelyi"))->Arg(6)->Arg(64);
BENCHMARK_CAPTURE(law_step, python_boids, std::string("python"))->Arg(6)->Arg(64);

BENCHMARK_MAIN();
