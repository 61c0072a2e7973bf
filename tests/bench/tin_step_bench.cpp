// One simulation step of the TIN (stamp + erosion + simplification) against the model size
// N = 10^3 ... 10^6 vertices, where the paper measured O(N^1.5).
//
// Two kinds of TIN: `border = 0`, jittered points strictly inside the domain (a 4-corner
// hull), and `border = 1`, the lattice tin.initial_points builds, whose outermost rows and
// columns lie on the domain's border (about 4 sqrt(N) hull vertices: a cost that walks or
// counts the hull shows up here). After the runs the bench prints the log-log slope of the
// step time against N over 10^3..10^6 for each kind and conserve setting.
//
// The TIN is built (outside the timed loop) from N jittered points at a fixed 6 mm spacing
// over a domain that grows with N, on a plane tilted by 3.4 degrees (so no vertex is "flat")
// with small bumps. The jitter and heights are functions of the point's offset from the
// domain's centre, so every N has the very same terrain around the centre, where a 1.5 cm
// disk stamps 12 poses on a 3 cm circle, round and round: each iteration does the same work
// at every N, and any growth with N comes from global costs (walks, lists, containers).
//
//   build/<dir>/tests/tin_step_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//
// Two more series build their TIN the way a scene does (tin::make_tin_terrain):
//  - BM_TinStepInitialPoints: `tin.initial_points` = N on a plane tilted by 3.4 degrees
//    (terrain.kind = "plane"), the domain growing with N at the same 6 mm spacing, so the
//    stamps meet the same lattice at every N, border points and all;
//  - BM_TinStepHeightmap: the 16-bit heightmap of experiments/scenes/heightmap.toml (greedy
//    insertion to tin.tolerance_m), stamped on a circle around the domain's centre.
//
// The cost per step should not grow with N: the printed slopes should be below 0.1.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <memory>
#include <numbers>
#include <string>
#include <tuple>
#include <vector>

#include "common/erosion.hpp"
#include "common/height_field.hpp"
#include "common/metrics.hpp"
#include "common/scene.hpp"
#include "tin/tin_terrain.hpp"

