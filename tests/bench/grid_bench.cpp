// Grid back-end benchmarks: erosion throughput (node updates per second: one update is one
// evaluation of the rule at one node) on realistic active sets of a 512 x 512 grid, on a
// 2048 x 2048 grid with every node active (on one thread and on two), against a plain scalar
// in-place sweep of the same rule in the same run (BM_ReferenceSweep), against a vectorised
// two-pass (Jacobi) sweep at its monotone fraction (BM_JacobiSweep), time to rest of both
// orders (BM_Settle*), stamp cost against tool area (BM_Stamp: the rim; BM_BulldozeStroke: a
// stroke pushing its front pile, bulldozing or carrying it); float and double; the pile and
// stroke also with the gradient rule.
//
//   build/<dir>/tests/grid_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//       --benchmark_enable_random_interleaving=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <span>
#include <vector>

#include "common/scene.hpp"
#include "grid/grid_terrain.hpp"

namespace {

using sb::grid::GridLayout;
using sb::grid::GridTerrain;

constexpr double kCell = 0.005;
constexpr std::size_t kNodes = 512;  // per axis
constexpr double kSize = kCell * (kNodes - 1);
constexpr double kSand = 0.1;

template <class Real>
GridTerrain<Real> flat_grid() {
  const GridLayout layout = GridLayout::covering({{0.0, 0.0}, {kSize, kSize}}, kCell);
  return GridTerrain<Real>(
      layout, [](const sb::Vec2&) { return kSand; }, 8, 2);
}

sb::ToolSpec disk(double radius_m, double depth_m) {
  sb::ToolSpec spec;
  spec.shape = sb::ToolShape::Disk;
  spec.radius_m = radius_m;
  spec.depth_m = depth_m;
  spec.rim.width_m = 0.5 * radius_m;
  return spec;
}

sb::ToolStamp stamp_at(const sb::ToolSpec& spec, sb::Vec2 xy, sb::Vec2 motion) {
  sb::ToolPose pose;
  pose.xy = xy;
  pose.bottom_z = kSand - spec.depth_m;
  pose.heading_rad = std::atan2(motion.y(), motion.x());
  return sb::make_stamp(spec, pose, motion, 0);
}

sb::ErosionRule rule(sb::ErosionRuleKind kind = sb::ErosionRuleKind::Edge) {
  sb::Material m;  // 30 degrees, fraction 0.5
  return sb::ErosionRule::from(m, 0.1, kind);
}

// Two starting states for erosion.
enum class Start { Pile, Stroke };

// Pile: a column of 2 litres 10 cm wide in the middle (every node within 5 cm of the centre
// raised by the same height, its 3 x 3 block active, as the pour tool left it until it became a
// cone handed to the nodes bilinearly), relaxing into a cone. Built here rather than poured, so
// that the kernel's state does not follow the pour tool (a cone runs ~5 % fewer updates/s).
// Stroke: a 5 cm disk dragged 3 cm deep over 40 cm (41 stamps), its trench and rims eroding.
template <class Real>
GridTerrain<Real> prepared(Start start) {
  const sb::Vec2 centre{kSize / 2, kSize / 2};
  if (start == Start::Pile) {
    constexpr double radius = 0.05, volume = 2e-3;
    const GridLayout layout = flat_grid<Real>().layout();
    const auto inside = [&](const sb::Vec2& p) { return (p - centre).squaredNorm() <= radius * radius; };
    double area = 0.0;
    for (std::size_t iy = 0; iy < layout.ny; ++iy)
      for (std::size_t ix = 0; ix < layout.nx; ++ix)
        if (inside(layout.position(ix, iy))) area += layout.area(ix, iy);
    GridTerrain<Real> t(
        layout, [&](const sb::Vec2& p) { return kSand + (inside(p) ? volume / area : 0.0); }, 8, 2);
    for (std::size_t iy = 0; iy < layout.ny; ++iy)
      for (std::size_t ix = 0; ix < layout.nx; ++ix)
        if (inside(layout.position(ix, iy))) t.activate_block(ix, iy);
    return t;
  }
  GridTerrain<Real> t = flat_grid<Real>();
  const sb::ToolSpec spec = disk(0.05, 0.03);
  for (int i = 0; i <= 40; ++i) t.stamp(stamp_at(spec, centre + sb::Vec2(-0.2 + 0.01 * i, 0.0), {1.0, 0.0}));
  return t;
}

// state.range(0) erosion passes of the kernel (erosion_kernel.hpp; no multi-resolution
// cascade) on a fresh copy of the prepared state each iteration (the copy is not timed).
// Rates are per CPU second. Edge rule; the Gradient variants: the gradient rule (the scenes' default).
template <class Real, Start kStart, sb::ErosionRuleKind kKind = sb::ErosionRuleKind::Edge>
void BM_Erosion(benchmark::State& state) {
  const int passes = static_cast<int>(state.range(0));
  const GridTerrain<Real> start = prepared<Real>(kStart);
  const sb::ErosionRule r = rule(kKind);
  double updates = 0, transfers = 0;
  for (auto _ : state) {
    state.PauseTiming();
    GridTerrain<Real> t = start;
    t.set_multires(false);  // the kernel's passes only (the settling cascade is measured by exp_settling)
    state.ResumeTiming();
    const sb::ErosionReport report = t.erode(r, {.max_passes = passes});
    benchmark::DoNotOptimize(report);
    updates += static_cast<double>(report.updates);
    transfers += static_cast<double>(report.transfers);
  }
  state.counters["updates_per_s"] = benchmark::Counter(updates, benchmark::Counter::kIsRate);
  state.counters["transfers_per_s"] = benchmark::Counter(transfers, benchmark::Counter::kIsRate);
  state.counters["updates_per_call"] = benchmark::Counter(updates, benchmark::Counter::kAvgIterations);
  state.counters["active_at_start"] = static_cast<double>(start.stats().active);
}
BENCHMARK(BM_Erosion<float, Start::Pile>)
    ->Name("BM_ErosionPile<float>")
    ->ArgName("passes")
    ->Arg(64)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Erosion<double, Start::Pile>)
    ->Name("BM_ErosionPile<double>")
    ->ArgName("passes")
    ->Arg(64)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Erosion<float, Start::Stroke>)
    ->Name("BM_ErosionStroke<float>")
    ->ArgName("passes")
    ->Arg(64)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Erosion<double, Start::Stroke>)
    ->Name("BM_ErosionStroke<double>")
    ->ArgName("passes")
    ->Arg(64)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Erosion<double, Start::Pile, sb::ErosionRuleKind::Gradient>)
    ->Name("BM_ErosionPileGradient<double>")
    ->ArgName("passes")
    ->Arg(64)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Erosion<double, Start::Stroke, sb::ErosionRuleKind::Gradient>)
    ->Name("BM_ErosionStrokeGradient<double>")
    ->ArgName("passes")
    ->Arg(64)
    ->Unit(benchmark::kMillisecond);

