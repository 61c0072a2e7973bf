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
#include <limits>
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

// Ordered, live sweeps over `active` until it is empty or the budget is spent (see
// active_set.hpp for the order). Cost: O(visits) plus the set's O(rows) per sweep.
template <int N, bool Gradient, class Store, class Active>
ErosionReport erode_ordered(Store& store, Active& active, const ErosionTables& t, const ErosionBudget& budget) {
  ErosionReport report;
  const std::size_t nx = t.layout().nx;
  double moved = 0.0;
  while (report.passes < budget.max_passes && !active.empty() && report.updates < budget.max_updates) {
    ++report.passes;
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
ErosionReport erode_ordered(Store& store, Active& active, const ErosionTables& t, const ErosionBudget& budget) {
  if (t.neighbours() == 4)
    return t.gradient() ? erode_ordered<4, true>(store, active, t, budget)
                        : erode_ordered<4, false>(store, active, t, budget);
  return t.gradient() ? erode_ordered<8, true>(store, active, t, budget)
                      : erode_ordered<8, false>(store, active, t, budget);
}

}  // namespace sb::grid
