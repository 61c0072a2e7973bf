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
// Active-set concept (grid/active_set.hpp, BasicActiveSet, for both grids):
//   bool empty() const; std::size_t size() const;
//   template <class V> std::size_t sweep(std::size_t max_visits, V&& visit);
//       visit(ix, iy) -> bool transferred; the set marks idle nodes, the caller activates
//   void activate_block(std::size_t ix, std::size_t iy);  // node and its 3 x 3 block
//   Spans spans() const; bool row_span(y, x0&, x1&) const; unsigned next_sweep();
//   std::size_t words_per_row() const;
//   void assign_blocks(centres, y0, y1, x0, x1);  // the dense pass's bookkeeping
// Node indices are those of the GridLayout (k = iy * nx + ix); a sparse store maps them to
// its own coordinates. A store may also offer data() (contiguous heights, HeightGrid), or
// read_row / write_changed (SparseHeights: the dense pass then runs each row on a
// RowWindow, grid/row_window.hpp, a contiguous copy of the three rows it touches that slides
// from row to row).
//
// Conservation. Each transfer V from i to j writes z_j + V / A_j and takes the same V
// from the centre: A_i dz_i = -sum_j A_j dz_j up to the rounding of the stored heights.
// With rounding storage the rounding errors of the neighbours' writes (as volumes) and the
// store's carry go into the centre's write, whose own error becomes the new carry: the
// stored volume never drifts by more than one rounding step (height_grid.hpp).
//
// Two sweeps (erode_ordered chooses per pass). The active-set sweep visits the members in
// an alternating, live order (active_set.hpp). The dense pass (dense_pass) visits every node
// from the first to the last member of each row (its span), row after row, and is taken when
// the members fill at least an eighth of the spans: it first classes a row's nodes with
// vector arithmetic (reads only) and visits only those that may transfer, in three phases
// per row (the columns modulo 3: visits of a phase touch disjoint blocks, so they overlap in
// the processor and run up to eight at a time in AVX-512 lanes, erosion_lanes_avx512.hpp, or
// four in AVX2 lanes, chosen at run time by what the CPU has), with no bookkeeping per visit
// (the active set is rebuilt word by word after the pass). Both write in place, one node after
// the other in a fixed order (disjoint visits at once are the same as one after the
// other); the vector classing never writes, so both are Gauss-Seidel sweeps with the
// conservation above and the energy argument below. They differ in which nodes they visit
// (the dense pass also visits non-members in the spans; the active-set sweep revisits members
// activated ahead of it) and in the order within a row, so their results differ in the order
// grains stop, not in conservation: within a cell of each other on random rough states
// (tests/unit/grid_dense_pass_test.cpp) and within the goldens' bounds on the shipped scenes.
// The choice and the order depend only on the active set, so the dense and sparse grids still
// compute the same heights bit for bit. A large dense pass goes as two bands of rows and the
// seam between them (dense_pass), which may run on two threads: the same order either way.
//
// Energy. Each visit sees the heights left by the visits before it, and moves at most f
// times the largest pair excess, split in proportion to the pair excesses: for f <= 1 no
// pair passes the level at which it would be exactly at the critical slope, so each
// transfer lowers the potential energy sum A z^2 / 2 (it moves mass downhill without
// inverting the pair); f in (1, 2] may overshoot a pair but still contracts it (the scene
// refuses f > 2).
//
// Why not a Jacobi (two-pass) sweep. If every node's transfers were computed from the same
// old heights and applied together, a node could receive from all its neighbours at once.
// With equal areas A and one pair each, a neighbour i with excess height x over a pit j
// (drop = d tan_critical + x) sends V = f x A / 2: i falls by f x / 2, and the pit rises
// by N f x / 2 if all N neighbours do the same. The pair's excess becomes
// x (1 - f (N + 1) / 2): the pass conserves volume exactly (each V is taken and given once)
// but is monotone in energy (no pair inverted) only for f <= 2 / (N + 1), 0.22 with 8
// neighbours, 0.4 with 4. At the default f = 0.5 an 8-neighbour pit overshoots to
// -1.25 x (it becomes a peak), so a Jacobi sweep would need a fraction 2.25x smaller, and
// about that many more passes to settle: the dense pass stays Gauss-Seidel. A faster sweep of
// the wrong order settles later: tests/bench/grid_bench.cpp's BM_JacobiSweep (a vectorised
// two-pass sweep at f = 2/9, every node each pass) and BM_Settle* (passes, updates and time
// to rest from the 512^2 dunes) measure both orders.
//
// Why not red-black (four colours). With 8 neighbours, four colours (x mod 2, y mod 2) keep
// same-colour nodes from being neighbours, but two of them can share a neighbour (a diagonal
// node has four same-colour neighbours): computed from the same old heights, their transfers
// into it pile up as in a Jacobi pass with N = 4 senders, monotone only for f <= 2 / 5. Nine
// colours (x mod 3, y mod 3) give disjoint blocks, so no accumulation and no condition on f;
// the dense pass uses the row-wise half of that (x mod 3 within a row, rows in order), which
// keeps the along-y avalanche of a row sweep and is exactly a sequential order.
//
// Cost per visit: 9 height loads (4-neighbour: 5), ~6 floating-point operations per neighbour,
// plus per transfer one division, and a store per receiving neighbour and one for the centre
// (visits in vector lanes write every slot: no branch per slot); the gradient rule adds a
// square root and a division per visit. Float costs more than its instructions: the rounding
// carry chains every transferring visit to the one before, so it gains least from wider
// lanes. How to measure: tests/bench/grid_bench.cpp (updates per second on the pile, the
// stroke and 2048^2 all active; BM_AllActiveTwoThreads for dense_pass's two bands; against
// BM_ReferenceSweep, the plain scalar sweep), callgrind for instructions per update (it runs
// no AVX-512), perf for where the time goes. What was tried beyond this and did not pay:
// erosion_lanes_avx512.hpp. The sparse grid runs the same paths on a RowWindow
// (row_window.hpp) that slides from row to row: each row of a run of adjacent visited rows is
// read once and its changed heights written back once, O(the columns its windows held);
// tests/bench/sparse_bench.cpp compares its steps with the dense grid's.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <exception>
#include <limits>
#include <system_error>
#include <thread>
#include <type_traits>
#include <utility>
#include <vector>