// Every node of a 2048 x 2048 grid (5 mm cells, 10.2 m square) active on a field of dunes
// whose flanks stand up to 44 degrees (46 % of the nodes steeper than the critical 30):
// the state a dense pass is for. state.range(0) passes on a fresh copy each iteration.
constexpr std::size_t kBigNodes = 2048;
constexpr double kBigSize = kCell * (kBigNodes - 1);
double dunes(const sb::Vec2& p) {
  const double k = 2.0 * std::numbers::pi / 0.4;  // 40 cm wavelength
  return kSand + 0.0625 * std::sin(k * p.x()) * std::cos(0.7 * k * p.y());
}

GridLayout big_layout() { return GridLayout::covering({{0.0, 0.0}, {kBigSize, kBigSize}}, kCell); }

template <class Real>
GridTerrain<Real> all_active() {
  GridTerrain<Real> t(big_layout(), dunes, 8, 2);
  t.activate_all();
  return t;
}

// state.range(0) passes over a fresh (untimed) copy of the all-active state per iteration:
// copy(start) makes the copy, run(copy, passes, rule) erodes it and returns the updates.
template <class Real, class Copy, class Run>
void time_all_active(benchmark::State& state, Copy&& copy, Run&& run) {
  const int passes = static_cast<int>(state.range(0));
  const GridTerrain<Real> start = all_active<Real>();
  const sb::ErosionRule r = rule();
  double updates = 0;
  for (auto _ : state) {
    state.PauseTiming();
    auto fresh = copy(start);
    state.ResumeTiming();
    updates += static_cast<double>(run(fresh, passes, r));
  }
  state.counters["updates_per_s"] = benchmark::Counter(updates, benchmark::Counter::kIsRate);
  state.counters["updates_per_call"] = benchmark::Counter(updates, benchmark::Counter::kAvgIterations);
}