namespace {

constexpr double kSpacing = 0.006;
constexpr double kToolRadius = 0.015;
constexpr double kDepth = 0.005;
constexpr double kLoopRadius = 0.03;
constexpr int kPoses = 12;

// A reproducible value in [0, 1) from two integers (splitmix64).
double hash01(std::int64_t i, std::int64_t j, std::uint64_t salt) {
  std::uint64_t x = static_cast<std::uint64_t>(i) * 0x9E3779B97F4A7C15ull ^
                    static_cast<std::uint64_t>(j) * 0xC2B2AE3D27D4EB4Full ^ salt;
  x ^= x >> 30;
  x *= 0xBF58476D1CE4E5B9ull;
  x ^= x >> 27;
  x *= 0x94D049BB133111EBull;
  x ^= x >> 31;
  return static_cast<double>(x >> 11) * 0x1.0p-53;
}

// Heights relative to the centre: a 3.4-degree plane plus 1 mm bumps.
double surface(const sb::Vec2& d) {
  return 1.0 + 0.05 * d.x() + 0.03 * d.y() + 0.001 * std::sin(60.0 * d.x()) * std::cos(50.0 * d.y());
}

struct Setup {
  sb::Scene scene;
  std::unique_ptr<sb::Terrain> terrain;
  sb::Vec2 centre;
  sb::ErosionRule rule;
  bool from_scene = false;  // built by make_tin_terrain: stamp depths from the TIN itself
  bool displayed = false;   // a display tracks the changes: changes_since after every step
  std::uint64_t version = 0;
};

std::unique_ptr<Setup> build(std::int64_t n, bool conserve, bool border) {
  auto s = std::make_unique<Setup>();
  const auto side = static_cast<std::int64_t>(std::llround(std::sqrt(static_cast<double>(n))));
  const double size = kSpacing * static_cast<double>(side);
  const std::string text = "[domain]\nsize_m = [" + std::to_string(size) + ", " + std::to_string(size) +
                           "]\n[tool]\nshape = \"disk\"\nradius_m = " + std::to_string(kToolRadius) +
                           "\ndepth_m = " + std::to_string(kDepth) + "\n[stroke]\npath_m = [[0.0, 0.0]]\n[tin]\n" +
                           "conserve_volume = " + (conserve ? "true" : "false") + "\n";
  s->scene = sb::parse_scene(text, "tin_step_bench");
  s->centre = sb::Vec2(size / 2, size / 2);
  s->rule = sb::ErosionRule::from(s->scene.material, s->scene.erosion.settle_tolerance_deg, s->scene.erosion.rule);
  std::vector<sb::Vec3> points;
  points.reserve(static_cast<std::size_t>(side * side));
  const std::int64_t mid = side / 2;
  for (std::int64_t j = 0; j < side; ++j)
    for (std::int64_t i = 0; i < side; ++i) {
      sb::Vec2 p((static_cast<double>(i) + 0.1 + 0.8 * hash01(i - mid, j - mid, 1)) * kSpacing,
                 (static_cast<double>(j) + 0.1 + 0.8 * hash01(i - mid, j - mid, 2)) * kSpacing);
      // The domain as parsed (its size went through text): the border exactly, nothing beyond.
      const sb::Vec2 hi = s->scene.domain.size_m;
      if (border && (i == 0 || i == side - 1)) p.x() = i == 0 ? 0.0 : hi.x();
      if (border && (j == 0 || j == side - 1)) p.y() = j == 0 ? 0.0 : hi.y();
      p = p.cwiseMin(hi);
      points.emplace_back(p.x(), p.y(), surface(p - s->centre));
    }
  s->terrain = sb::tin::make_tin_terrain_from_points(s->scene, points);
  return s;
}

sb::ToolStamp pose(const Setup& s, int k) {
  const double a = 2.0 * std::numbers::pi * (k % kPoses) / kPoses;
  const sb::Vec2 offset = kLoopRadius * sb::Vec2(std::cos(a), std::sin(a));
  const sb::Vec2 motion(-std::sin(a), std::cos(a));
  sb::ToolPose p;
  p.xy = s.centre + offset;
  p.bottom_z = (s.from_scene ? s.terrain->height(p.xy) : surface(offset)) - kDepth;
  p.heading_rad = std::atan2(motion.y(), motion.x());
  return sb::make_stamp(s.scene.tool, p, motion, static_cast<std::uint32_t>(k));
}

struct PhaseTimes {
  double stamp_s = 0.0, erode_s = 0.0, simplify_s = 0.0, changes_s = 0.0;
  std::size_t updates = 0;
};

void step(Setup& s, int k, PhaseTimes* times = nullptr) {
  sb::Stopwatch watch;
  s.terrain->stamp(pose(s, k));
  const double t1 = watch.seconds();
  const sb::ErosionReport r = s.terrain->erode(s.rule, sb::ErosionBudget{s.scene.erosion.max_passes_per_step});
  const double t2 = watch.seconds();
  s.terrain->simplify(sb::SimplifyParams{s.scene.tin.alpha_flat_deg});
  const double t3 = watch.seconds();
  if (s.displayed) s.version = s.terrain->changes_since(s.version).version;
  if (times) {
    times->stamp_s += t1;
    times->erode_s += t2 - t1;
    times->simplify_s += t3 - t2;
    times->changes_s += watch.seconds() - t3;
    times->updates += r.updates;
  }
}

// A TIN built as a scene builds it: tin.initial_points = N on a tilted plane (6 mm spacing),
// or the heightmap scene (n = 0).
std::unique_ptr<Setup> build_from_scene(std::int64_t n) {
  auto s = std::make_unique<Setup>();
  if (n > 0) {
    const double size = kSpacing * std::sqrt(static_cast<double>(n));
    const std::string text = "[domain]\nsize_m = [" + std::to_string(size) + ", " + std::to_string(size) +
                             "]\n[terrain]\nkind = \"plane\"\nheight_m = 1.0\nslope_deg = 3.4\nazimuth_deg = 30.0\n" +
                             "[tool]\nshape = \"disk\"\nradius_m = " + std::to_string(kToolRadius) +
                             "\ndepth_m = " + std::to_string(kDepth) + "\n[stroke]\npath_m = [[0.0, 0.0]]\n";
    s->scene = sb::parse_scene(text, "tin_step_bench", {"tin.initial_points=" + std::to_string(n)});
  } else {
    s->scene = sb::load_scene(std::string(SB_SOURCE_DIR) + "/experiments/scenes/heightmap.toml");
  }
  s->centre = s->scene.domain.centre();
  s->rule = sb::ErosionRule::from(s->scene.material, s->scene.erosion.settle_tolerance_deg, s->scene.erosion.rule);
  s->terrain = sb::tin::make_tin_terrain(s->scene, sb::HeightField::from_scene(s->scene));
  s->from_scene = true;
  return s;
}

// Built once per (N, conserve) and kept: construction is not what is measured.
Setup& setup(std::int64_t n, bool conserve, bool border) {
  static std::map<std::tuple<std::int64_t, bool, bool>, std::unique_ptr<Setup>> cache;
  auto& slot = cache[{n, conserve, border}];
  if (!slot) {
    slot = build(n, conserve, border);
    for (int k = 0; k < 2 * kPoses; ++k) step(*slot, k);  // warm up: the loop's steady state
  }
  return *slot;
}

void run_steps(benchmark::State& state, Setup& s) {
  const sb::ModelStats before = s.terrain->stats();
  int k = 0;
  PhaseTimes times;
  for (auto _ : state) step(s, k++, &times);
  const sb::ModelStats after = s.terrain->stats();
  state.counters["stamp_us"] = 1e6 * times.stamp_s / k;
  state.counters["erode_us"] = 1e6 * times.erode_s / k;
  state.counters["simplify_us"] = 1e6 * times.simplify_s / k;
  state.counters["changes_us"] = 1e6 * times.changes_s / k;
  state.counters["erosion_updates"] = static_cast<double>(times.updates) / k;
  state.counters["vertices"] = static_cast<double>(after.vertices);
  state.counters["walk_steps_per_step"] =
      static_cast<double>(after.walk_steps - before.walk_steps) / static_cast<double>(k);
  state.counters["active"] = static_cast<double>(after.active);
  state.counters["MB"] = static_cast<double>(after.bytes) / 1e6;
}

void BM_TinStep(benchmark::State& state) {
  run_steps(state, setup(state.range(0), state.range(1) != 0, state.range(2) != 0));
}

// Per N (0: the heightmap), built once and warmed up like setup().
Setup& scene_setup(std::int64_t n) {
  static std::map<std::int64_t, std::unique_ptr<Setup>> cache;
  auto& slot = cache[n];
  if (!slot) {
    slot = build_from_scene(n);
    for (int k = 0; k < 2 * kPoses; ++k) step(*slot, k);
  }
  return *slot;
}

void BM_TinStepInitialPoints(benchmark::State& state) { run_steps(state, scene_setup(state.range(0))); }

// The heightmap's steps without and with a display tracking what changed (TinTerrain::changes_since after every
// step, more often than a window asks): what the tracking's marks and its answers cost. Separate TINs, built and
// warmed up alike.
void BM_TinStepDisplayed(benchmark::State& state) {
  static std::map<bool, std::unique_ptr<Setup>> cache;
  const bool displayed = state.range(0) != 0;
  auto& slot = cache[displayed];
  if (!slot) {
    slot = build_from_scene(0);
    slot->displayed = displayed;
    if (displayed) slot->version = slot->terrain->changes_since(0).version;
    for (int k = 0; k < 2 * kPoses; ++k) step(*slot, k);
  }
  run_steps(state, *slot);
}
void BM_TinStepHeightmap(benchmark::State& state) { run_steps(state, scene_setup(0)); }

BENCHMARK(BM_TinStep)
    ->ArgNames({"N", "conserve", "border"})
    ->Args({1000, 0, 0})
    ->Args({10000, 0, 0})
    ->Args({100000, 0, 0})
    ->Args({1000000, 0, 0})
    ->Args({1000, 0, 1})
    ->Args({10000, 0, 1})
    ->Args({100000, 0, 1})
    ->Args({1000000, 0, 1})
    ->Args({1000, 1, 1})
    ->Args({1000000, 1, 1})
    ->Iterations(240)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_TinStepInitialPoints)
    ->ArgName("N")
    ->Arg(1000)
    ->Arg(10000)
    ->Arg(100000)
    ->Arg(1000000)
    ->Iterations(240)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_TinStepHeightmap)->Iterations(240)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_TinStepDisplayed)
    ->ArgName("display")
    ->Arg(0)
    ->Arg(1)
    ->Iterations(480)
    ->Repetitions(5)
    ->Unit(benchmark::kMicrosecond);