#include "common/erosion.hpp"
#include "common/terrain.hpp"
#include "grid/erosion_lanes_avx512.hpp"
#include "grid/grid_layout.hpp"
#include "grid/row_bits.hpp"
#include "grid/row_window.hpp"

// _mm256_movemask_pd, in the AVX2 functions only (compiled for AVX2 by their target attribute).
#include <immintrin.h>

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

  // Slot s holds a neighbour at index offset `index_offset`, of area `area_j`, at (dx, dy) m.
  void set_neighbour(int s, std::ptrdiff_t index_offset, double area_j, double dx, double dy, double tan_critical,
                     double tan_settle) {
    const double d = std::hypot(dx, dy);
    offset[s] = index_offset;
    area[s] = area_j;
    inv_area[s] = 1.0 / area_j;
    weight[s] = area_i * area_j / (area_i + area_j);
    crit[s] = d * tan_critical;
    margin[s] = d * (tan_settle - tan_critical);
    ox[s] = dx;
    oy[s] = dy;
  }
  // Slot s has no neighbour: it reads the centre and never receives.
  void set_missing(int s) {
    offset[s] = 0;
    margin[s] = std::numeric_limits<double>::infinity();
    crit[s] = 0.0;
  }
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

// Heights widened to double (GCC/Clang vector extensions, no FMA, so each lane computes what
// the scalar code does, bit for bit): two at p[0..1] in one SSE2 register (baseline x86-64),
// four at p[0..3] in one AVX2 register (only inside functions compiled for AVX2).
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

using Double4 = double __attribute__((vector_size(32)));
using Mask4 = std::int64_t __attribute__((vector_size(32)));
template <class Real>
[[gnu::target("avx2"), gnu::always_inline]] inline Double4 load4(const Real* p) {
  if constexpr (std::is_same_v<Real, double>) {
    Double4 v;
    std::memcpy(&v, p, sizeof v);
    return v;
  } else {
    using Float4 = float __attribute__((vector_size(16)));
    Float4 f;
    std::memcpy(&f, p, sizeof f);
    return __builtin_convertvector(f, Double4);
  }
}

// Four interior nodes k, k + 3, k + 6, k + 9 of an interior row of a contiguous store, all of
// the interior class c, visited at once, one per AVX2 lane. Their 3 x 3 blocks are disjoint,
// so this is the four visits one after the other, in any order; each lane computes what
// erosion_visit computes for its node, bit for bit (the same expressions, slot by slot in the
// same order; AVX2 brings no FMA, so nothing is contracted). The rounding carry (float) is
// settled lane by lane in visiting order (`reverse`: k + 9 first). Lanes that stay put write
// their own heights back. Returns the lanes that transferred (bit l: node k + 3 l); then
// given[l] is the volume lane l gave (m^3; +0.0 for lanes that stayed put) and `transfers`
// the receiving neighbours of all lanes (both unset when it returns 0), as erosion_visit8 does.
// Gradient: the gradient rule (the interior class's central differences), as
// erosion_visit<N, true>.
// Heights p[0], p[3], p[6], p[9], widened to double.
template <class Real>
[[gnu::target("avx2"), gnu::always_inline]] inline Double4 every3(const Real* p) {
  return Double4{static_cast<double>(p[0]), static_cast<double>(p[3]), static_cast<double>(p[6]),
                 static_cast<double>(p[9])};
}
template <int N, bool Gradient, class Store>
[[gnu::target("avx2")]] unsigned erosion_visit4(Store& store, const ErosionTables& t, std::size_t k, const NodeClass& c,
                                                bool reverse, double given_out[4], std::size_t& transfers_out) {
  const auto* z = store.data() + k;
  const Double4 zi = every3(z);
  Double4 zj[N], e[N];
  Double4 sum = {0.0, 0.0, 0.0, 0.0}, largest = {0.0, 0.0, 0.0, 0.0};
  const Double4 one = {1.0, 1.0, 1.0, 1.0};
  for (int s = 0; s < N; ++s) {
    zj[s] = every3(z + c.offset[s]);
    const Double4 excess = zi - zj[s] - c.crit[s];
    e[s] = reinterpret_cast<Double4>(reinterpret_cast<Mask4>(excess) & (excess > c.margin[s]));
  }
  if constexpr (Gradient) {  // erosion_visit's expressions, lane by lane; lanes not steep keep e
    const Double4 gx = (every3(z + c.gx_hi) - every3(z + c.gx_lo)) * c.inv_run_x;
    const Double4 gy = (every3(z + c.gy_hi) - every3(z + c.gy_lo)) * c.inv_run_y;
    const Double4 g2 = gx * gx + gy * gy;
    const Mask4 steep = g2 > t.tan_settle() * t.tan_settle();
    if (_mm256_movemask_pd(reinterpret_cast<__m256d>(steep)) != 0) {
      // 1 where not steep (unused there); the square root and divisions round as the scalar ones.
      const auto steepness = reinterpret_cast<Double4>(_mm256_sqrt_pd(reinterpret_cast<__m256d>(steep ? g2 : one)));
      const Double4 ux = -gx / steepness, uy = -gy / steepness;  // downhill unit vector (steep lanes)
      for (int s = 0; s < N; ++s) {
        const Double4 run = c.ox[s] * ux + c.oy[s] * uy;
        const Double4 drop = zi - zj[s], cap = steepness * run;
        const Double4 along = (cap < drop ? cap : drop) - run * t.tan_critical();  // std::min(drop, cap)
        const Mask4 takes = steep & (run > 0.0) & (along > c.margin[s]);
        const Double4 raised = e[s] < along ? along : e[s];  // std::max(e, along)
        e[s] = takes ? raised : e[s];
      }
    }
  }
  for (int s = 0; s < N; ++s) {
    e[s] *= c.weight[s];
    sum += e[s];
    largest = largest < e[s] ? e[s] : largest;
  }
  const Mask4 moving = sum > 0.0;
  const auto moving_bits = static_cast<unsigned>(_mm256_movemask_pd(reinterpret_cast<__m256d>(moving)));
  if (moving_bits == 0) return 0;
  const Double4 scale = t.fraction() * largest / (moving ? sum : one);  // 0 where nothing moves
  Double4 given = {0.0, 0.0, 0.0, 0.0}, error_m3 = {0.0, 0.0, 0.0, 0.0};
  Mask4 transfers = {0, 0, 0, 0};
  for (int s = 0; s < N; ++s) {
    const Double4 v = e[s] * scale;
    const Double4 z_new = zj[s] + v * c.inv_area[s];
    if constexpr (Store::kRounds) {
      // The rounding as put() does it, in one register (written out: GCC 12's SLP vectoriser
      // turns the four scalar round trips double -> float -> double into the identity).
      using Float4 = float __attribute__((vector_size(16)));
      const Float4 stored = __builtin_convertvector(z_new, Float4);
      for (int l = 0; l < 4; ++l) store.put(k + static_cast<std::size_t>(3 * l + c.offset[s]), stored[l]);
      error_m3 += (z_new - __builtin_convertvector(stored, Double4)) * c.area[s];  // 0 where nothing was received
    } else {
      for (int l = 0; l < 4; ++l) store.put(k + static_cast<std::size_t>(3 * l + c.offset[s]), z_new[l]);
    }
    given += v;
    transfers -= e[s] > 0.0;  // lanes are 0 or -1
  }
  if constexpr (Store::kRounds) {
    double& carry = store.carry();
    for (int i = 0; i < 4; ++i) {
      const int l = reverse ? 3 - i : i;
      if (!moving[l]) continue;
      carry = store.put(k + static_cast<std::size_t>(3 * l),
                        zi[l] - given[l] * c.inv_area_i + (carry + error_m3[l]) * c.inv_area_i) *
              c.area_i;
    }
  } else {
    const Double4 z_centre = zi - given * c.inv_area_i;
    for (int l = 0; l < 4; ++l) store.put(k + static_cast<std::size_t>(3 * l), z_centre[l]);
  }
  std::memcpy(given_out, &given, sizeof given);
  transfers_out = static_cast<std::size_t>(transfers[0] + transfers[1] + transfers[2] + transfers[3]);
  return moving_bits;
}

