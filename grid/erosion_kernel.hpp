#pragma once
// The grid erosion kernel: sb::erosion_transfers (common/erosion.hpp) for one node of a
// regular grid, with everything that does not depend on the heights precomputed per node
// class, and the ordered sweeps that drive it. One implementation for every grid storage:
// the dense HeightGrid and the sparse (OpenVDB) grid instantiate the same templates.
//
// Node classes. A node's stencil (which neighbours exist, their areas, the pair weights
// A_i A_j / (A_i + A_j), the thresholds d tan) depends only on whether it, and its
// neighbours, lie on a border. Per axis a node is described by 4 bits (has a lower
// neighbour, that neighbour is a border node, has an upper neighbour, that one is a border
// node), so there are at most 16 x 16 classes; all but a thin frame of nodes are in the
// interior class. A missing neighbour gets index offset 0 (it reads the centre) and an
// infinite margin (it never receives), so every class runs the same branch-free, unrolled
// loop: no border tests, no division per neighbour, no clearing of buffers per visit (one
// division per node that transfers).
//
// Storage concept (what a Store passed to erosion_visit / erode_ordered must provide):
//   static constexpr bool kRounds;        // true when stored heights are rounded (float)
//   double z(std::size_t k) const;        // height of node k = iy * nx + ix of the layout
//   double put(std::size_t k, double z);  // stores z (rounded); returns z - stored (0 if exact)
//   double& carry();                      // volume (m^3) owed by rounding; read and written
//                                         // only when kRounds
// Active-set concept (grid/active_set.hpp is the dense one):
//   bool empty() const; std::size_t size() const;
//   template <class V> std::size_t sweep(std::size_t max_visits, V&& visit);
//       visit(ix, iy) -> bool transferred; the set marks idle nodes, the caller activates
//   void activate_block(std::size_t ix, std::size_t iy);  // node and its 3 x 3 block
// Node indices are those of the GridLayout (k = iy * nx + ix); a sparse store maps them to
// its own coordinates.
//
// Conservation. Each transfer V from i to j writes z_j + V / A_j and takes the same V
// from the centre: A_i dz_i = -sum_j A_j dz_j up to the rounding of the stored heights.
// With rounding storage the rounding errors of the neighbours' writes (as volumes) and the
// store's carry go into the centre's write, whose own error becomes the new carry: the
// stored volume never drifts by more than one rounding step (height_grid.hpp).
//
// Energy. Sweeps are Gauss-Seidel (each visit sees the heights left by the visits before
// it) and each visit moves at most f times the largest pair excess, split in proportion to
// the pair excesses: for f <= 1 no pair passes the level at which it would be exactly at
// the critical slope, so each transfer lowers the potential energy sum A z^2 / 2
// (it moves mass downhill without inverting the pair); f in (1, 2] may overshoot a pair
// but still contracts it (the scene refuses f > 2).
//
// Cost per visit: 9 height loads (4-neighbour: 5), ~6 floating-point operations per
// neighbour, plus per transfer one division, one store per receiving neighbour and one
// for the centre; the gradient rule adds a square root and a division per visit.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>
#include <type_traits>
#include <vector>

#include "common/erosion.hpp"
#include "common/terrain.hpp"
#include "grid/grid_layout.hpp"

namespace sb::grid {

// What erosion needs to know about a class of nodes (see above). Slots follow Stencil's
// fixed order: +x, -x, +y, -y, (+1,+1), (-1,+1), (+1,-1), (-1,-1).
struct NodeClass {
  std::array<std::ptrdiff_t, 8> offset{};  // index offset of each neighbour, 0 where missing
  std::array<double, 8> weight{};          // A_i A_j / (A_i + A_j), m^2
  std::array<double, 8> area{};            // A_j, m^2
  std::array<double, 8> inv_area{};        // 1 / A_j
  std::array<double, 8> crit{};            // d_j tan_critical: the edge rule's allowed drop
  std::array<double, 8> margin{};          // d_j (tan_settle - tan_critical); +inf where missing
  std::array<double, 8> ox{}, oy{};        // offset to the neighbour, m (gradient rule)
  double area_i = 0.0, inv_area_i = 0.0;
  // Central differences, one-sided on the border: g = (z[+] - z[-]) * inv_run.
  std::ptrdiff_t gx_hi = 0, gx_lo = 0, gy_hi = 0, gy_lo = 0;
  double inv_run_x = 0.0, inv_run_y = 0.0;
};

// The classes of one layout, stencil and rule; built in O(nx + ny) (microseconds).
class ErosionTables {
 public:
  ErosionTables(const GridLayout& layout, int neighbours, const ErosionRule& rule, bool gradient);