// Collects the median (or the only) CPU time (the machine may be shared) per (conserve, border) series and N, and
// prints the least-squares slope of log(time) against log(N).
class SlopeReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& r : runs) {
      if (r.error_occurred || (r.run_type == Run::RT_Aggregate && r.aggregate_name != "median")) continue;
      if (r.run_type == Run::RT_Iteration && r.repetitions > 1) continue;
      const std::string name = r.run_name.str();  // BM_TinStep/N:1000/conserve:0/border:1
      const auto at = name.find("/N:");
      if (at == std::string::npos) continue;
      const auto end = name.find('/', at + 1);
      // The series: the name without its N (BM_TinStep/conserve:0/border:1).
      const std::string series = name.substr(0, at) + (end == std::string::npos ? "" : name.substr(end));
      series_[series].emplace_back(std::stod(name.substr(at + 3)), r.GetAdjustedCPUTime());
    }
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    for (const auto& [key, pts] : series_) {
      if (pts.size() < 2) continue;
      double mx = 0, my = 0;
      for (const auto& [n, t] : pts) mx += std::log(n), my += std::log(t);
      mx /= pts.size();
      my /= pts.size();
      double sxy = 0, sxx = 0;
      for (const auto& [n, t] : pts) {
        sxy += (std::log(n) - mx) * (std::log(t) - my);
        sxx += (std::log(n) - mx) * (std::log(n) - mx);
      }
      std::printf("log-log slope of the step time against N, %s: %.3f (%zu sizes)\n", key.c_str(), sxy / sxx,
                  pts.size());
    }
  }

 private:
  std::map<std::string, std::vector<std::pair<double, double>>> series_;
};

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  SlopeReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