// Which sweep erode_ordered runs (tests force one; Auto is what the terrains use). Dense
// sweeps the members' row spans with the widest lanes the CPU has; DenseAvx2 is Dense with
// AVX2 lanes even where the CPU has AVX-512; DenseBaseline is Dense with its rows classed in
// SSE2 registers and one visit at a time (tests: all give the same heights, bit for bit).
enum class SweepPath { Auto, ActiveSet, Dense, DenseAvx2, DenseBaseline };

// Whether a pass sweeps the members' row spans (dense_pass) rather than the members: a dense
// pass costs about a sixth of an active-set visit per node it skips (instructions,
// callgrind; tests/bench/grid_bench.cpp), so it pays once the members fill about an eighth of
// the spans from the first to the last member of each row.
inline bool dense_pass_pays(std::size_t active, std::size_t span_nodes) { return active * 8 >= span_nodes; }

// The thresholds of the interior class, copied (the flags could alias the class as far as
// the compiler knows).
template <int N>
struct RowThresholds {
  std::ptrdiff_t off[N];
  double crit[N], margin[N];
  double inv_run_x, inv_run_y, tan_settle2;
  RowThresholds(const NodeClass& c, double tan_settle2_) : inv_run_x(c.inv_run_x), inv_run_y(c.inv_run_y) {
    for (int s = 0; s < N; ++s) off[s] = c.offset[s], crit[s] = c.crit[s], margin[s] = c.margin[s];
    tan_settle2 = tan_settle2_;
  }
};

// Whether node x of a row of contiguous heights `z` may transfer, scalar: the first half of
// erosion_visit with the same floating-point expressions, so a node it calls stable is one
// the visit would leave alone.
template <int N, bool Gradient, class Real>
inline bool unstable_at(const Real* z, std::ptrdiff_t w, std::ptrdiff_t x, const RowThresholds<N>& c) {
  const double zi = static_cast<double>(z[x]);
  bool u = false;
  for (int s = 0; s < N; ++s) u |= zi - static_cast<double>(z[x + c.off[s]]) - c.crit[s] > c.margin[s];
  if constexpr (Gradient) {
    const double gx = (static_cast<double>(z[x + 1]) - static_cast<double>(z[x - 1])) * c.inv_run_x;
    const double gy = (static_cast<double>(z[x + w]) - static_cast<double>(z[x - w])) * c.inv_run_y;
    u |= gx * gx + gy * gy > c.tan_settle2;
  }
  return u;
}

// Sets the bit of each node x in [x0, x1] of a row of contiguous heights `z` (node (0, iy);
// rows iy - 1 and iy + 1 at -nx and +nx) that may transfer (unstable_at), two nodes at a
// time. Interior nodes of interior rows only (1 <= x0, x1 <= nx - 2: every neighbour present,
// the thresholds are the interior class's). The bits of [x0, x1] must be clear.
template <int N, bool Gradient, class Real>
void unstable_bits(const Real* z, std::size_t nx, std::size_t x0, std::size_t x1, const RowThresholds<N>& c,
                   std::uint64_t* out) {
  const auto w = static_cast<std::ptrdiff_t>(nx);
  auto x = static_cast<std::ptrdiff_t>(x0);
  const auto end = static_cast<std::ptrdiff_t>(x1) + 1;
  for (; x + 2 <= end; x += 2) {
    const Double2 zi = load2(z + x);
    Mask2 u = {0, 0};
#pragma GCC unroll 8
    for (int s = 0; s < N; ++s) u |= zi - load2(z + x + c.off[s]) - c.crit[s] > c.margin[s];
    if constexpr (Gradient) {
      const Double2 gx = (load2(z + x + 1) - load2(z + x - 1)) * c.inv_run_x;
      const Double2 gy = (load2(z + x + w) - load2(z + x - w)) * c.inv_run_y;
      u |= gx * gx + gy * gy > c.tan_settle2;
    }
    or_bits(out, static_cast<std::size_t>(x),
            static_cast<std::uint64_t>(u[0] & 1) | static_cast<std::uint64_t>(u[1] & 2));
  }
  for (; x < end; ++x)
    if (unstable_at<N, Gradient>(z, w, x, c)) or_bits(out, static_cast<std::size_t>(x), 1);
}

