// Haptics benchmarks on both back-ends at about 10^5 elements (a 317 x 317 grid; a TIN of
// 10^5 vertices): the force computation of one servo tick (device read, patch take-over,
// force model, limit, command) and the simulation's patch publication (one sample() of the
// 49 x 49 patch around the tool, plus the hand-over). The patch is what the servo reads,
// so the force cost does not depend on the model's size; publication does, via sample().
//
//   build/<dir>/tests/haptics_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <memory>
#include <random>

#include "bench_scenes.hpp"
#include "common/haptics/force_model.hpp"
#include "common/haptics/servo_core.hpp"
#include "common/haptics/shared_pose_device.hpp"
#include "common/height_field.hpp"
#include "common/scene.hpp"
#include "harness/run/backends.hpp"
#include "tin/tin_terrain.hpp"

namespace {

using namespace sb;
using namespace sb::haptics;

// Dunes over the paper's domain (diagonal 1 m); grid cell for 317 x 317 = 100489 nodes.
const Scene& scene() {
  static const Scene s = parse_scene(bench::kPaperDunesScene, "haptics_bench.toml", {"grid.cell_m=0.0022360679"});
  return s;
}

// One terrain per back-end, built once: ~10^5 cells, or 10^5 TIN vertices on the dunes.
Terrain& terrain(int backend) {
  static std::unique_ptr<Terrain> grid, tin;
  const HeightField initial = HeightField::from_scene(scene());
  if (backend == 0) {
    if (!grid) grid = make_terrain("grid", scene(), initial);
    return *grid;
  }
  if (!tin) {
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(0.001, 0.7061);
    std::vector<Vec3> points;
    for (int i = 0; i < 100000; ++i) {
      const Vec2 p(u(rng), u(rng));
      points.emplace_back(p.x(), p.y(), initial(p));
    }
    tin = tin::make_tin_terrain_from_points(scene(), points);
  }
  return *tin;
}

const char* name(int backend) { return backend == 0 ? "grid" : "tin"; }

void counters(benchmark::State& state, int backend) {
  const ModelStats st = terrain(backend).stats();
  state.counters["elements"] = static_cast<double>(backend == 0 ? st.cells : st.vertices);
  state.SetLabel(name(backend));
}

// Servo ticks with the tool 5 mm into the sand, moving, on a patch published from the model;
// with new_patch_every_tick, a new patch arrives before every tick (the rendering's worst
// tick: the model runs on the old and on the new patch for the blend).
void force_ticks(benchmark::State& state, const RenderingOptions& rendering, bool new_patch_every_tick) {
  const int backend = static_cast<int>(state.range(0));
  Terrain& t = terrain(backend);
  const ForceParams params = ForceParams::from(scene().material, scene().tool);
  const PatchLayout layout = PatchLayout::for_tool(params.reach_m, 0.015);
  const Vec2 centre(0.35, 0.35);
  HeightPatch filled;
  fill_patch(t, centre, layout, params, 1, filled);
  PatchBuffer patches;
  patches.for_each_slot([&](HeightPatch& p) { p = filled; });  // every slot holds a valid patch
  patches.publish();
  DeviceLimits limits;
  limits.workspace.lo = Vec3(-1, -1, -1);
  limits.workspace.hi = Vec3(2, 2, 2);
  SharedPoseDevice device("bench", limits);
  ServoCore core(device, patches, 40.0, rendering);
  core.start();
  const double z = t.height(centre) - 0.005;
  double now = 0.0;
  for (auto _ : state) {
    now += 0.001;
    device.set_pose(Vec3(centre.x() + 0.005 * std::sin(now), centre.y(), z), 0);
    if (new_patch_every_tick) patches.publish();
    const ServoState s = core.step(now);
    benchmark::DoNotOptimize(s.force_n);
  }
  counters(state, backend);
}

void BM_ForceTick(benchmark::State& state) { force_ticks(state, scene().haptics, false); }
BENCHMARK(BM_ForceTick)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

void BM_ForceTickNewPatchEveryTick(benchmark::State& state) { force_ticks(state, scene().haptics, true); }
BENCHMARK(BM_ForceTickNewPatchEveryTick)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

// The force model alone (no device, no hand-over).
void BM_ForceModel(benchmark::State& state) {
  const int backend = static_cast<int>(state.range(0));
  Terrain& t = terrain(backend);
  const ForceParams params = ForceParams::from(scene().material, scene().tool);
  HeightPatch patch;
  const Vec2 centre(0.35, 0.35);
  fill_patch(t, centre, PatchLayout::for_tool(params.reach_m, 0.015), params, 1, patch);
  const double z = t.height(centre) - 0.005;
  double x = 0.0;
  for (auto _ : state) {
    x += 1e-4;
    const ForceOutput f =
        compute_force(patch, Vec3(centre.x() + 0.005 * std::sin(x), centre.y(), z), Vec3(0.05, 0.0, 0.0), 2000.0);
    benchmark::DoNotOptimize(limit_force(f.force_n, 8.0));
  }
  counters(state, backend);
}
BENCHMARK(BM_ForceModel)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

// Publishing the patch after a simulation step, the tool moving 1 mm per step along a line.
void BM_PatchPublish(benchmark::State& state) {
  const int backend = static_cast<int>(state.range(0));
  Terrain& t = terrain(backend);
  const ForceParams params = ForceParams::from(scene().material, scene().tool);
  const PatchLayout layout = PatchLayout::for_tool(params.reach_m, 0.015);
  PatchBuffer patches;
  reserve_patches(patches, layout.cells);
  std::uint64_t version = 0;
  for (auto _ : state) {
    const double s = static_cast<double>(version % 200) * 0.001;
    fill_patch(t, Vec2(0.25 + s, 0.3 + 0.5 * s), layout, params, ++version, patches.back());
    patches.publish();
    benchmark::ClobberMemory();
  }
  counters(state, backend);
  state.counters["patch_points"] = static_cast<double>(layout.cells * layout.cells);
}
BENCHMARK(BM_PatchPublish)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

}  // namespace
