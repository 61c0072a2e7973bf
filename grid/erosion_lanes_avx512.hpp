#pragma once
// The dense pass's AVX-512 paths (grid/erosion_kernel.hpp): a row classed eight nodes per
// compare, and eight nodes of one phase (three columns apart) visited at once, one per lane,
// with the edge or the gradient rule (as the AVX2 lanes do four at a time).
// Compiled for AVX-512 by target attributes and called only where the CPU has it
// (has_avx512()); the kernel falls back to its AVX2 and SSE2 paths elsewhere, with the same
// results bit for bit (tests/unit/grid_dense_pass_test.cpp compares them).
//
// Bit for bit: every lane evaluates the scalar visit's expressions (erosion_visit), slot by
// slot, in the same order, and nothing is contracted into fused multiply-adds: AVX-512 has
// them, and GCC contracts by default in C++ (-ffp-contract=fast, even with -std=c++20), so
// this file's functions are compiled with fp-contract=off (the pragma below). The
// conversions double <-> float round to nearest as the scalar casts do.
//
// Memory. A group of L <= 8 nodes a, a + 3, ..., a + 3 (L - 1) of an interior row reads and
// writes their 3 x 3 blocks, which tile the columns a - 1 .. a + 3 L - 2 of three rows: nine
// (masked) vector loads, split into the nine neighbour positions by two permutes each, and
// after the visit nine permuted (masked) vector stores (nodes that receive nothing get their
// own heights back, unchanged). Nodes beyond the group (L < 8) are masked: they read nothing,
// write nothing and never transfer, so groups at the ends of a row's span need no scalar
// visits. Cost of a group (8 neighbours): 9 loads and 18 permutes, ~10 vector operations per
// neighbour, and where a lane transfers 18 permutes and 9 stores; groups with no transfer
// write nothing: ~190 vector instructions, of which 36 permutes, and a dependency chain of an
// estimated ~80 cycles (loads, permutes, the sum over the slots in their order, the division,
// the stores) that the processor overlaps with the next group's only in part. The classing
// also fetches the row after next into the cache (one prefetch per eight nodes; a hint, no
// result changes): on 2048^2 nodes its loads of the next row waited on memory for ~45 % of its
// time before. The dense pass runs these functions inlined into its row loop
// (dense_pass_avx512, erosion_kernel.hpp).
//
// Tried and not kept (ratios of medians of 5 to 9 interleaved runs to the code kept, double,
// pile / stroke / every node of 2048^2 active; the machine was shared, so +-5 % is noise):
// visiting two groups in one block of code, ~15 % slower (an earlier session); keeping a chunk
// of 22 nodes in registers across its three phases (a chunk-by-chunk order: 36 permutes per
// chunk instead of per group, no reload between phases, the chunk's last two columns handed to
// the next in registers) 0.94 / 0.92 / 0.67 -- each chunk waits for the one before, so a row
// becomes one chain of dependent phases, where phase by phase the groups of a phase are
// independent and overlap; splitting a row's three rows by column modulo 3 once per row (the
// same order, the groups' blocks then loaded with no permutes: 12 permutes per 24 columns
// instead of 36 per group) 0.93 / 0.93 / 0.85; 16 of ~190 vector operations fewer per group
// (the excess weighted in one masked multiply, the transfers counted from the comparison masks)
// 0.99 / 0.99 / 1.00; plain rather than masked loads and stores for whole groups 0.96 / 0.88 /
// 0.88; deferring a phase's near-node flags to its end (the scan for the next group then does
// not wait on the group before through memory) 0.99 / 1.02 / 0.99; the classing's flags of 64
// nodes gathered in a register 0.96 / 0.97 / 0.99; BMI2 shifts in the pass 1.01 / 1.03 / 1.01
// (noise); the sums over the slots as balanced trees (a shorter chain, other roundings)
// 1.02 / 1.00 / 1.00. So neither the permutes, the arithmetic nor the chain's length bound a
// group here. A diagnostic (wrong heights, not kept): the groups without their nine stores ran
// 1.01 / 1.23 / 1.13, so on long rows about a sixth of the time goes with the stores or what
// they hold up, and on the pile's short rows with the pass's bookkeeping. Not 4 KiB aliasing
// between rows (grid_bench's widths are powers of two): 510 and 2046 nodes wide instead of 512
// and 2048 ran 0.99 / 0.99 / 1.02. This virtual machine has no hardware counters; the next step
// is where those stores stall.
// Valgrind runs no AVX-512, so there are no callgrind counts for these paths: measure their
// throughput with tests/bench/grid_bench.cpp (erosion_kernel.hpp's header says what it runs).
#include <immintrin.h>

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "grid/row_bits.hpp"