// The same, four nodes at a time in AVX2 registers (the same expressions per lane: AVX2
// brings no FMA, so no contraction; the results are those of unstable_bits bit for bit).
// Only called where the CPU has AVX2 (has_avx2()).
template <int N, bool Gradient, class Real>
[[gnu::target("avx2")]] void unstable_bits_avx2(const Real* z, std::size_t nx, std::size_t x0, std::size_t x1,
                                                const RowThresholds<N>& c, std::uint64_t* out) {
  const auto w = static_cast<std::ptrdiff_t>(nx);
  auto x = static_cast<std::ptrdiff_t>(x0);
  const auto end = static_cast<std::ptrdiff_t>(x1) + 1;
  for (; x + 4 <= end; x += 4) {
    const Double4 zi = load4(z + x);
    Mask4 u = {0, 0, 0, 0};
#pragma GCC unroll 8
    for (int s = 0; s < N; ++s) u |= zi - load4(z + x + c.off[s]) - c.crit[s] > c.margin[s];
    if constexpr (Gradient) {
      const Double4 gx = (load4(z + x + 1) - load4(z + x - 1)) * c.inv_run_x;
      const Double4 gy = (load4(z + x + w) - load4(z + x - w)) * c.inv_run_y;
      u |= gx * gx + gy * gy > c.tan_settle2;
    }
    or_bits(out, static_cast<std::size_t>(x),
            static_cast<std::uint64_t>(_mm256_movemask_pd(reinterpret_cast<__m256d>(u))));
  }
  for (; x < end; ++x)
    if (unstable_at<N, Gradient>(z, w, x, c)) or_bits(out, static_cast<std::size_t>(x), 1);
}

// Whether this CPU runs AVX2 (checked once).
inline bool has_avx2() {
  static const bool yes = __builtin_cpu_supports("avx2");
  return yes;
}

// The dense pass's vector width: rows classed two (SSE2), four (AVX2) or eight (AVX-512)
// nodes at a time, and visits one at a time (SSE2), four (AVX2) or up to eight (AVX-512) at once.
enum class Lanes { Sse2, Avx2, Avx512 };
// The widest the CPU runs, at most what `path` asks for.
inline Lanes lanes_for(SweepPath path) {
  if (path == SweepPath::DenseBaseline) return Lanes::Sse2;
  if (path != SweepPath::DenseAvx2 && has_avx512()) return Lanes::Avx512;
  return has_avx2() ? Lanes::Avx2 : Lanes::Sse2;
}

// The RowWindow a store's dense pass runs its rows on (stores that copy rows), else nothing.
struct NoWindow {
  template <class Store>
  NoWindow(Store&, std::size_t, std::size_t) {}
};
template <class Store>
struct WindowOfStore {
  using type = NoWindow;
};
template <class Store>
requires requires(Store& s) { s.read_row(0, 0, 0, nullptr); }
struct WindowOfStore<Store> {
  using type = RowWindow<Store>;
};
template <class Store>
using WindowOf = typename WindowOfStore<Store>::type;

// A run of rows of a dense pass (dense_rows): from `first` in the pass's y direction, either
// `rows` rows (a band, which stops there) or, with rows = 0, on to the spans' end and past it
// while the row before transferred. live_lo..live_hi: the transfers of the row visited just
// before `first` (empty: lo > hi); moved: the volume moved so far, to add this run's to.
struct DenseRun {
  std::size_t first = 0, rows = 0;
  bool y_up = true, x_up = true;
  std::size_t live_lo = 1, live_hi = 0;
  double moved = 0.0;
};
// What a run did: the nodes that transferred (one row of words per visited row, in visiting
// order), its counts, the columns it visited, and its last row's transfers (for the next run).
struct DenseRunResult {
  std::vector<std::uint64_t> moved_bits;
  std::size_t rows = 0, updates = 0, transfers = 0;
  double moved = 0.0;
  std::size_t col_lo = 0, col_hi = 0;
  std::size_t live_lo = 1, live_hi = 0;
};

// Which nodes of row iy's span x0..x1 a dense pass visits, as bits in MUST: on a contiguous
// store, in an interior row, the interior nodes (skip_lo..skip_hi) classed unstable, or all of
// them where the row is not classed (class_row: the same heights without the classing's cost);
// every other node of the span. (A transfer adds the nodes within two columns later: those
// that read its writes.)
struct RowClassing {
  std::size_t skip_lo = 1, skip_hi = 0;  // nodes classed (empty: none)
  bool classed = false;
};
template <int N, bool Gradient, Lanes lanes, class RowStore>
[[gnu::always_inline]] inline RowClassing flag_span(const RowStore& rs, const ErosionTables& t, const NodeClass& middle,
                                                    std::size_t row_k, std::size_t iy, std::size_t x0, std::size_t x1,
                                                    bool y_up, bool class_row, bool windowed, std::uint64_t* must) {
  const std::size_t nx = t.layout().nx, ny = t.layout().ny;
  RowClassing c;
  if constexpr (requires { rs.data(); }) {
    if (iy > 0 && iy + 1 < ny && nx >= 3) {
      c.skip_lo = std::max<std::size_t>(1, x0);
      c.skip_hi = std::min(nx - 2, x1);
      if (c.skip_lo <= c.skip_hi) {
        const auto* row = rs.data() + row_k;
        // The row after the next one, fetched while this one is classed: its first reads come
        // in the next row's classing, a row of visits from now (a large grid streams its rows
        // from memory; without this the classing waits for them). A hint: no result changes.
        const std::size_t ahead = y_up ? iy + 2 : iy - 2;  // wraps below 0: past the grid
        const auto w = static_cast<std::ptrdiff_t>(nx);
        const auto* fetch = windowed || ahead >= ny ? nullptr : row + (y_up ? 2 * w : -2 * w);
        c.classed = class_row;
        if (!class_row) {  // every node flagged: the same heights, without the classing's cost
          set_bits(must, c.skip_lo, c.skip_hi);
          constexpr std::size_t kLine = 64 / sizeof(*row);  // heights per cache line
          if (fetch != nullptr)
            for (std::size_t x = c.skip_lo; x <= c.skip_hi + kLine - 1; x += kLine)
              __builtin_prefetch(fetch + std::min(x, c.skip_hi));
        } else {
          const RowThresholds<N> th(middle, t.tan_settle() * t.tan_settle());
          if (lanes == Lanes::Avx512)
            unstable_bits_avx512<N, Gradient>(row, nx, c.skip_lo, c.skip_hi, th, must, fetch);
          else if (lanes == Lanes::Avx2)
            unstable_bits_avx2<N, Gradient>(row, nx, c.skip_lo, c.skip_hi, th, must);
          else
            unstable_bits<N, Gradient>(row, nx, c.skip_lo, c.skip_hi, th, must);
        }
      }
    }
  }
  if (c.skip_lo > c.skip_hi) {
    set_bits(must, x0, x1);
  } else {
    if (x0 < c.skip_lo) set_bits(must, x0, c.skip_lo - 1);
    if (x1 > c.skip_hi) set_bits(must, c.skip_hi + 1, x1);
  }
  return c;
}