  const NodeClass& of(std::size_t ix, std::size_t iy) const {
    return classes_[slot_[axis_code(ix, layout_.nx) | (axis_code(iy, layout_.ny) << 4)]];
  }
  std::size_t bytes() const { return classes_.capacity() * sizeof(NodeClass); }
  const GridLayout& layout() const { return layout_; }
  int neighbours() const { return neighbours_; }
  bool gradient() const { return gradient_; }
  double fraction() const { return fraction_; }
  double tan_critical() const { return tan_critical_; }
  double tan_settle() const { return tan_settle_; }
  // True when the tables were built for this rule (so they can be reused).
  bool built_for(const ErosionRule& rule, bool gradient) const {
    return rule.tan_critical == tan_critical_ && rule.tan_settle == tan_settle_ && rule.fraction == fraction_ &&
           gradient == gradient_;
  }

  // Bits: 1 has a lower neighbour, 2 it is a border node, 4 has an upper neighbour, 8 it is
  // a border node.
  static unsigned axis_code(std::size_t i, std::size_t n) {
    return (i > 0 ? 1u : 0u) | (i == 1 ? 2u : 0u) | (i + 1 < n ? 4u : 0u) | (i + 2 == n ? 8u : 0u);
  }

 private:
  GridLayout layout_;
  int neighbours_;
  bool gradient_;
  double fraction_, tan_critical_, tan_settle_;
  std::array<std::uint8_t, 256> slot_{};  // axis codes -> index in classes_
  std::vector<NodeClass> classes_;        // the classes that occur: at most 5 x 5
};

struct VisitResult {
  int transfers = 0;   // neighbours that received
  double moved = 0.0;  // volume the centre gave, m^3
};

// Applies the rule at node k of class c, in place. Returns the transfers made (none: the
// node is stable). N: stencil size (4 or 8); Gradient: the gradient rule's runs.
template <int N, bool Gradient, class Store>
inline VisitResult erosion_visit(Store& store, const ErosionTables& t, std::size_t k, const NodeClass& c) {
  const double zi = store.z(k);
  double zj[N];
  for (int s = 0; s < N; ++s) zj[s] = store.z(k + c.offset[s]);
  // The rule of common/erosion.hpp (erosion_transfers), unrolled: the edge rule's excess per
  // pair, and with the gradient rule, where the centre's gradient is steeper than tan_settle,
  // the excess along the neighbour's run on the downhill direction where it asks for more.
  double e[N];
  double largest = 0.0, sum = 0.0;
  for (int s = 0; s < N; ++s) {
    const double excess = zi - zj[s] - c.crit[s];
    e[s] = excess > c.margin[s] ? excess : 0.0;
  }
  if constexpr (Gradient) {
    const double gx = (store.z(k + c.gx_hi) - store.z(k + c.gx_lo)) * c.inv_run_x;
    const double gy = (store.z(k + c.gy_hi) - store.z(k + c.gy_lo)) * c.inv_run_y;
    const double g2 = gx * gx + gy * gy;
    if (g2 > t.tan_settle() * t.tan_settle()) {
      const double steepness = std::sqrt(g2);
      const double ux = -gx / steepness, uy = -gy / steepness;  // downhill unit vector
      for (int s = 0; s < N; ++s) {
        const double run = c.ox[s] * ux + c.oy[s] * uy;  // 0 for a missing neighbour
        if (!(run > 0.0)) continue;
        const double along = std::min(zi - zj[s], steepness * run) - run * t.tan_critical();
        if (along > c.margin[s]) e[s] = std::max(e[s], along);
      }
    }
  }
  for (int s = 0; s < N; ++s) {
    e[s] *= c.weight[s];
    sum += e[s];
    largest = std::max(largest, e[s]);
  }
  if (!(sum > 0.0)) return {};
  const double scale = t.fraction() * largest / sum;
  VisitResult r;
  double given = 0.0, error_m3 = 0.0;
  for (int s = 0; s < N; ++s) {
    if (!(e[s] > 0.0)) continue;
    const double v = e[s] * scale;
    const double err = store.put(k + c.offset[s], zj[s] + v * c.inv_area[s]);
    if constexpr (Store::kRounds) error_m3 += err * c.area[s];
    given += v;
    ++r.transfers;
  }
  if constexpr (Store::kRounds) {
    double& carry = store.carry();
    carry = store.put(k, zi - given * c.inv_area_i + (carry + error_m3) * c.inv_area_i) * c.area_i;
  } else {
    store.put(k, zi - given * c.inv_area_i);
  }
  r.moved = given;
  return r;
}

// Which sweep erode_ordered runs (tests force one; Auto is what the terrains use). Dense
// sweeps the active set's bounding box.
enum class SweepPath { Auto, ActiveSet, Dense };

// Whether a pass sweeps the box around the active set (dense_pass) rather than its members:
// a dense pass costs ~1/8 of an active-set visit per node that it skips (measured,
// tests/bench/grid_bench.cpp), so it wins once the members fill about an eighth of their
// bounding box.
inline bool dense_pass_pays(std::size_t active, std::size_t box_nodes) { return active * 8 >= box_nodes; }

// Two heights at p[0..1], widened to double (GCC/Clang vector extensions: one SSE2 register
// on baseline x86-64; no intrinsics, no FMA, so each lane computes what the scalar code
// does, bit for bit).
using Double2 = double __attribute__((vector_size(16)));
using Mask2 = std::int64_t __attribute__((vector_size(16)));
template <class Real>
inline Double2 load2(const Real* p) {
  if constexpr (std::is_same_v<Real, double>) {
    Double2 v;
    std::memcpy(&v, p, sizeof v);
    return v;
  } else {
    using Float2 = float __attribute__((vector_size(8)));
    Float2 f;
    std::memcpy(&f, p, sizeof f);
    return __builtin_convertvector(f, Double2);
  }
}

// Whether each interior node x in [max(1, x0), min(nx - 2, x1)] of a row of contiguous heights `z` (node
// (0, iy); rows iy - 1 and iy + 1 at -nx and +nx) may transfer: the first half of
// erosion_visit with the same floating-point expressions, so a node it calls stable is one
// the visit would leave alone. Two nodes at a time. Interior rows only (every neighbour
// present: the thresholds are the interior class's).
template <int N, bool Gradient, class Real>
void unstable_flags(const Real* z, std::size_t nx, std::size_t x0, std::size_t x1, const NodeClass& c,
                    double tan_settle2, std::int64_t* out) {
  const auto w = static_cast<std::ptrdiff_t>(nx);
  // Local copies: `out` could alias the class's arrays as far as the compiler knows.
  std::ptrdiff_t off[N];
  double crit[N], margin[N];
  for (int s = 0; s < N; ++s) off[s] = c.offset[s], crit[s] = c.crit[s], margin[s] = c.margin[s];
  const double irx = c.inv_run_x, iry = c.inv_run_y;
  const auto flag = [&](std::ptrdiff_t x) {  // one node, scalar
    const double zi = static_cast<double>(z[x]);
    bool u = false;
    for (int s = 0; s < N; ++s) u |= zi - static_cast<double>(z[x + off[s]]) - crit[s] > margin[s];
    if constexpr (Gradient) {
      const double gx = (static_cast<double>(z[x + 1]) - static_cast<double>(z[x - 1])) * irx;
      const double gy = (static_cast<double>(z[x + w]) - static_cast<double>(z[x - w])) * iry;
      u |= gx * gx + gy * gy > tan_settle2;
    }
    return static_cast<std::int64_t>(u);
  };
  std::ptrdiff_t x = std::max<std::ptrdiff_t>(1, static_cast<std::ptrdiff_t>(x0));
  const std::ptrdiff_t end = std::min<std::ptrdiff_t>(w - 1, static_cast<std::ptrdiff_t>(x1) + 1);  // exclusive
  for (; x + 2 <= end; x += 2) {
    const Double2 zi = load2(z + x);
    Mask2 u = {0, 0};
#pragma GCC unroll 8
    for (int s = 0; s < N; ++s) u |= zi - load2(z + x + off[s]) - crit[s] > margin[s];
    if constexpr (Gradient) {
      const Double2 gx = (load2(z + x + 1) - load2(z + x - 1)) * irx;
      const Double2 gy = (load2(z + x + w) - load2(z + x - w)) * iry;
      u |= gx * gx + gy * gy > tan_settle2;
    }
    std::memcpy(out + x, &u, sizeof u);  // lanes are 0 or -1
  }
  for (; x < end; ++x) out[x] = flag(x);
}

// One dense pass: every node of the box `b` (the active set's bounds) visited once, in place
// (Gauss-Seidel), in the direction the active set's next sweep would take; the active set is
// then rebuilt, word by word, from the blocks of the nodes that transferred (each a member
// with a fresh idle count). Same visits, same rule, same conservation as the active-set
// sweep; what differs is which nodes are visited: every node of the box, members or not,
// once (an active-set sweep visits only members, and those activated ahead of it again).
//
// Exactness of the shortcut. On a store with contiguous heights (HeightGrid: data()), a
// row's nodes are first classed by unstable_flags, computed after the previous row is done;
// a node is then visited only if it is flagged, on a border, or one of the two nodes before
// it in the row transferred (a visit writes into its 3 x 3 block, which a node up to two
// columns away reads). Its inputs are otherwise those it was classed with, so skipping it is
// exactly what its visit would have done: the pass gives the same heights, bit for bit, as a
// plain sweep of every node of the box (which is what it runs on other stores, e.g. the
// sparse grid).
//
// Cost: O(box nodes) per pass -- the classing vectorised over the row, one visit per unstable
// node -- plus O(words of the box's rows) to find the box and to rebuild the active set.
template <int N, bool Gradient, class Store, class Active>
void dense_pass(Store& store, Active& active, const typename Active::Bounds& b, const ErosionTables& t,
                ErosionReport& report, double& moved) {
  const std::size_t nx = t.layout().nx, ny = t.layout().ny;
  const std::size_t width = b.x1 - b.x0 + 1, height = b.y1 - b.y0 + 1;
  const unsigned pass = active.next_sweep();
  const bool y_up = pass % 2 == 0;
  const bool x_up = (pass / 2) % 2 == 0;
  const std::size_t words = active.words_per_row();
  std::vector<std::uint64_t> moved_bits(words * height, 0);  // rows y0..y1: the nodes that transferred
  constexpr bool kContiguous = requires { store.data(); };
  std::vector<std::int64_t> flags(kContiguous ? nx : 0, 1);  // as wide as a double: one vector lane each
  const double tan_settle2 = t.tan_settle() * t.tan_settle();
  for (std::size_t r = 0; r < height; ++r) {
    const std::size_t iy = y_up ? b.y0 + r : b.y1 - r;
    const bool interior_row = iy > 0 && iy + 1 < ny && nx >= 3;
    const NodeClass& middle = t.of(nx / 2, iy);
    if constexpr (kContiguous) {
      if (interior_row)
        unstable_flags<N, Gradient>(store.data() + iy * nx, nx, b.x0, b.x1, middle, tan_settle2, flags.data());
    }
    int since_transfer = 3;  // nodes visited since the last one that transferred, in this row
    for (std::size_t c = 0; c < width; ++c) {
      const std::size_t ix = x_up ? b.x0 + c : b.x1 - c;
      const bool edge = ix < 2 || ix + 2 >= nx;
      if constexpr (kContiguous) {
        if (interior_row && since_transfer > 2 && ix > 0 && ix + 1 < nx && !flags[ix]) {
          ++since_transfer;
          continue;
        }
      }
      const VisitResult v = erosion_visit<N, Gradient>(store, t, iy * nx + ix, edge ? t.of(ix, iy) : middle);
      if (v.transfers == 0) {
        ++since_transfer;
        continue;
      }
      since_transfer = 0;
      report.transfers += static_cast<std::size_t>(v.transfers);
      moved += v.moved;
      moved_bits[(iy - b.y0) * words + ix / 64] |= std::uint64_t{1} << (ix % 64);
    }
  }
  active.assign_blocks(moved_bits, b.y0, b.y1);
  report.updates += width * height;
}

// Passes until `active` is empty or the budget is spent: ordered, live sweeps of the active
// set (see active_set.hpp for the order), or a dense pass over the set's bounding box
// (dense_pass) when the members fill enough of it and the budget allows the whole box.
// Cost: O(visits) plus the set's O(rows) per active-set sweep, O(box nodes) per dense pass.
template <int N, bool Gradient, class Store, class Active>
ErosionReport erode_ordered(Store& store, Active& active, const ErosionTables& t, const ErosionBudget& budget,
                            SweepPath path = SweepPath::Auto) {
  ErosionReport report;
  const std::size_t nx = t.layout().nx;
  double moved = 0.0;
  while (report.passes < budget.max_passes && !active.empty() && report.updates < budget.max_updates) {
    ++report.passes;
    if (path != SweepPath::ActiveSet) {
      const typename Active::Bounds b = active.bounds();
      const bool dense = path == SweepPath::Dense || (dense_pass_pays(active.size(), b.nodes()) &&
                                                      budget.max_updates - report.updates >= b.nodes());
      if (dense) {
        dense_pass<N, Gradient>(store, active, b, t, report, moved);
        continue;
      }
    }
    report.updates += active.sweep(budget.max_updates - report.updates, [&](std::size_t ix, std::size_t iy) {
      const VisitResult v = erosion_visit<N, Gradient>(store, t, iy * nx + ix, t.of(ix, iy));
      if (v.transfers == 0) return false;
      report.transfers += static_cast<std::size_t>(v.transfers);
      moved += v.moved;
      active.activate_block(ix, iy);
      return true;
    });
  }
  report.active = active.size();
  report.volume_moved_m3 = moved;
  return report;
}

// Dispatches on the stencil size and the rule kind.
template <class Store, class Active>
ErosionReport erode_ordered(Store& store, Active& active, const ErosionTables& t, const ErosionBudget& budget,
                            SweepPath path = SweepPath::Auto) {
  if (t.neighbours() == 4)
    return t.gradient() ? erode_ordered<4, true>(store, active, t, budget, path)
                        : erode_ordered<4, false>(store, active, t, budget, path);
  return t.gradient() ? erode_ordered<8, true>(store, active, t, budget, path)
                      : erode_ordered<8, false>(store, active, t, budget, path);
}

}  // namespace sb::grid