// Threads: GridTerrain::set_threads (two: each large dense pass runs its two bands at once,
// erosion_kernel.hpp's dense_pass; the same heights bit for bit).
template <class Real, unsigned Threads = 1>
void BM_AllActive(benchmark::State& state) {
  time_all_active<Real>(
      state, [](const GridTerrain<Real>& start) { return start; },
      [](GridTerrain<Real>& t, int passes, const sb::ErosionRule& r) {
        t.set_threads(Threads);
        const sb::ErosionReport report = t.erode(r, {.max_passes = passes});
        benchmark::DoNotOptimize(report);
        return report.updates;
      });
}
BENCHMARK(BM_AllActive<float>)->Name("BM_AllActive<float>")->ArgName("passes")->Arg(4)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_AllActive<double>)->Name("BM_AllActive<double>")->ArgName("passes")->Arg(4)->Unit(benchmark::kMillisecond);
// On two threads: rates per second of wall time; the CPU time shown is both threads'.
BENCHMARK(BM_AllActive<float, 2>)
    ->Name("BM_AllActiveTwoThreads<float>")
    ->ArgName("passes")
    ->Arg(4)
    ->UseRealTime()
    ->MeasureProcessCPUTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_AllActive<double, 2>)
    ->Name("BM_AllActiveTwoThreads<double>")
    ->ArgName("passes")
    ->Arg(4)
    ->UseRealTime()
    ->MeasureProcessCPUTime()
    ->Unit(benchmark::kMillisecond);

// The reference: a plain scalar in-place sweep of the same rule (sb::erosion_transfers of
// common/erosion.hpp, edge rule) over every node of the same 2048^2 state, in storage order,
// each transfer written at once (dz_i = -V / A_i, dz_j = +V / A_j). No tables, no active set,
// no shortcut: what the kernel is measured against.
template <class Real>
void reference_pass(std::vector<Real>& z, const GridLayout& g, const sb::ErosionRule& r) {
  const int ox[8] = {1, -1, 0, 0, 1, -1, 1, -1}, oy[8] = {0, 0, 1, -1, 1, 1, -1, -1};
  sb::ErosionNeighbour nb[8];
  std::size_t at[8];
  double out[8];
  for (std::size_t iy = 0; iy < g.ny; ++iy)
    for (std::size_t ix = 0; ix < g.nx; ++ix) {
      const std::size_t k = iy * g.nx + ix;
      int n = 0;
      for (int s = 0; s < 8; ++s) {
        const std::size_t jx = ix + static_cast<std::size_t>(ox[s]), jy = iy + static_cast<std::size_t>(oy[s]);
        if (jx >= g.nx || jy >= g.ny) continue;
        at[n] = jy * g.nx + jx;
        nb[n] = {static_cast<double>(z[at[n]]), std::hypot(ox[s] * g.dx, oy[s] * g.dy), g.area(jx, jy)};
        ++n;
      }
      const double area_i = g.area(ix, iy);
      const double given = sb::erosion_transfers(static_cast<double>(z[k]), area_i, {},
                                                 std::span<const sb::ErosionNeighbour>(nb, n), r, std::span(out, n));
      if (given <= 0.0) continue;
      for (int m = 0; m < n; ++m) z[at[m]] = static_cast<Real>(z[at[m]] + out[m] / nb[m].area);
      z[k] = static_cast<Real>(z[k] - given / area_i);
    }
}

template <class Real>
void BM_ReferenceSweep(benchmark::State& state) {
  const GridLayout layout = big_layout();
  time_all_active<Real>(
      state, [](const GridTerrain<Real>& start) { return start.heights().heights(); },
      [&layout](std::vector<Real>& z, int passes, const sb::ErosionRule& r) {
        for (int p = 0; p < passes; ++p) reference_pass(z, layout, r);
        benchmark::DoNotOptimize(z.data());
        return static_cast<std::size_t>(passes) * layout.nodes();
      });
}
BENCHMARK(BM_ReferenceSweep<float>)
    ->Name("BM_ReferenceSweep<float>")
    ->ArgName("passes")
    ->Arg(4)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_ReferenceSweep<double>)
    ->Name("BM_ReferenceSweep<double>")
    ->ArgName("passes")
    ->Arg(4)
    ->Unit(benchmark::kMillisecond);