// A row's span as the phases see it: x0..x1, the interior four_lo..four_hi where groups of
// lanes may run, the row's first node row_k on the store, the direction, and whether groups run.
struct PhaseSpan {
  std::size_t x0, x1, four_lo, four_hi, row_k;
  bool x_up, in_groups;
};

// One phase of a row (the columns x = r (mod 3) of the span, in the sweep's direction): each
// node flagged in MUST visited, on a contiguous store up to eight (AVX-512) or four (AVX2) at
// once in the span's interior. group_transferred(a, bits, given, width, transfers) and
// visit(ix) are dense_rows' bookkeeping; covered and idle count the nodes visited and those
// that moved nothing.
template <int N, bool Gradient, Lanes lanes, class RowStore, class Group, class Visit>
[[gnu::always_inline]] inline void visit_phase(RowStore& rs, const ErosionTables& t, const NodeClass& middle,
                                               const std::uint64_t* must, const PhaseSpan& s, std::size_t r,
                                               std::size_t& covered, std::size_t& idle, Group& group_transferred,
                                               Visit& visit) {
  const std::size_t nx = t.layout().nx;
  const std::size_t x0 = s.x0, x1 = s.x1, four_lo = s.four_lo, four_hi = s.four_hi, row_k = s.row_k;
  const bool x_up = s.x_up, in_groups = s.in_groups;
  std::size_t from = x_up ? x0 : x1;  // the next node of the phase may be here or beyond
  std::size_t ix;
  while (x_up ? next_in_class(must, r, from, x1, ix) : prev_in_class(must, r, x0, from, ix)) {
    const std::size_t lowest = x_up ? ix : ix - std::min<std::size_t>(ix, 9);
    if constexpr (requires { rs.data(); }) {
      // Up to eight nodes of the phase from ix on, in the span's interior (AVX-512).
      const std::size_t room = !in_groups || lanes != Lanes::Avx512 || ix < four_lo || ix > four_hi ? 0
                               : x_up ? (four_hi - ix) / 3 + 1
                                      : (ix - four_lo) / 3 + 1;
      if (room >= 2) {
        const std::size_t count = std::min<std::size_t>(8, room);
        const std::size_t a = x_up ? ix : ix - 3 * (count - 1);
        double given[8];
        std::size_t transfers = 0;
        covered += count;
        if (const unsigned b =
                erosion_visit8<N, Gradient>(rs, t, nx, row_k + a, count, middle, !x_up, given, transfers))
          group_transferred(a, b, given, 8, transfers);
        else
          idle += count;
        const std::size_t last = x_up ? a + 3 * (count - 1) : a;
        if (x_up ? last >= x1 : last <= x0) break;
        from = x_up ? last + 1 : last - 1;
        continue;
      }
      if (in_groups && lanes == Lanes::Avx2 && lowest >= four_lo && lowest + 9 <= four_hi) {
        double given[4];
        std::size_t transfers = 0;
        covered += 4;
        if (const unsigned b = erosion_visit4<N, Gradient>(rs, t, row_k + lowest, middle, !x_up, given, transfers))
          group_transferred(lowest, b, given, 4, transfers);
        else
          idle += 4;
        const std::size_t last = x_up ? lowest + 9 : lowest;
        if (x_up ? last >= x1 : last <= x0) break;
        from = x_up ? last + 1 : last - 1;
        continue;
      }
    }
    visit(ix);
    if (x_up ? ix >= x1 : ix <= x0) break;
    from = x_up ? ix + 1 : ix - 1;
  }
}