// No fused multiply-adds in this file's functions (see above).
#pragma GCC push_options
#pragma GCC optimize("fp-contract=off")

namespace sb::grid {

using Double8 = double __attribute__((vector_size(64)));
using Float8 = float __attribute__((vector_size(32)));
using Mask8 = std::int64_t __attribute__((vector_size(64)));

// Whether this CPU (and its operating system) runs the AVX-512 subsets used here (checked once).
inline bool has_avx512() {
  static const bool yes = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
                          __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512bw");
  return yes;
}

// Heights p[0..7] widened to double; lanes outside `m` read nothing (0).
template <class Real>
[[gnu::target("avx512f,avx512vl,avx512dq,avx512bw"), gnu::always_inline]] inline Double8 load8(const Real* p,
                                                                                               __mmask8 m) {
  if constexpr (std::is_same_v<Real, double>)
    return reinterpret_cast<Double8>(_mm512_maskz_loadu_pd(m, p));
  else
    return __builtin_convertvector(reinterpret_cast<Float8>(_mm256_maskz_loadu_ps(m, p)), Double8);
}
// Stores the lanes of `v` in `m` at p[0..7] (rounded to Real).
template <class Real>
[[gnu::target("avx512f,avx512vl,avx512dq,avx512bw"), gnu::always_inline]] inline void store8(Real* p, __mmask8 m,
                                                                                             Double8 v) {
  if constexpr (std::is_same_v<Real, double>)
    _mm512_mask_storeu_pd(p, m, reinterpret_cast<__m512d>(v));
  else
    _mm256_mask_storeu_ps(p, m, reinterpret_cast<__m256>(__builtin_convertvector(v, Float8)));
}
[[gnu::target("avx512f,avx512vl,avx512dq,avx512bw"), gnu::always_inline]] inline __mmask8 greater(Double8 a,
                                                                                                  Double8 b) {
  return _mm512_cmp_pd_mask(reinterpret_cast<__m512d>(a), reinterpret_cast<__m512d>(b), _CMP_GT_OQ);
}
[[gnu::target("avx512f,avx512vl,avx512dq,avx512bw"), gnu::always_inline]] inline Double8 min8(Double8 a, Double8 b) {
  return a < b ? a : b;
}
[[gnu::target("avx512f,avx512vl,avx512dq,avx512bw"), gnu::always_inline]] inline Double8 splat8(double x) {
  return Double8{x, x, x, x, x, x, x, x};
}

// Sets the bit of each node x in [x0, x1] of a row of contiguous heights `z` that may
// transfer: unstable_bits (erosion_kernel.hpp) eight nodes per compare, the row's last
// (x1 - x0 + 1) % 8 nodes in masked lanes. Same preconditions (interior nodes of an interior
// row, bits of [x0, x1] clear; `out` holds the word after x1's); `c`: RowThresholds<N>.
// Neighbours with the same thresholds (+-x; +-y; the diagonals) are tested at once on their
// lowest height: (z_i - z_j) - crit is a non-increasing function of z_j in floating point too
// (every rounding is monotone), so it exceeds the margin for some j exactly when it does for
// the lowest -- the same bits as slot by slot, with 5 minima and 3 tests instead of 8 tests.
template <int N, bool Gradient, class Real, class Thresholds>
[[gnu::target("avx512f,avx512vl,avx512dq,avx512bw")]] void unstable_bits_avx512(const Real* z, std::size_t nx,
                                                                                std::size_t x0, std::size_t x1,
                                                                                const Thresholds& c, std::uint64_t* out,
                                                                                const Real* fetch = nullptr) {
  const auto w = static_cast<std::ptrdiff_t>(nx);
  bool grouped = true;  // +-x, +-y and the diagonals each share their thresholds
  for (const int s : {1, 3, 5, 6, 7})
    if (s < N) grouped &= c.crit[s] == c.crit[s < 4 ? s - 1 : 4] && c.margin[s] == c.margin[s < 4 ? s - 1 : 4];
  // In registers (`out` could alias `c` as far as the compiler knows).
  std::ptrdiff_t off[N];
  double crit[N], margin[N];
  for (int s = 0; s < N; ++s) off[s] = c.off[s], crit[s] = c.crit[s], margin[s] = c.margin[s];
  const double inv_run_x = c.inv_run_x, inv_run_y = c.inv_run_y, tan_settle2 = c.tan_settle2;
  // The bits of nodes x..x + 7 in `m` (lanes outside it read nothing).
  const auto classify = [&](std::size_t x, __mmask8 m)
      __attribute__((always_inline, target("avx512f,avx512vl,avx512dq,avx512bw"))) {
    const Real* p = z + x;
    if (fetch != nullptr) __builtin_prefetch(fetch + x);  // a hint for a later row
    const Double8 zi = load8(p, m);
    __mmask8 u = 0;
    if (grouped) {
      Double8 zj[N];
#pragma GCC unroll 8
      for (int s = 0; s < N; ++s) zj[s] = load8(p + off[s], m);
      const Double8 x_low = min8(zj[0], zj[1]), y_low = min8(zj[2], zj[3]);
      u = greater(zi - x_low - crit[0], splat8(margin[0])) | greater(zi - y_low - crit[2], splat8(margin[2]));
      if constexpr (N == 8) {
        const Double8 d_low = min8(min8(zj[4], zj[5]), min8(zj[6], zj[7]));
        u |= greater(zi - d_low - crit[4], splat8(margin[4]));
      }
    } else {
#pragma GCC unroll 8
      for (int s = 0; s < N; ++s) u |= greater(zi - load8(p + off[s], m) - crit[s], splat8(margin[s]));
    }
    if constexpr (Gradient) {
      const Double8 gx = (load8(p + 1, m) - load8(p - 1, m)) * inv_run_x;
      const Double8 gy = (load8(p + w, m) - load8(p - w, m)) * inv_run_y;
      u |= greater(gx * gx + gy * gy, splat8(tan_settle2));
    }
    or_bits(out, x, static_cast<std::uint64_t>(u & m));
  };
  std::size_t x = x0;
  for (; x + 7 <= x1; x += 8) classify(x, 0xFF);  // whole vectors (the mask folds away)
  if (x <= x1) classify(x, static_cast<__mmask8>((1u << (x1 + 1 - x)) - 1));
}

// Neighbour positions of the stencil slots (Stencil's order: +x, -x, +y, -y, (+1,+1),
// (-1,+1), (+1,-1), (-1,-1)) in a group's window: row dy + 1, column dx + 1.
inline constexpr int kSlotRow[8] = {1, 1, 2, 0, 2, 2, 0, 0};
inline constexpr int kSlotColumn[8] = {2, 0, 1, 1, 2, 0, 2, 0};

// One row of a group's window, columns a - 1 + j (j = 0..23) in three registers, split into
// the columns dx = d - 1 of the eight lanes (j = d + 3 l), and merged back.
[[gnu::target("avx512f,avx512vl,avx512dq,avx512bw"), gnu::always_inline]] inline void split3(const Double8 w[3],
                                                                                             Double8 col[3]) {
  constexpr Mask8 kFirst[3] = {{0, 3, 6, 9, 12, 15, 0, 0}, {1, 4, 7, 10, 13, 0, 0, 0}, {2, 5, 8, 11, 14, 0, 0, 0}};
  constexpr Mask8 kSecond[3] = {{0, 1, 2, 3, 4, 5, 10, 13}, {0, 1, 2, 3, 4, 8, 11, 14}, {0, 1, 2, 3, 4, 9, 12, 15}};
  for (int d = 0; d < 3; ++d) col[d] = __builtin_shuffle(__builtin_shuffle(w[0], w[1], kFirst[d]), w[2], kSecond[d]);
}
[[gnu::target("avx512f,avx512vl,avx512dq,avx512bw"), gnu::always_inline]] inline void merge3(const Double8 col[3],
                                                                                             Double8 w[3]) {
  constexpr Mask8 kFirst[3] = {{0, 8, 0, 1, 9, 0, 2, 10}, {0, 3, 11, 0, 4, 12, 0, 5}, {13, 0, 6, 14, 0, 7, 15, 0}};
  constexpr Mask8 kSecond[3] = {{0, 1, 8, 3, 4, 9, 6, 7}, {10, 1, 2, 11, 4, 5, 12, 7}, {0, 13, 2, 3, 14, 5, 6, 15}};
  for (int r = 0; r < 3; ++r)
    w[r] = __builtin_shuffle(__builtin_shuffle(col[0], col[1], kFirst[r]), col[2], kSecond[r]);
}

// Visits the `lanes` (1..8) nodes k, k + 3, ..., k + 3 (lanes - 1) of an interior row of a
// contiguous store (store.data() writable), interior nodes of class c (a NodeClass), at
// once: the same as their erosion_visit calls one after the other, bit for bit (their blocks
// are disjoint). The rounding carry (float) is settled lane by lane in visiting order
// (`reverse`: the last lane first). Returns the lanes that transferred (bit l: node k + 3 l);
// then given[l] is the volume lane l gave (m^3; +0.0 for lanes that stayed put or are masked:
// the dense pass adds every lane) and `transfers` the receiving neighbours of
// all lanes (both unset when it returns 0). Gradient: the gradient rule (central differences,
// the interior class's), as erosion_visit<N, true>; `t`: the ErosionTables.
template <int N, bool Gradient, class Store, class Class, class Tables>
[[gnu::target("avx512f,avx512vl,avx512dq,avx512bw")]] unsigned erosion_visit8(Store& store, const Tables& t,
                                                                              std::size_t nx, std::size_t k,
                                                                              std::size_t lanes, const Class& c,
                                                                              bool reverse, double given_out[8],
                                                                              std::size_t& transfers_out) {
  auto* base = store.data() + k - 1;
  const auto w = static_cast<std::ptrdiff_t>(nx);
  const std::uint32_t window = (std::uint32_t{1} << (3 * lanes)) - 1;  // columns a - 1 .. a + 3 lanes - 2
  const __mmask8 m[3] = {static_cast<__mmask8>(window), static_cast<__mmask8>(window >> 8),
                         static_cast<__mmask8>(window >> 16)};
  Double8 col[3][3];  // [dy + 1][dx + 1]
  for (int r = 0; r < 3; ++r) {
    const auto* row = base + (r - 1) * w;
    const Double8 raw[3] = {load8(row, m[0]), load8(row + 8, m[1]), load8(row + 16, m[2])};
    split3(raw, col[r]);
  }
  const auto live = static_cast<__mmask8>((1u << lanes) - 1);
  const Double8 zi = col[1][1];
  Double8 zj[N], e[N];
  Double8 sum = splat8(0.0), largest = splat8(0.0);
  for (int s = 0; s < N; ++s) {
    zj[s] = col[kSlotRow[s]][kSlotColumn[s]];
    const Double8 excess = zi - zj[s] - c.crit[s];
    const __mmask8 over = greater(excess, splat8(c.margin[s])) & live;
    e[s] = reinterpret_cast<Double8>(_mm512_maskz_mov_pd(over, reinterpret_cast<__m512d>(excess)));  // else +0
  }
  if constexpr (Gradient) {  // erosion_visit's expressions, lane by lane; lanes not steep keep e
    const Double8 gx = (col[1][2] - col[1][0]) * c.inv_run_x;
    const Double8 gy = (col[2][1] - col[0][1]) * c.inv_run_y;
    const Double8 g2 = gx * gx + gy * gy;
    const __mmask8 steep = greater(g2, splat8(t.tan_settle() * t.tan_settle())) & live;
    if (steep != 0) {
      const Double8 steepness = reinterpret_cast<Double8>(  // 1 where not steep (unused)
          _mm512_mask_sqrt_pd(reinterpret_cast<__m512d>(splat8(1.0)), steep, reinterpret_cast<__m512d>(g2)));
      const Double8 ux = -gx / steepness, uy = -gy / steepness;  // downhill unit vector (steep lanes)
      for (int s = 0; s < N; ++s) {
        const Double8 run = c.ox[s] * ux + c.oy[s] * uy;
        const Double8 drop = zi - zj[s], cap = steepness * run;
        const Double8 along = (cap < drop ? cap : drop) - run * t.tan_critical();  // std::min(drop, cap)
        const __mmask8 takes = steep & greater(run, splat8(0.0)) & greater(along, splat8(c.margin[s]));
        const Double8 raised = e[s] < along ? along : e[s];  // std::max(e, along)
        e[s] = reinterpret_cast<Double8>(
            _mm512_mask_mov_pd(reinterpret_cast<__m512d>(e[s]), takes, reinterpret_cast<__m512d>(raised)));
      }
    }
  }
  for (int s = 0; s < N; ++s) {
    e[s] *= c.weight[s];
    sum += e[s];
    largest = largest < e[s] ? e[s] : largest;
  }
  const __mmask8 moving = greater(sum, splat8(0.0));
  const auto moving_bits = static_cast<unsigned>(moving);
  if (moving_bits == 0) return 0;
  const Double8 scale =
      reinterpret_cast<Double8>(_mm512_maskz_div_pd(moving, reinterpret_cast<__m512d>(t.fraction() * largest),
                                                    reinterpret_cast<__m512d>(sum)));  // 0 where nothing moves
  Double8 given = splat8(0.0), error_m3 = splat8(0.0);
  int transfers = 0;
  for (int s = 0; s < N; ++s) {
    const Double8 v = e[s] * scale;
    const Double8 z_new = zj[s] + v * c.inv_area[s];
    if constexpr (Store::kRounds) {
      const Double8 stored = __builtin_convertvector(__builtin_convertvector(z_new, Float8), Double8);
      error_m3 += (z_new - stored) * c.area[s];  // 0 where nothing was received
      col[kSlotRow[s]][kSlotColumn[s]] = stored;
    } else {
      col[kSlotRow[s]][kSlotColumn[s]] = z_new;
    }
    given += v;
    transfers += std::popcount(static_cast<unsigned>(greater(e[s], splat8(0.0))));
  }
  if constexpr (Store::kRounds) {
    double& carry = store.carry();
    using Real = std::remove_cvref_t<decltype(*base)>;
    for (unsigned b = moving_bits; b != 0;) {
      const int l = reverse ? 31 - std::countl_zero(b) : std::countr_zero(b);
      b &= ~(1u << l);
      const double target = zi[l] - given[l] * c.inv_area_i + (carry + error_m3[l]) * c.inv_area_i;
      const auto stored = static_cast<Real>(target);
      carry = (target - static_cast<double>(stored)) * c.area_i;
      col[1][1][l] = static_cast<double>(stored);
    }
  } else {
    col[1][1] = zi - given * c.inv_area_i;
  }
  for (int r = 0; r < 3; ++r) {
    Double8 merged[3];
    merge3(col[r], merged);
    auto* row = base + (r - 1) * w;
    store8(row, m[0], merged[0]);
    store8(row + 8, m[1], merged[1]);
    store8(row + 16, m[2], merged[2]);
  }
  _mm512_storeu_pd(given_out, reinterpret_cast<__m512d>(given));
  transfers_out = static_cast<std::size_t>(transfers);
  return moving_bits;
}

}  // namespace sb::grid

#pragma GCC pop_options
