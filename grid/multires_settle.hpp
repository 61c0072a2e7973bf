#pragma once
// Multi-resolution settling for the regular grids: a coarse-to-fine cascade that moves sand
// over long distances on coarse copies of the grid, where a pass is cheap and a distance is
// a few nodes, so that the fine passes only finish what is left at the fine scale.
//
// Why. The kernel's relaxation (erosion_kernel.hpp) moves at most half a pair's excess per
// visit: near the critical angle it behaves like diffusion, and the passes to settle a
// disturbance of width L grow as (L / h)^2 (flat_stroke.toml: 163, 552, 2077 passes at 2.5,
// 1.25, 0.625 mm) times an active set that grows as n: a settling cost of n^2.
//
// The cascade (multires_settle). Within a box around the active set (its bounding box,
// widened by a quarter of its larger side on every side, at least 4 nodes, clipped to the
// grid), level 1 groups the fine nodes in blocks of 2 x 2 (2 x 1 or 1 x 2 when an axis has
// fewer than 16 nodes and is not halved; a lone node at an odd end), level 2 groups level
// 1's nodes the same way, and so on while an axis has 16 nodes or more. A coarse node
// stands for the sum of its children's areas (per axis the sum of their weights, so
// A = Wx Wy), lies at their area-weighted centroid and starts at their area-weighted mean
// height (block means of block means: the mean of its fine nodes). Then, from the coarsest
// level to level 1: the level is relaxed with the fine rule's own kernel (erosion_visit: the
// same rule, fraction and thresholds, with the level's distances and areas,
// MultiresClasses) over its own active set -- the nodes above active fine nodes, and the
// blocks of those the coarser level changed -- for at most 512 passes, and its total change
// dZ_I (relaxed minus restricted height, so it includes what the coarser levels changed) is
// added to every one of its children. The fine nodes that changed, and their blocks, join
// the fine active set, and the fine passes (erode_ordered) finish: the state returned is at
// repose under the fine rule whenever the fine passes empty the active set, as without the
// cascade.
//
// Why piecewise constant. The fine detail under a block (a cut wall, a rim) is kept and only
// shifted by the block's change; the fine passes then settle the detail locally. Rebuilding
// the children from the coarse heights instead (a slope per block) replaces detail the fine
// rule would have kept with flat or bumped blocks below the critical angle, which the rule,
// moving sand only downhill, never undoes: on trench_azimuth.toml such rebuilds leave the walls
// degrees flatter than critical, where piecewise-constant injection leaves them where the fine
// passes alone do (tests/unit/grid_multires_test.cpp checks the cascade against the fine passes).
//
// Conservation. A coarse transfer of V from I to J changes Z_I by -V / A_I and Z_J by
// V / A_J (the kernel's pairwise transfer, with the level's areas); adding dZ_I to every
// child c of I changes the finer volume by sum_c A_c dZ_I = A_I dZ_I, exactly the coarse
// change, because A_I is the sum of the children's areas. So every level and the fine grid
// keep their volume up to the rounding of the heights (coarse levels in double; a float
// fine grid takes the change through its rounding carry, height_grid.hpp, like any write).
//
// Energy. With Z_I the area-weighted mean of its children, adding dZ_I to them changes the
// finer level's potential energy sum A z^2 / 2 by sum_c A_c ((z_c + dZ_I)^2 - z_c^2) / 2 =
// A_I Z_I dZ_I + A_I dZ_I^2 / 2: exactly the coarse level's energy change. Each level's
// relaxation lowers its own energy (the kernel's argument, erosion_kernel.hpp, "Energy"),
// and every level is restricted from the same fine state before any level changes, so when
// a level's change is added its restricted heights are still the means of its children. By
// induction the fine energy changes by the coarsest level's relaxation plus every other
// level's: it never rises. Conditions: piecewise-constant injection (a bilinear one would
// need matching weights, borders included), coarse areas the sums of the children's, coarse
// heights their area-weighted means, all levels restricted before any is relaxed, and the
// kernel's own condition (f <= 1 for monotone energy; the scene's default is 0.5). In
// floating point up to the rounding of the heights (tests/unit/grid_multires_test.cpp).
//
// Accuracy. Where the sand spreads over many coarse cells onto flat ground (a pile poured at a
// point), the piecewise-constant change of the outermost cells puts sand past where the fine rule
// would have left it, and the rule, which moves sand only downhill, never takes it back: the
// pile ends wider and flatter, more so with every level (pile.toml on a 1 mm grid: flank 29.04
// degrees, RMSE 107 um, against 30.00 and 28 um with the fine passes alone, which take 6.6x the
// time; 0.5 mm: 28.45 and 109 against 30.04 and 25, 8.9x). Walls that sand falls from keep their
// angle (trench.toml within 0.01 degrees). So the cascade is a scene's choice (erosion.cascade,
// ErosionBudget::cascade; results/cascade.md).
//
// When (multires_pays, erode_settling): only when the budget allows it (cascade), for a budget
// of 32 passes or more (the runner's settling asks for 64 at a time; interactive steps and the
// stroke's steps for 4), an update budget of at least 8 updates per active node, 1024 active
// nodes or more, and a box of at most (passes x active nodes) nodes, so that restricting it
// costs no more than the passes it replaces; the cascade runs once per such call (counted as
// one pass, its coarse visits as updates), then the fine passes use the rest of the budget.
// Interactive budgets therefore stay local and cheap. The cascade depends only on the
// heights and the active set's members, so the dense and the sparse grid still compute the
// same heights bit for bit.
//
// Cost: O(box) to restrict and inject, plus the levels' visits (each level's active set:
// the nodes above fine members and around changes); memory per coarse node 8 bytes for the
// height, 8 for the restricted height, 1 flag and the coarse active set's ~2 bytes, about a
// third of the box's nodes in all, freed on return. What it saves: results/settling.md and
// results/cascade.md.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "common/terrain.hpp"
#include "grid/active_set.hpp"
#include "grid/erosion_kernel.hpp"