// One dense pass, in place (Gauss-Seidel), rows in the direction the active set's next
// sweep would take: in each row, every node from the first to the last member (the row's
// span) is visited once. Like the active-set sweep it is live: a row's span also covers the
// nodes next to those that transferred in the row before (the blocks activate_block would
// have added, so rows beyond the members are reached too), and grows past its end while the
// node at the end transfers. The active set is then updated word by word (assign_blocks):
// the blocks of the nodes that transferred become members with a fresh idle count, other
// members count an idle visit. Same rule, same conservation as the active-set sweep; what
// differs is which nodes are visited: every node of the spans, members or not, once (an
// active-set sweep visits only members, and those activated ahead of it again).
//
// Order within a row: three phases, the columns x = r (mod 3) for each r in turn, each phase
// in the sweep's x direction. Nodes three columns apart have disjoint 3 x 3 blocks, so the
// visits of a phase do not depend on one another: the processor overlaps them, and on a
// contiguous store up to eight of them (k, k + 3, ..., k + 21; erosion_visit8, AVX-512, masked
// lanes where the span's interior ends) or four (erosion_visit4, AVX2) run at once, one per
// lane, bit for bit those erosion_visit calls. It is still one visit after the
// other (Gauss-Seidel, the energy argument above), in a different order from a plain row
// sweep: an avalanche along x moves up to three nodes per pass in a row instead of the whole
// run (along y, rows still follow each other). The order depends only on the active set, so
// every store computes the same heights.
//
// Exactness of the shortcut. On a store with contiguous heights (HeightGrid: data(); the
// sparse grid's RowWindow), a row's interior nodes are first classed by unstable_bits
// (AVX-512: eight at a time; AVX2: four), after the previous row is done; a node is then visited only if it is flagged,
// on a border, or within two columns of a node of its row that transferred before it (a visit writes into its 3 x 3
// block, which a node up to two columns away reads). Its inputs are otherwise those it was
// classed with, so skipping it is exactly what its visit would have done: the pass gives the
// same heights, bit for bit, as visiting every node of the spans (which is what it does on
// stores with neither data() nor read_row). `lanes` = Sse2 classes in SSE2 registers and visits
// one node at a time, Avx2 four at a time (the same heights; tests compare). The classing is
// itself a choice that changes no height: a row is classed only where the row before showed it
// pays (its visits left more than an eighth of its span out, or, not classed, more than an
// eighth of its nodes were visited for nothing); otherwise every node of the row is flagged.
// On states where nearly every group of eight nodes of a phase holds one that moves (grid_bench's
// pile and stroke) most rows go unclassed; where whole stretches of a row stay put (its
// all-active dunes) most rows are still classed.
//
// Cost: O(span nodes) per pass -- the classing vectorised over the row, one visit per
// unstable node -- plus O(words of the visited rows) to find the spans and update the set.
template <int N, bool Gradient, Lanes lanes, class Store, class Active>
inline void dense_rows(Store& store, const Active& active, const typename Active::Spans& spans, const ErosionTables& t,
                       const DenseRun& run, DenseRunResult& out) {
  const std::size_t nx = t.layout().nx, ny = t.layout().ny;
  const bool y_up = run.y_up, x_up = run.x_up;
  const std::size_t words = active.words_per_row();
  // The nodes that transferred, one row of words per visited row in visiting order.
  std::vector<std::uint64_t>& moved_bits = out.moved_bits;
  moved_bits.clear();
  moved_bits.reserve((run.rows > 0 ? run.rows : spans.y1 - spans.y0 + 3) * words);  // and one row each way, as a rule
  // A store without contiguous heights that copies rows (the sparse grid) runs each row on a
  // RowWindow of the three rows it touches (node k = nx + ix of the row), as a contiguous
  // store runs it on its own heights (node k = iy * nx + ix). The window slides from row to
  // row (load) and writes the rows it still holds back after the last one (flush).
  constexpr bool kWindowed = requires { store.read_row(0, 0, 0, nullptr); };
  [[maybe_unused]] WindowOf<Store> window(store, nx, ny);
  auto& rs = [&]() -> auto& {
    if constexpr (kWindowed)
      return window;
    else
      return store;
  }
  ();
  // The row's unstable nodes, one bit each (plus a word: or_bits may write one past the row).
  std::vector<std::uint64_t> flags(words + 1, 0);
  // Whether this row is classed. The classing costs about a third of a group's visit per eight
  // nodes and saves the groups whose nodes are all stable; where the row before left few such
  // nodes out of its visits, the next row is visited whole (every node flagged: the same heights
  // bit for bit, as above). Rows are alike from one to the next on the states this pass is for.
  bool class_row = true;
  std::size_t prev_lo = run.live_lo, prev_hi = run.live_hi;  // span of the previous row's transfers
  std::size_t visited_rows = 0;
  double moved_sum = run.moved;  // in visiting order, in a register
  std::size_t transfer_count = 0, updates = 0;
  std::size_t col_lo = nx, col_hi = 0;  // columns of the visited spans: every member and transfer lies in them
  for (std::size_t iy = run.first; iy < ny; iy = y_up ? iy + 1 : iy - 1) {  // iy - 1 wraps below 0: stops
    std::size_t x0 = nx, x1 = 0;
    const bool members = active.row_span(iy, x0, x1);
    const bool live = prev_lo <= prev_hi;
    const bool inside = y_up ? iy <= spans.y1 : iy >= spans.y0;
    if (run.rows > 0 ? visited_rows == run.rows : !members && !live && !inside) break;
    if (live) {  // the blocks of the previous row's transfers
      x0 = std::min(x0, prev_lo > 0 ? prev_lo - 1 : 0);
      x1 = std::max(x1, std::min(prev_hi + 1, nx - 1));
    }
    moved_bits.resize(moved_bits.size() + words, 0);
    std::uint64_t* moved_row = moved_bits.data() + visited_rows * words;
    ++visited_rows;
    prev_lo = 1, prev_hi = 0;
    if (!members && !live) continue;  // a row inside the members' rows with none
    const NodeClass& middle = t.of(nx / 2, iy);
    std::uint64_t* must = flags.data();
    std::fill(flags.begin() + static_cast<std::ptrdiff_t>(x0 / 64),
              flags.begin() + static_cast<std::ptrdiff_t>(x1 / 64 + 2), std::uint64_t{0});
    // The row's first node on the store it runs on.
    const std::size_t row_k = kWindowed ? nx : iy * nx;
    if constexpr (kWindowed) window.load(iy, x0 > 0 ? x0 - 1 : 0, std::min(x1 + 1, nx - 1));
    const RowClassing rc = flag_span<N, Gradient, lanes>(std::as_const(rs), t, middle, row_k, iy, x0, x1, y_up,
                                                         class_row, kWindowed, must);
    const std::size_t skip_lo = rc.skip_lo, skip_hi = rc.skip_hi;
    const bool classed = rc.classed;
    std::size_t row_lo = nx, row_hi = 0;  // span of this row's transfers (empty)
    std::size_t covered = 0;              // nodes visited, the lanes of groups included
    std::size_t idle = 0;                 // those of them in groups or visits that moved nothing
    const auto transferred = [&](std::size_t ix, const VisitResult& v) __attribute__((always_inline)) {
      transfer_count += static_cast<std::size_t>(v.transfers);
      moved_sum += v.moved;
      moved_row[ix / 64] |= std::uint64_t{1} << (ix % 64);
      row_lo = std::min(row_lo, ix);
      row_hi = std::max(row_hi, ix);
      near_bits(must, ix);
    };
    // The same for the nodes a + 3 l of a group whose lanes l (bits of b) transferred, at once
    // (volumes added in visiting order).
    const auto group_transferred = [&](std::size_t a, unsigned b, const double* given, int width, std::size_t transfers)
        __attribute__((always_inline)) {
      // Every lane, branch-free (a loop over the bits of b mispredicts its exit, which flushes
      // the next group's visit the processor had started): a lane that stayed put gave +0.0,
      // and adding +0.0 to the non-negative sum (never -0.0) leaves it unchanged, bit for bit.
      for (int i = 0; i < width; ++i) moved_sum += given[x_up ? i : width - 1 - i];
      transfer_count += transfers;
      const std::uint64_t at = kEveryThird[b];  // bit 3 l: node a + 3 l
      or_bits32(moved_row, a, at);
      or_bits32(must, a - 2, at | at << 1 | at << 2 | at << 3 | at << 4);  // near_bits of each
      row_lo = std::min(row_lo, a + 3 * static_cast<std::size_t>(std::countr_zero(b)));
      row_hi = std::max(row_hi, a + 3 * static_cast<std::size_t>(31 - std::countl_zero(b)));
    };
    const auto visit = [&](std::size_t ix) __attribute__((flatten)) {  // the store's reads and writes inlined
      const VisitResult v =
          erosion_visit<N, Gradient>(rs, t, row_k + ix, ix < 2 || ix + 2 >= nx ? t.of(ix, iy) : middle);
      ++covered;
      if (v.transfers > 0)
        transferred(ix, v);
      else
        ++idle;
    };
    // Three phases, one per column modulo 3, each in the sweep's direction; on a contiguous
    // store, four nodes of a phase at once where they are interior nodes of the span.
    const bool in_groups = (lanes == Lanes::Avx512 || lanes == Lanes::Avx2) && skip_lo <= skip_hi && nx >= 13;
    const std::size_t four_lo = std::max<std::size_t>(x0, 2), four_hi = std::min(x1, nx - 3);
    const PhaseSpan ps{x0, x1, four_lo, four_hi, row_k, x_up, in_groups};
    for (std::size_t p = 0; p < 3; ++p)
      visit_phase<N, Gradient, lanes>(rs, t, middle, must, ps, x_up ? (x0 + p) % 3 : (x1 + 3 - p) % 3, covered, idle,
                                      group_transferred, visit);
    // Past the span's end while the node at the end transferred (its block reaches one node further).
    // (A window holds columns x0 - 1 .. x1 + 1 from its load: only these visits reach beyond.)
    if (x_up) {
      while (x1 + 1 < nx && bit_at(moved_row, x1)) {
        ++x1;
        if constexpr (kWindowed) window.extend(x1, std::min(x1 + 1, nx - 1));
        visit(x1);
      }
    } else {
      while (x0 > 0 && bit_at(moved_row, x0)) {
        --x0;
        if constexpr (kWindowed) window.extend(x0 > 0 ? x0 - 1 : 0, x0);
        visit(x0);
      }
    }
    updates += x1 - x0 + 1;
    col_lo = std::min(col_lo, x0), col_hi = std::max(col_hi, x1);
    if (row_lo <= row_hi) prev_lo = row_lo, prev_hi = row_hi;
    // Class the next row where the classing pays (see class_row): this one left more than an
    // eighth of its span out of its visits (classed), or more than an eighth of its nodes were
    // visited for nothing (not classed). Tuned on grid_bench's pile, stroke and all-active states.
    const std::size_t span = x1 - x0 + 1;
    class_row = (classed ? span - std::min(covered, span) : idle) * 8 > span;
  }
  if constexpr (kWindowed) window.flush();  // the rows still held, back into the store
  out.rows = visited_rows;
  out.updates = updates;
  out.transfers = transfer_count;
  out.moved = moved_sum;
  out.col_lo = col_lo, out.col_hi = col_hi;
  out.live_lo = prev_lo, out.live_hi = prev_hi;
}

