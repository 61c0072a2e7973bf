// Queries on the TINs the tool really builds (`tin.initial_points`: a jittered lattice whose
// outermost rows lie on the domain's border, about 4 sqrt(N) hull vertices) at N = 10^4, 10^5
// and 10^6 vertices:
//  - BM_TinSample: one raster sampling of the whole domain at the scene's default raster
//    (2.5 mm on the paper's 0.707 m square: 283 x 283 points), as every run does for its
//    reference metrics and energy;
//  - BM_TinPatchPublish: the interactive mode's haptic patch publication (one sample() of the
//    49 x 49 patch around the tool, plus the hand-over), the tool moving 1 mm per step.
// Both report the median and the 95th percentile of single calls as counters, because the
// servo feels the slow publications, not the mean one: in wall time (p50_ms, p95_ms, which on
// a loaded machine include preemption) and in the thread's CPU time (cpu_p50_ms, cpu_p95_ms,
// which do not). A walk or a count over the hull shows up here as a time growing with N.
//
//   build/<dir>/tests/tin_query_bench --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bench_scenes.hpp"
#include "common/haptics/force_model.hpp"
#include "common/haptics/height_patch.hpp"
#include "common/height_field.hpp"
#include "common/raster.hpp"
#include "common/scene.hpp"
#include "tin/tin_terrain.hpp"

namespace {

using namespace sb;

// Dunes over the paper's domain (diagonal 1 m), N initial points.
Scene scene_with(std::int64_t n) {
  return parse_scene(bench::kPaperDunesScene, "tin_query_bench.toml", {"tin.initial_points=" + std::to_string(n)});
}

// Built once per size (a 10^6-vertex TIN takes seconds), outside the timed loops.
Terrain& terrain(std::int64_t n) {
  static std::map<std::int64_t, std::unique_ptr<Terrain>> built;
  auto& t = built[n];
  if (!t) {
    const Scene s = scene_with(n);
    t = tin::make_tin_terrain(s, HeightField::from_scene(s));
  }
  return *t;
}

double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

// Times each iteration by hand as well (wall and thread CPU time), for the percentiles.
class CallTimes {
 public:
  void start() {
    wall_start_ = std::chrono::steady_clock::now();
    cpu_start_ = thread_cpu_ms();
  }
  void stop() {
    cpu_ms_.push_back(thread_cpu_ms() - cpu_start_);
    wall_ms_.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - wall_start_).count());
  }
  void report(benchmark::State& state, Terrain& t) {
    state.counters["p50_ms"] = percentile(wall_ms_, 0.5);
    state.counters["p95_ms"] = percentile(wall_ms_, 0.95);
    state.counters["cpu_p50_ms"] = percentile(cpu_ms_, 0.5);
    state.counters["cpu_p95_ms"] = percentile(cpu_ms_, 0.95);
    state.counters["vertices"] = static_cast<double>(t.stats().vertices);
  }

 private:
  static double percentile(std::vector<double> v, double q) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))];
  }
  std::chrono::steady_clock::time_point wall_start_;
  double cpu_start_ = 0.0;
  std::vector<double> wall_ms_, cpu_ms_;
};

void BM_TinSample(benchmark::State& state) {
  const Scene s = scene_with(state.range(0));
  Terrain& t = terrain(state.range(0));
  Raster raster = Raster::covering(s.domain.box(), s.output.raster_m);
  CallTimes times;
  for (auto _ : state) {
    times.start();
    t.sample(raster);
    times.stop();
    benchmark::DoNotOptimize(raster.values.data());
  }
  times.report(state, t);
  state.counters["samples"] = static_cast<double>(raster.values.size());
}
BENCHMARK(BM_TinSample)->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond);

void BM_TinPatchPublish(benchmark::State& state) {
  const Scene s = scene_with(state.range(0));
  Terrain& t = terrain(state.range(0));
  using namespace sb::haptics;
  const ForceParams params = ForceParams::from(s.material, s.tool);
  const PatchLayout layout = PatchLayout::for_tool(params.reach_m, 0.015);
  PatchBuffer patches;
  reserve_patches(patches, layout.cells);
  std::uint64_t version = 0;
  CallTimes times;
  for (auto _ : state) {
    const double step = static_cast<double>(version % 200) * 0.001;
    times.start();
    fill_patch(t, Vec2(0.25 + step, 0.3 + 0.5 * step), layout, params, ++version, patches.back());
    patches.publish();
    times.stop();
    benchmark::ClobberMemory();
  }
  times.report(state, t);
  state.counters["patch_points"] = static_cast<double>(layout.cells * layout.cells);
}
BENCHMARK(BM_TinPatchPublish)->Arg(10000)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMicrosecond);

}  // namespace