// The two-pass (Jacobi) sweep that erosion_kernel.hpp argues against ("Why not a Jacobi
// sweep"), vectorised, as a measured alternative: every node's transfers computed from the same
// old heights (edge rule, 8 neighbours, every node a full cell; a halo of high nodes that never
// give or receive), applied together. Monotone in energy only for f <= 2 / (N + 1) = 2 / 9, so it
// runs at that fraction: the comparison is of sweeps that both settle. Pass A: per node, the
// height it gives, out = f / 2 * its largest pair excess, and share = out / the sum of its pair
// excesses (0 where stable); pass B: z_i += -out_i + sum_j share_j e_ji, e_ji the excess of j over
// i from the old heights (the same value pass A summed at j, so volume is conserved exactly up
// to rounding). Both passes are plain stencil loops the compiler vectorises (target_clones).
class JacobiSweep {
 public:
  JacobiSweep(const std::vector<double>& heights, std::size_t nx, std::size_t ny, double cell, const sb::ErosionRule& r)
      : w_(nx + 2), h_(ny + 2), z_(w_ * h_, kHalo), out_(z_.size(), 0.0), share_(z_.size(), 0.0) {
    for (std::size_t iy = 0; iy < ny; ++iy)
      for (std::size_t ix = 0; ix < nx; ++ix) z_[(iy + 1) * w_ + ix + 1] = heights[iy * nx + ix];
    next_ = z_;  // (the halo stays in both)
    p_.allowed_axis = cell * r.tan_critical;
    p_.settle_axis = cell * r.tan_settle;
    p_.allowed_diagonal = std::numbers::sqrt2 * cell * r.tan_critical;
    p_.settle_diagonal = std::numbers::sqrt2 * cell * r.tan_settle;
    p_.half_fraction = 0.5 * (2.0 / 9.0);
  }
  // One pass; returns the number of nodes that gave.
  std::size_t pass() {
    std::size_t gave = 0;
    const auto w = static_cast<std::ptrdiff_t>(w_);
    for (std::size_t iy = 1; iy + 1 < h_; ++iy)
      gave += give_row(p_, z_.data() + iy * w_, out_.data() + iy * w_, share_.data() + iy * w_, w_ - 2, w);
    for (std::size_t iy = 1; iy + 1 < h_; ++iy)
      take_row(p_, z_.data() + iy * w_, share_.data() + iy * w_, out_.data() + iy * w_, next_.data() + iy * w_, w_ - 2,
               w);
    z_.swap(next_);
    return gave;
  }
  double volume() const {
    double v = 0.0;
    for (std::size_t iy = 1; iy + 1 < h_; ++iy)
      for (std::size_t ix = 1; ix + 1 < w_; ++ix) v += z_[iy * w_ + ix];
    return v;
  }