// dense_rows in AVX-512 lanes, compiled for AVX-512 as a whole (flatten): the eight-node
// visits and the classing are inlined into the row loop, not called (measured before / after
// in this file's header). fp-contract=off as in erosion_lanes_avx512.hpp: the scalar visits
// inlined here must not be fused into multiply-adds (AVX-512 has them), so every path still
// computes the same heights bit for bit (tests/unit/grid_dense_pass_test.cpp).
template <int N, bool Gradient, class Store, class Active>
[[gnu::target("avx512f,avx512vl,avx512dq,avx512bw"), gnu::optimize("fp-contract=off"), gnu::flatten]] void
dense_rows_avx512(Store& store, const Active& active, const typename Active::Spans& spans, const ErosionTables& t,
                  const DenseRun& run, DenseRunResult& out) {
  dense_rows<N, Gradient, Lanes::Avx512>(store, active, spans, t, run, out);
}

// One run of rows (dense_rows) in the given lanes.
template <int N, bool Gradient, class Store, class Active>
void dense_rows_in(Lanes lanes, Store& store, const Active& active, const typename Active::Spans& spans,
                   const ErosionTables& t, const DenseRun& run, DenseRunResult& out) {
  if (lanes == Lanes::Avx512)
    dense_rows_avx512<N, Gradient>(store, active, spans, t, run, out);
  else if (lanes == Lanes::Avx2)
    dense_rows<N, Gradient, Lanes::Avx2>(store, active, spans, t, run, out);
  else
    dense_rows<N, Gradient, Lanes::Sse2>(store, active, spans, t, run, out);
}

// Whether a dense pass over these spans is split into two bands and a seam (dense_pass): tall
// and large enough that a second thread pays for its start (~50 us against ~0.3 ms of visits).
// A property of the spans alone, so every store and thread count takes the same order.
template <class Spans>
bool dense_pass_splits(const Spans& spans) {
  return spans.y1 - spans.y0 + 1 >= 32 && spans.nodes >= std::size_t{1} << 16;
}

// Whether a store's bands may run at the same time: heights in one array that is written in
// place (HeightGrid) and no rounding carry (double): the carry chains every write to the one
// before (height_grid.hpp), and a sparse store's accessors and row windows are not shared.
template <class Store>
constexpr bool bands_run_together() {
  constexpr bool contiguous = requires(Store & s) { s.data(); };
  constexpr bool windowed = requires(Store & s) { s.read_row(0, 0, 0, nullptr); };
  return !Store::kRounds && contiguous && !windowed;
}

// Runs first() on this thread and second() on a thread of its own when `together` (and a
// thread can be had), else one after the other; both have run when it returns, and an
// exception from either is thrown on once both have stopped.
template <class First, class Second>
void run_both(bool together, First&& first, Second&& second) {
  std::thread other;
  std::exception_ptr failed;
  if (together) {
    try {
      other = std::thread([&] {
        try {
          second();
        } catch (...) {
          failed = std::current_exception();
        }
      });
    } catch (const std::system_error&) {  // no thread to be had: one after the other
    }
  }
  try {
    first();
  } catch (...) {
    if (other.joinable()) other.join();  // a running thread is joined before the stack unwinds
    throw;
  }
  if (other.joinable())
    other.join();
  else
    second();
  if (failed) std::rethrow_exception(failed);
}