namespace sb::grid {

// One axis of a level: per node, the sum of its finer nodes' weights (m; level 0: the
// trapezoid weights) and their weighted centroid (m, from the box's first node). A coarse
// axis pairs the finer nodes 2i, 2i + 1 (a lone last node when the count is odd), or keeps
// them one to one when the axis is too short to halve.
struct MultiresAxis {
  std::vector<double> weight, position;
  std::vector<std::uint32_t> parent;  // per node of the finer axis
  std::size_t size() const { return weight.size(); }
  static MultiresAxis coarsen(const MultiresAxis& finer, bool halve);
};

// A coarse level's node classes (erosion_kernel.hpp's NodeClass, with the level's own
// distances and areas): nodes whose axis neighbourhoods agree share one class.
class MultiresClasses {
 public:
  MultiresClasses(const MultiresAxis& x, const MultiresAxis& y, int neighbours, const ErosionTables& fine);
  const NodeClass& of(std::size_t ix, std::size_t iy) const { return classes_[cx_[ix] * ny_classes_ + cy_[iy]]; }

 private:
  std::vector<std::uint8_t> cx_, cy_;
  std::size_t ny_classes_ = 0;
  std::vector<NodeClass> classes_;
};

// What a cascade did, per level (index 0 = level 1, the finest coarse level).
struct MultiresLevelReport {
  std::size_t nx = 0, ny = 0;
  int passes = 0;
  std::size_t updates = 0;
  std::size_t changed = 0;                         // nodes whose height the level changed
  double energy_before = 0.0, energy_after = 0.0;  // sum A z^2 / 2, when measured
};
struct MultiresReport {
  std::vector<MultiresLevelReport> levels;
  std::size_t box_nodes = 0;
  std::size_t fine_changed = 0;  // fine nodes injected into
  std::size_t updates = 0;       // coarse visits, all levels
  std::size_t transfers = 0;
  double moved_m3 = 0.0;
};

struct MultiresOptions {
  bool measure_energy = false;  // fill energy_before/after (O(level nodes) each)
  int max_passes_per_level = 512;
  // No cascade when the box holds more nodes (its O(box) restriction would cost more than
  // the fine passes it saves).
  std::size_t max_box_nodes = std::numeric_limits<std::size_t>::max();
};

// Minimum budget and active set for the cascade (see "When" above).
inline constexpr int kMultiresMinPasses = 32;
inline constexpr std::size_t kMultiresMinActive = 1024;

namespace multires_detail {

// Inclusive box of fine nodes.
struct Box {
  std::size_t x0, x1, y0, y1;
  std::size_t nx() const { return x1 - x0 + 1; }
  std::size_t ny() const { return y1 - y0 + 1; }
};

// The members' bounding box, widened (see "The cascade"). false: no members.
template <class Active>
bool settle_box(const Active& active, const GridLayout& layout, Box& box) {
  box = {layout.nx, 0, layout.ny, 0};
  for (std::size_t y = 0; y < layout.ny; ++y) {
    std::size_t a, b;
    if (!active.row_span(y, a, b)) continue;
    box.x0 = std::min(box.x0, a), box.x1 = std::max(box.x1, b);
    box.y0 = std::min(box.y0, y), box.y1 = y;
  }
  if (box.x0 > box.x1) return false;
  const std::size_t margin = std::max<std::size_t>(4, std::max(box.nx(), box.ny()) / 4);
  box.x0 = box.x0 > margin ? box.x0 - margin : 0;
  box.y0 = box.y0 > margin ? box.y0 - margin : 0;
  box.x1 = std::min(layout.nx - 1, box.x1 + margin);
  box.y1 = std::min(layout.ny - 1, box.y1 + margin);
  return true;
}

// A coarse level's heights (double): the kernel's Store concept, without rounding.
struct LevelStore {
  static constexpr bool kRounds = false;
  std::vector<double> h;
  double unused_carry = 0.0;
  double z(std::size_t k) const { return h[k]; }
  double put(std::size_t k, double v) {
    h[k] = v;
    return 0.0;
  }
  double& carry() { return unused_carry; }
};

struct Level {
  MultiresAxis x, y;  // x.parent: the parents of the finer level's nodes
  LevelStore store;
  std::vector<std::uint8_t> fine_active;  // some fine descendant is an active member
  std::vector<double> restricted;         // the heights restricted from the finer level (block means)
  std::size_t nx() const { return x.size(); }
  std::size_t ny() const { return y.size(); }
};

inline double level_energy(const Level& l) {
  double e = 0.0;
  for (std::size_t iy = 0; iy < l.ny(); ++iy)
    for (std::size_t ix = 0; ix < l.nx(); ++ix) {
      const double z = l.store.h[iy * l.nx() + ix];
      e += l.x.weight[ix] * l.y.weight[iy] * z * z * 0.5;
    }
  return e;
}

// Adds each coarse node's total change (relaxed minus restricted height) to its children in
// the finer level, read with z(i, j) and written with put(i, j, z); changed(i, j) is called
// for each node written. O(finer nodes).
template <class Z, class Put, class Changed>
void inject_change(const Level& coarse, const MultiresAxis& fx, const MultiresAxis& fy, Z&& z, Put&& put,
                   Changed&& changed) {
  const std::size_t nx = coarse.nx();
  for (std::size_t j = 0; j < fy.size(); ++j)
    for (std::size_t i = 0; i < fx.size(); ++i) {
      const std::size_t k = coarse.y.parent[j] * nx + coarse.x.parent[i];
      const double dz = coarse.store.h[k] - coarse.restricted[k];
      if (dz == 0.0) continue;
      put(i, j, z(i, j) + dz);
      changed(i, j);
    }
}

// Relaxes a level over `active` until it is empty or max_passes passes are done.
template <int N, bool Gradient>
void relax_level(Level& l, ActiveSet& active, const MultiresClasses& classes, const ErosionTables& t, int max_passes,
                 MultiresLevelReport& lr, MultiresReport& report) {
  const std::size_t nx = l.nx();
  while (!active.empty() && lr.passes < max_passes) {
    ++lr.passes;
    lr.updates += active.sweep(std::numeric_limits<std::size_t>::max(), [&](std::size_t ix, std::size_t iy) {
      const VisitResult v = erosion_visit<N, Gradient>(l.store, t, iy * nx + ix, classes.of(ix, iy));
      if (v.transfers == 0) return false;
      report.transfers += static_cast<std::size_t>(v.transfers);
      report.moved_m3 += v.moved;
      active.activate_block(ix, iy);
      return true;
    });
  }
  report.updates += lr.updates;
}

}  // namespace multires_detail

// Whether the cascade pays for this call (see "When" above).
template <class Active>
bool multires_pays(const Active& active, const ErosionBudget& budget) {
  return budget.cascade && budget.max_passes >= kMultiresMinPasses && active.size() >= kMultiresMinActive &&
         budget.max_updates / 8 >= active.size();
}

// The cascade (see above) on the fine grid `store` (erosion_kernel.hpp's Store concept) with
// its active set; tables: the fine grid's (the rule). The fine nodes it changes join
// `active`; the caller then runs the fine passes (erode_ordered).
template <int N, bool Gradient, class Store, class Active>
MultiresReport multires_settle(Store& store, Active& active, const ErosionTables& t,
                               const MultiresOptions& options = {}) {
  using namespace multires_detail;
  MultiresReport report;
  const GridLayout& layout = t.layout();
  Box box;
  if (!settle_box(active, layout, box)) return report;
  report.box_nodes = box.nx() * box.ny();
  if (report.box_nodes > options.max_box_nodes) return report;
  constexpr std::size_t kHalveFrom = 16;  // an axis with fewer nodes is not halved
  const auto coarser = [](const MultiresAxis& a) { return MultiresAxis::coarsen(a, a.size() >= kHalveFrom); };

  // Level 0: the box's fine nodes (axes only; heights stay in the store).
  MultiresAxis fx, fy;
  for (std::size_t i = box.x0; i <= box.x1; ++i) {
    fx.weight.push_back(layout.weight_x(i));
    fx.position.push_back(static_cast<double>(i - box.x0) * layout.dx);
  }
  for (std::size_t i = box.y0; i <= box.y1; ++i) {
    fy.weight.push_back(layout.weight_y(i));
    fy.position.push_back(static_cast<double>(i - box.y0) * layout.dy);
  }
  if (fx.size() < kHalveFrom && fy.size() < kHalveFrom) return report;  // no coarse level

  // Levels 1..L, restricted from the fine heights: block means Z_I = sum_c A_c z_c / A_I,
  // each level from the finer one.
  std::vector<Level> levels;
  const auto restrict_from = [](Level& c, const MultiresAxis& x, const MultiresAxis& y, auto&& z_of, auto&& active_of) {
    c.store.h.assign(c.nx() * c.ny(), 0.0);
    c.fine_active.assign(c.nx() * c.ny(), 0);
    for (std::size_t j = 0; j < y.size(); ++j)
      for (std::size_t i = 0; i < x.size(); ++i) {
        const std::size_t p = c.y.parent[j] * c.nx() + c.x.parent[i];
        c.store.h[p] += x.weight[i] * y.weight[j] * z_of(i, j);
        if (active_of(i, j)) c.fine_active[p] = 1;
      }
    for (std::size_t iy = 0; iy < c.ny(); ++iy)
      for (std::size_t ix = 0; ix < c.nx(); ++ix) c.store.h[iy * c.nx() + ix] /= c.x.weight[ix] * c.y.weight[iy];
    c.restricted = c.store.h;
  };
  levels.push_back({coarser(fx), coarser(fy), {}, {}, {}});
  restrict_from(
      levels.back(), fx, fy,
      [&](std::size_t i, std::size_t j) { return store.z((box.y0 + j) * layout.nx + box.x0 + i); },
      [&](std::size_t i, std::size_t j) { return active.contains(box.x0 + i, box.y0 + j); });
  while (levels.back().nx() >= kHalveFrom || levels.back().ny() >= kHalveFrom) {
    Level c{coarser(levels.back().x), coarser(levels.back().y), {}, {}, {}};
    const Level& f = levels.back();
    restrict_from(
        c, f.x, f.y, [&](std::size_t i, std::size_t j) { return f.store.h[j * f.nx() + i]; },
        [&](std::size_t i, std::size_t j) { return f.fine_active[j * f.nx() + i] != 0; });
    levels.push_back(std::move(c));
  }

  // Coarsest to finest: relax, then add the level's change to the finer level.
  std::vector<std::uint8_t> changed_from_coarser;  // per node of the current level
  for (std::size_t li = levels.size(); li-- > 0;) {
    Level& l = levels[li];
    ActiveSet level_active(l.nx(), l.ny(), 2);
    for (std::size_t iy = 0; iy < l.ny(); ++iy)
      for (std::size_t ix = 0; ix < l.nx(); ++ix) {
        const std::size_t k = iy * l.nx() + ix;
        if (!changed_from_coarser.empty() && changed_from_coarser[k])
          level_active.activate_block(ix, iy);
        else if (l.fine_active[k])
          level_active.activate(ix, iy);
      }
    const MultiresClasses classes(l.x, l.y, N, t);
    const std::vector<double> before = l.store.h;
    MultiresLevelReport lr;
    lr.nx = l.nx(), lr.ny = l.ny();
    if (options.measure_energy) lr.energy_before = level_energy(l);
    relax_level<N, Gradient>(l, level_active, classes, t, options.max_passes_per_level, lr, report);
    if (options.measure_energy) lr.energy_after = level_energy(l);
    for (std::size_t k = 0; k < before.size(); ++k) lr.changed += l.store.h[k] != before[k] ? 1 : 0;
    report.levels.insert(report.levels.begin(), lr);
    if (li > 0) {  // into the finer coarse level
      Level& f = levels[li - 1];
      changed_from_coarser.assign(f.nx() * f.ny(), 0);
      inject_change(
          l, f.x, f.y, [&](std::size_t i, std::size_t j) { return f.store.h[j * f.nx() + i]; },
          [&](std::size_t i, std::size_t j, double v) { f.store.h[j * f.nx() + i] = v; },
          [&](std::size_t i, std::size_t j) { changed_from_coarser[j * f.nx() + i] = 1; });
      continue;
    }
    inject_change(  // into the fine grid
        l, fx, fy, [&](std::size_t i, std::size_t j) { return store.z((box.y0 + j) * layout.nx + box.x0 + i); },
        [&](std::size_t i, std::size_t j, double v) {
          const std::size_t k = (box.y0 + j) * layout.nx + box.x0 + i;
          if constexpr (Store::kRounds) {
            // As any rounded write: the carry goes in, the new rounding error becomes the carry.
            const double area = fx.weight[i] * fy.weight[j];
            double& carry = store.carry();
            carry = store.put(k, v + carry / area) * area;
          } else {
            store.put(k, v);
          }
        },
        [&](std::size_t i, std::size_t j) {
          active.activate_block(box.x0 + i, box.y0 + j);
          ++report.fine_changed;
        });
  }
  return report;
}

// Dispatches on the stencil size and the rule kind.
template <class Store, class Active>
MultiresReport multires_settle(Store& store, Active& active, const ErosionTables& t,
                               const MultiresOptions& options = {}) {
  if (t.neighbours() == 4)
    return t.gradient() ? multires_settle<4, true>(store, active, t, options)
                        : multires_settle<4, false>(store, active, t, options);
  return t.gradient() ? multires_settle<8, true>(store, active, t, options)
                      : multires_settle<8, false>(store, active, t, options);
}

// Erosion as the terrains run it: the cascade first when it pays (multires_pays), then the
// fine passes (erode_ordered) within the budget. The cascade's visits count as updates, and
// as one pass. Both grids call this, so they stay identical (threads: the fine passes' large
// dense passes may use two, dense_pass; the heights do not depend on it).
template <class Store, class Active>
ErosionReport erode_settling(Store& store, Active& active, const ErosionTables& t, const ErosionBudget& budget,
                             SweepPath path, bool multires, unsigned threads = 1) {
  if (!multires || path != SweepPath::Auto || !multires_pays(active, budget))
    return erode_ordered(store, active, t, budget, path, threads);
  MultiresOptions options;
  options.max_box_nodes = static_cast<std::size_t>(budget.max_passes) * active.size();
  const MultiresReport m = multires_settle(store, active, t, options);
  if (m.levels.empty())
    return erode_ordered(store, active, t, budget, path, threads);  // no coarse level, or too large a box
  ErosionBudget rest = budget;
  rest.max_passes -= 1;
  rest.max_updates -= std::min(rest.max_updates, m.updates);
  ErosionReport r = erode_ordered(store, active, t, rest, path, threads);
  r.passes += 1;
  r.updates += m.updates;
  r.transfers += m.transfers;
  r.volume_moved_m3 += m.moved_m3;
  return r;
}

}  // namespace sb::grid