 private:
  static constexpr double kHalo = 1e30;  // never gives (no drop), never receives (share 0)
  struct Stencil8 {
    // d tan_critical and d tan_settle along the axes and the diagonals.
    double allowed_axis, settle_axis, allowed_diagonal, settle_diagonal;
    double half_fraction;
  };
  // The excess height of a drop over a run: drop - allowed where drop > settle, else 0.
  static double excess(double drop, double allowed, double settle) { return drop > settle ? drop - allowed : 0.0; }
  // Row of n real nodes at z[1..n] (z[0] and z[n + 1]: the halo); the rows above and below are
  // w apart. The eight neighbours written out, so the compiler vectorises along the row.
  __attribute__((target_clones("avx512f", "avx2", "default"))) static std::size_t give_row(
      const Stencil8& p, const double* __restrict z, double* __restrict out, double* __restrict share, std::size_t n,
      std::ptrdiff_t w) {
    const double* __restrict up = z + w;
    const double* __restrict down = z - w;
    const double a0 = p.allowed_axis, s0 = p.settle_axis, a1 = p.allowed_diagonal, s1 = p.settle_diagonal;
    std::size_t gave = 0;
    for (std::size_t x = 1; x <= n; ++x) {
      const double zi = z[x];
      const double e[8] = {excess(zi - z[x + 1], a0, s0),    excess(zi - z[x - 1], a0, s0),
                           excess(zi - up[x], a0, s0),       excess(zi - down[x], a0, s0),
                           excess(zi - up[x + 1], a1, s1),   excess(zi - up[x - 1], a1, s1),
                           excess(zi - down[x + 1], a1, s1), excess(zi - down[x - 1], a1, s1)};
      const double sum = ((e[0] + e[1]) + (e[2] + e[3])) + ((e[4] + e[5]) + (e[6] + e[7]));
      const double largest = std::max(std::max(std::max(e[0], e[1]), std::max(e[2], e[3])),
                                      std::max(std::max(e[4], e[5]), std::max(e[6], e[7])));
      const double o = p.half_fraction * largest;
      out[x] = o;
      share[x] = sum > 0.0 ? o / sum : 0.0;
      gave += sum > 0.0 ? 1 : 0;
    }
    return gave;
  }
  __attribute__((target_clones("avx512f", "avx2", "default"))) static void take_row(
      const Stencil8& p, const double* __restrict z, const double* __restrict share, const double* __restrict out,
      double* __restrict next, std::size_t n, std::ptrdiff_t w) {
    const double *up = z + w, *down = z - w, *sup = share + w, *sdown = share - w;
    const double a0 = p.allowed_axis, s0 = p.settle_axis, a1 = p.allowed_diagonal, s1 = p.settle_diagonal;
    for (std::size_t x = 1; x <= n; ++x) {
      const double zi = z[x];  // each neighbour's drop towards x, times its share
      const double in =
          (share[x + 1] * excess(z[x + 1] - zi, a0, s0) + share[x - 1] * excess(z[x - 1] - zi, a0, s0)) +
          (sup[x] * excess(up[x] - zi, a0, s0) + sdown[x] * excess(down[x] - zi, a0, s0)) +
          (sup[x + 1] * excess(up[x + 1] - zi, a1, s1) + sup[x - 1] * excess(up[x - 1] - zi, a1, s1)) +
          (sdown[x + 1] * excess(down[x + 1] - zi, a1, s1) + sdown[x - 1] * excess(down[x - 1] - zi, a1, s1));
      next[x] = zi + (in - out[x]);
    }
  }
  std::size_t w_, h_;
  std::vector<double> z_, next_, out_, share_;
  Stencil8 p_{};
};

// Jacobi passes over every node of the 2048^2 all-active state (updates: nodes x passes).
void BM_JacobiSweep(benchmark::State& state) {
  const GridLayout layout = big_layout();
  time_all_active<double>(
      state,
      [&layout](const GridTerrain<double>& start) {
        return JacobiSweep(start.heights().heights(), layout.nx, layout.ny, kCell, rule());
      },
      [&layout](JacobiSweep& j, int passes, const sb::ErosionRule&) {
        for (int p = 0; p < passes; ++p) benchmark::DoNotOptimize(j.pass());
        return static_cast<std::size_t>(passes) * layout.nodes();
      });
}
BENCHMARK(BM_JacobiSweep)->Name("BM_JacobiSweep<double>")->ArgName("passes")->Arg(4)->Unit(benchmark::kMillisecond);

// Time to rest from the dunes (512 x 512, every node active, fine passes only): the kernel's
// Gauss-Seidel passes at the scenes' fraction 0.5 against the Jacobi sweep at its monotone 2/9.
// One iteration each; counters: passes, node updates, and the volume's relative change.
GridTerrain<double> small_dunes() {
  GridTerrain<double> t(GridLayout::covering({{0.0, 0.0}, {kSize, kSize}}, kCell), dunes, 8, 2);
  t.activate_all();
  t.set_multires(false);
  return t;
}
void BM_SettleGaussSeidel(benchmark::State& state) {
  for (auto _ : state) {
    state.PauseTiming();
    GridTerrain<double> t = small_dunes();
    const double v0 = t.volume();
    state.ResumeTiming();
    const sb::ErosionReport r = t.erode(rule(), {.max_passes = 1000000});
    state.counters["passes"] = r.passes;
    state.counters["updates"] = static_cast<double>(r.updates);
    state.counters["settled"] = r.active == 0 ? 1 : 0;
    state.counters["volume_rel"] = t.volume() / v0 - 1.0;
  }
}
BENCHMARK(BM_SettleGaussSeidel)->Iterations(1)->Unit(benchmark::kMillisecond);
void BM_SettleJacobi(benchmark::State& state) {
  const GridTerrain<double> start = small_dunes();
  for (auto _ : state) {
    state.PauseTiming();
    JacobiSweep j(start.heights().heights(), start.layout().nx, start.layout().ny, kCell, rule());
    const double v0 = j.volume();
    state.ResumeTiming();
    int passes = 0;
    while (passes < 1000000 && j.pass() > 0) ++passes;
    state.counters["passes"] = passes;
    state.counters["updates"] = static_cast<double>(passes) * static_cast<double>(start.layout().nodes());
    state.counters["volume_rel"] = j.volume() / v0 - 1.0;
  }
}
BENCHMARK(BM_SettleJacobi)->Iterations(1)->Unit(benchmark::kMillisecond);