// One dense pass (dense_rows) in the given lanes, then the active set updated word by word
// (assign_blocks). Large passes (dense_pass_splits) go in a fixed order of three runs: the
// first band (the first half of the spans' rows in the sweep's direction, up to two rows
// before the middle), the second band (from two rows after, to the end and on while live),
// then the seam between them (two rows, live from the first band's last row). A row's visits
// touch only it and its two neighbours, so the two bands touch disjoint rows and either order
// of them gives the same heights: on `threads` >= 2 (and a store whose bands run together) the
// second band runs on a thread of its own while the first runs on this one. The order is a
// sequential one, so the conservation and energy arguments above hold as they are, and the
// heights are the same bit for bit with one thread or two, dense or sparse. It differs from a
// pass that is not split only at the seam: the second band starts without the first's live
// rows (its first row's span is its members'), and sand that crosses the seam downstream is
// taken on by the next pass. Cost of the split: the seam's two rows visited after the bands,
// a thread started per pass, and the bits copied once into rows of increasing y.
template <int N, bool Gradient, class Store, class Active>
void dense_pass(Store& store, Active& active, const typename Active::Spans& spans, const ErosionTables& t,
                ErosionReport& report, double& moved, Lanes lanes, unsigned threads = 1) {
  const unsigned pass = active.next_sweep();
  DenseRun run{.first = 0, .rows = 0, .y_up = pass % 2 == 0, .x_up = (pass / 2) % 2 == 0, .moved = moved};
  const bool y_up = run.y_up;
  run.first = y_up ? spans.y0 : spans.y1;
  const auto row_at = [&](std::size_t first, std::size_t i) { return y_up ? first + i : first - i; };
  const auto go = [&](const DenseRun& r, DenseRunResult& out) {
    dense_rows_in<N, Gradient>(lanes, store, std::as_const(active), spans, t, r, out);
  };
  // The runs in the order of their rows (first band, seam, second band), and the one run last.
  DenseRunResult parts[3];
  std::size_t count = 1, last_run = 0;
  if (!dense_pass_splits(spans)) {
    go(run, parts[0]);
  } else {
    count = 3, last_run = 1;
    const std::size_t band_rows = (spans.y1 - spans.y0 + 1 - 2) / 2;
    DenseRun first_band = run, second_band = run, seam = run;
    first_band.rows = band_rows;
    second_band.first = row_at(run.first, band_rows + 2);
    second_band.moved = 0.0;
    run_both(
        bands_run_together<Store>() && threads >= 2, [&] { go(first_band, parts[0]); },
        [&] { go(second_band, parts[2]); });
    seam.first = row_at(run.first, band_rows);
    seam.rows = 2;
    seam.live_lo = parts[0].live_lo, seam.live_hi = parts[0].live_hi;
    seam.moved = parts[0].moved + parts[2].moved;
    go(seam, parts[1]);
  }
  // The rows the runs visited, in increasing y for the set (they adjoin, in visiting order).
  const std::size_t words = active.words_per_row();
  std::size_t rows = 0, col_lo = t.layout().nx, col_hi = 0;
  for (std::size_t r = 0; r < count; ++r) {
    rows += parts[r].rows;
    report.updates += parts[r].updates;
    report.transfers += parts[r].transfers;
    col_lo = std::min(col_lo, parts[r].col_lo), col_hi = std::max(col_hi, parts[r].col_hi);
  }
  moved = parts[last_run].moved;
  const std::size_t last = row_at(run.first, rows - 1), y_min = std::min(run.first, last);
  std::vector<std::uint64_t> bits;
  if (count == 1) {  // one run: its rows, reversed in place when the pass went down
    bits = std::move(parts[0].moved_bits);
    if (!y_up)
      for (std::size_t a = 0, b = rows - 1; a < b; ++a, --b)
        std::swap_ranges(bits.begin() + static_cast<std::ptrdiff_t>(a * words),
                         bits.begin() + static_cast<std::ptrdiff_t>((a + 1) * words),
                         bits.begin() + static_cast<std::ptrdiff_t>(b * words));
  } else {
    bits.resize(rows * words);
    for (std::size_t r = 0, i = 0; r < count; ++r)
      for (std::size_t row = 0; row < parts[r].rows; ++row, ++i)
        std::copy_n(parts[r].moved_bits.begin() + static_cast<std::ptrdiff_t>(row * words), words,
                    bits.begin() + static_cast<std::ptrdiff_t>((row_at(run.first, i) - y_min) * words));
  }
  active.assign_blocks(bits, std::min(run.first, last), std::max(run.first, last), col_lo, col_hi);
}

// Passes until `active` is empty or the budget is spent: ordered, live sweeps of the active
// set (see active_set.hpp for the order), or a dense pass over the members' row spans
// (dense_pass) when the members fill enough of them and the budget allows twice the spans.
// Cost: O(visits) plus the set's O(rows + words with members) per pass, O(span nodes) per
// dense pass.
template <int N, bool Gradient, class Store, class Active>
ErosionReport erode_ordered(Store& store, Active& active, const ErosionTables& t, const ErosionBudget& budget,
                            SweepPath path = SweepPath::Auto, unsigned threads = 1) {
  ErosionReport report;
  const std::size_t nx = t.layout().nx;
  double moved = 0.0;
  while (report.passes < budget.max_passes && !active.empty() && report.updates < budget.max_updates) {
    ++report.passes;
    if (path != SweepPath::ActiveSet) {
      const typename Active::Spans spans = active.spans();
      const bool forced = path == SweepPath::Dense || path == SweepPath::DenseAvx2 || path == SweepPath::DenseBaseline;
      const bool dense = forced || (dense_pass_pays(active.size(), spans.nodes) &&
                                    budget.max_updates - report.updates >= 2 * spans.nodes);
      if (dense) {
        dense_pass<N, Gradient>(store, active, spans, t, report, moved, lanes_for(path), threads);
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
                            SweepPath path = SweepPath::Auto, unsigned threads = 1) {
  if (t.neighbours() == 4)
    return t.gradient() ? erode_ordered<4, true>(store, active, t, budget, path, threads)
                        : erode_ordered<4, false>(store, active, t, budget, path, threads);
  return t.gradient() ? erode_ordered<8, true>(store, active, t, budget, path, threads)
                      : erode_ordered<8, false>(store, active, t, budget, path, threads);
}

}  // namespace sb::grid
