// The sparse grid against the dense grid on the shipped scenes, as the runner runs them
// (stamp, erode, relax at the end): per-step time (p50), relaxation time and memory. The
// two back-ends compute the same heights (tests/unit/sparse_terrain_test.cpp), so the
// ratios are the price of the sparse storage alone.
//
//   build/<dir>/tests/sparse_bench --benchmark_repetitions=7
//       --benchmark_enable_random_interleaving=true --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "common/scene.hpp"
#include "harness/run/backends.hpp"
#include "harness/run/runner.hpp"

namespace {

const sb::PreparedScene& scene(const std::string& name) {
  static std::vector<std::pair<std::string, sb::PreparedScene>> cache;
  for (const auto& [n, p] : cache)
    if (n == name) return p;
  const auto path = std::filesystem::path(SB_SOURCE_DIR) / "experiments/scenes" / (name + ".toml");
  cache.emplace_back(name, sb::prepare_scene(sb::load_scene(path)));
  return cache.back().second;
}

// One run of the scene per iteration (terrain construction untimed).
void BM_Scene(benchmark::State& state, const std::string& backend, const std::string& name) {
  const sb::PreparedScene& prepared = scene(name);
  double step_p50_ms = 0.0, relax_s = 0.0, bytes = 0.0;
  for (auto _ : state) {
    state.PauseTiming();
    auto terrain = sb::make_terrain(backend, prepared.scene, prepared.initial);
    state.ResumeTiming();
    const sb::RunResult r = sb::run_schedule(*terrain, prepared);
    std::vector<double> step_ms;
    for (const sb::StepRecord& s : r.steps) {
      if (s.stamp < 0)
        relax_s += s.total_s();
      else
        step_ms.push_back(1e3 * s.total_s());
    }
    std::nth_element(step_ms.begin(), step_ms.begin() + static_cast<std::ptrdiff_t>(step_ms.size() / 2), step_ms.end());
    step_p50_ms += step_ms[step_ms.size() / 2];
    bytes = static_cast<double>(r.final_stats.bytes);
  }
  state.counters["step_p50_ms"] = benchmark::Counter(step_p50_ms, benchmark::Counter::kAvgIterations);
  state.counters["relax_ms"] = benchmark::Counter(1e3 * relax_s, benchmark::Counter::kAvgIterations);
  state.counters["bytes"] = bytes;
}

const int kRegistered = [] {
  for (const char* name : {"flat_stroke", "pile", "trench", "dunes", "heightmap"})
    for (const char* backend : {"grid", "sparse"})
      benchmark::RegisterBenchmark((std::string("BM_Scene/") + name + "/" + backend).c_str(), BM_Scene, backend, name)
          ->Unit(benchmark::kMillisecond);
  return 0;
}();

}  // namespace