// One stamp of a disk of the given radius (in cells) on fresh sand: stamps walk a lattice
// of positions far enough apart that none overlaps the last; the grid is reset (untimed)
// when the lattice is used up.
template <class Real>
void BM_Stamp(benchmark::State& state) {
  const double radius = static_cast<double>(state.range(0)) * kCell;
  const sb::ToolSpec spec = disk(radius, 0.01);
  const double pitch = 2.0 * (radius + spec.rim.width_m) + 2 * kCell;
  std::vector<sb::ToolStamp> stamps;
  for (double y = pitch / 2; y + pitch / 2 < kSize; y += pitch)
    for (double x = pitch / 2; x + pitch / 2 < kSize; x += pitch) stamps.push_back(stamp_at(spec, {x, y}, {1.0, 0.0}));
  const GridTerrain<Real> fresh = flat_grid<Real>();
  GridTerrain<Real> t = fresh;
  std::size_t next = 0;
  double touched = 0, window = 0;
  const GridLayout& layout = fresh.layout();
  for (auto _ : state) {
    if (next == stamps.size()) {
      state.PauseTiming();
      t = fresh;
      next = 0;
      state.ResumeTiming();
    }
    const sb::ToolStamp& s = stamps[next++];
    const sb::StampReport report = t.stamp(s);
    benchmark::DoNotOptimize(report);
    touched += static_cast<double>(report.elements_touched);
    window += static_cast<double>(layout.nodes_in(s.influence_bounds()).count());
  }
  state.counters["radius_cells"] = static_cast<double>(state.range(0));
  state.counters["area_m2"] = std::numbers::pi * radius * radius;
  state.counters["nodes_touched"] = benchmark::Counter(touched, benchmark::Counter::kAvgIterations);
  state.counters["nodes_in_window"] = benchmark::Counter(window, benchmark::Counter::kAvgIterations);
  state.counters["window_nodes_per_s"] = benchmark::Counter(window, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_Stamp<float>)->ArgName("radius_cells")->RangeMultiplier(2)->Range(2, 64)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Stamp<double>)->ArgName("radius_cells")->RangeMultiplier(2)->Range(2, 64)->Unit(benchmark::kMicrosecond);

// A bulldozing stroke (common/front_pile.hpp): a disk of the given radius (in cells) pulled 12
// radii along x, a stamp every quarter radius as in the shipped scenes, so the front pile grows
// and is carried as in a real stroke; time per stamp. carry = 1: tool.displacement = "carry"
// (each stamp also picks up the pile the one before heaped). The grid is reset (untimed) per stroke.
template <class Real>
void BM_BulldozeStroke(benchmark::State& state) {
  const double radius = static_cast<double>(state.range(0)) * kCell;
  sb::ToolSpec spec = disk(radius, 0.01);
  spec.rim.model = state.range(1) ? sb::Displacement::Carry : sb::Displacement::Bulldoze;
  std::vector<sb::ToolStamp> stamps;
  for (int i = 0; i <= 48; ++i) {
    stamps.push_back(stamp_at(spec, {2.0 * radius + 0.25 * radius * i, 0.5 * kSize}, {1.0, 0.0}));
    stamps.back().generation = static_cast<std::uint32_t>(i);
  }
  const GridTerrain<Real> fresh = flat_grid<Real>();
  GridTerrain<Real> t = fresh;
  std::size_t next = 0;
  double touched = 0;
  for (auto _ : state) {
    if (next == stamps.size()) {
      state.PauseTiming();
      t = fresh;
      next = 0;
      state.ResumeTiming();
    }
    const sb::StampReport report = t.stamp(stamps[next++]);
    benchmark::DoNotOptimize(report);
    touched += static_cast<double>(report.elements_touched);
  }
  state.counters["radius_cells"] = static_cast<double>(state.range(0));
  state.counters["nodes_touched"] = benchmark::Counter(touched, benchmark::Counter::kAvgIterations);
}
BENCHMARK(BM_BulldozeStroke<double>)
    ->ArgNames({"radius_cells", "carry"})
    ->ArgsProduct({{4, 8, 16, 32}, {0, 1}})
    ->Unit(benchmark::kMicrosecond);

}  // namespace
