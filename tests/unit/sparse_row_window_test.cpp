// RowWindow (grid/row_window.hpp), the sliding three-row window the sparse grid's dense
// erosion pass runs on:
//   - on a model store, against the same writes made on a plain array: every read through the
//     window sees the current height, the store ends with the array's heights, only changed
//     heights are written, and over a run of adjacent rows each node is read and written back
//     at most once (the window slides instead of reloading its three rows); rows up, down,
//     with gaps, back and forth, spans that move and grow, many wraps of the buffer;
//   - in the erosion kernel, SparseHeights on the window against HeightGrid on its own heights:
//     the same heights bit for bit, the same reports, for members laid out so that the visited
//     rows go up and down, leave gaps between spans, move sideways and grow mid-row, on grids
//     whose width is not a multiple of 8, 1-row and 2-row grids and a grid taller than the
//     window's buffer, in every lane width.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include "grid/active_set.hpp"
#include "grid/erosion_kernel.hpp"
#include "grid/height_grid.hpp"
#include "grid/row_window.hpp"
#include "grid/sparse_heights.hpp"
#include "grid_rough_states.hpp"

namespace sb::grid {
namespace {

// A store of the window's Store concept over a plain array, counting reads and writes per node.
struct ModelStore {
  using value_type = double;
  static constexpr bool kRounds = false;
  std::size_t nx, ny;
  std::vector<double> z;
  std::vector<int> reads, writes;
  double carry_m3 = 0.0;

  ModelStore(std::size_t nx_, std::size_t ny_) : nx(nx_), ny(ny_), z(nx * ny), reads(nx * ny), writes(nx * ny) {
    for (std::size_t k = 0; k < z.size(); ++k) z[k] = 0.25 * static_cast<double>(k % 97);
  }
  void read_row(std::size_t iy, std::size_t x0, std::size_t x1, double* out) {
    EXPECT_LT(iy, ny);
    EXPECT_LE(x0, x1);
    EXPECT_LT(x1, nx);
    for (std::size_t x = x0; x <= x1; ++x) out[x - x0] = z[iy * nx + x], ++reads[iy * nx + x];
  }
  void write_changed(std::size_t iy, std::size_t x0, std::size_t x1, const double* values, const double* before) {
    EXPECT_LT(iy, ny);
    EXPECT_LT(x1, nx);
    for (std::size_t x = x0; x <= x1; ++x) {
      // what the window compares with is what the store holds: only changed heights are written
      EXPECT_EQ(std::bit_cast<std::uint64_t>(before[x - x0]), std::bit_cast<std::uint64_t>(z[iy * nx + x]));
      if (std::bit_cast<std::uint64_t>(values[x - x0]) != std::bit_cast<std::uint64_t>(before[x - x0]))
        z[iy * nx + x] = values[x - x0], ++writes[iy * nx + x];
    }
  }
  double& carry() { return carry_m3; }
};

struct Row {
  std::size_t iy, x0, x1;
  std::size_t grow = 0;  // columns the span grows by at its end, one extend() at a time
};

// Runs rows on a window over a model store and the same writes on a plain array (what the
// store would hold without the window). Each row: the window's reads of its 3 x (span + 2)
// block checked, then writes of new heights to nodes of the block, pseudo-random, some of them
// writing the height a node already had (not written back) or changing a node and changing it
// back.
void run_rows(std::size_t nx, std::size_t ny, const std::vector<Row>& rows, const std::string& what) {
  SCOPED_TRACE(what);
  ModelStore store(nx, ny);
  std::vector<double> expected = store.z;
  RowWindow<ModelStore> window(store, nx, ny);
  std::uint64_t h = 0x1234567;
  const auto next = [&h] { return h = h * 6364136223846793005ull + 1442695040888963407ull, h >> 33; };
  for (const Row& row : rows) {
    window.load(row.iy, row.x0 > 0 ? row.x0 - 1 : 0, std::min(row.x1 + 1, nx - 1));
    std::size_t x1 = row.x1;
    for (std::size_t g = 0; g <= row.grow; ++g) {
      if (g > 0) {
        ++x1;
        window.extend(x1 - 1, std::min(x1 + 1, nx - 1));
      }
      const std::size_t lo = row.x0 > 0 ? row.x0 - 1 : 0, hi = std::min(x1 + 1, nx - 1);
      for (std::size_t r = 0; r < 3; ++r) {
        if (row.iy + r < 1 || row.iy + r - 1 >= ny) continue;
        const std::size_t y = row.iy + r - 1;
        for (std::size_t x = lo; x <= hi; ++x) {
          const std::size_t k = r * nx + x;
          ASSERT_EQ(std::bit_cast<std::uint64_t>(window.z(k)), std::bit_cast<std::uint64_t>(expected[y * nx + x]))
              << "row " << row.iy << " window row " << r << " column " << x;
          EXPECT_EQ(window.data()[k], expected[y * nx + x]);
          const std::uint64_t u = next() % 8;
          if (u >= 3) continue;
          // 0: a new height; 1: the height it has; 2: a change that a later write takes back
          const double target = u == 1 ? expected[y * nx + x] : expected[y * nx + x] + 0.5 + static_cast<double>(u);
          EXPECT_EQ(window.put(k, target), 0.0);
          if (u == 2)
            window.put(k, expected[y * nx + x]);
          else
            expected[y * nx + x] = target;
        }
      }
    }
  }
  window.flush();
  window.flush();  // a second flush writes nothing
  const ModelStore untouched(nx, ny);
  for (std::size_t k = 0; k < expected.size(); ++k) {
    ASSERT_EQ(std::bit_cast<std::uint64_t>(store.z[k]), std::bit_cast<std::uint64_t>(expected[k])) << "node " << k;
    if (store.z[k] == untouched.z[k]) {
      EXPECT_EQ(store.writes[k], 0) << "node " << k;  // changed heights only
    }
  }
}

// Counts of reads and writes per node after running `rows` with every node of each visited
// block written once (a new height), or none written.
std::pair<int, int> most_reads_and_writes(std::size_t nx, std::size_t ny, const std::vector<Row>& rows) {
  ModelStore store(nx, ny);
  RowWindow<ModelStore> window(store, nx, ny);
  for (const Row& row : rows) {
    window.load(row.iy, row.x0, row.x1);
    for (std::size_t r = 0; r < 3; ++r)
      if (row.iy + r >= 1 && row.iy + r - 1 < ny)
        for (std::size_t x = row.x0; x <= row.x1; ++x) window.put(r * nx + x, window.z(r * nx + x) + 1.0);
  }
  window.flush();
  return {*std::max_element(store.reads.begin(), store.reads.end()),
          *std::max_element(store.writes.begin(), store.writes.end())};
}

std::vector<Row> rows_up(std::size_t y0, std::size_t y1, std::size_t x0, std::size_t x1) {
  std::vector<Row> rows;
  for (std::size_t y = y0; y <= y1; ++y) rows.push_back({y, x0, x1});
  return rows;
}
std::vector<Row> rows_down(std::size_t y1, std::size_t y0, std::size_t x0, std::size_t x1) {
  std::vector<Row> rows;
  for (std::size_t y = y1 + 1; y-- > y0;) rows.push_back({y, x0, x1});
  return rows;
}

TEST(RowWindow, ReadsSeeTheCurrentHeightsAndTheStoreEndsWithEveryWrite) {
  const std::size_t nx = 21, ny = 40;  // taller than the buffer: the window wraps
  run_rows(nx, ny, rows_up(0, ny - 1, 0, nx - 1), "up, whole rows");
  run_rows(nx, ny, rows_down(ny - 1, 0, 0, nx - 1), "down, whole rows");
  run_rows(nx, ny, rows_up(3, 37, 5, 9), "up, inside");
  run_rows(nx, ny, rows_down(36, 2, 5, 9), "down, inside");
  std::vector<Row> moving;  // spans moving sideways and growing mid-row, each way
  for (std::size_t y = 1; y < 35; ++y) moving.push_back({y, y % 11, y % 11 + 3 + y % 4, y % 3});
  run_rows(nx, ny, moving, "up, spans moving and growing");
  std::reverse(moving.begin(), moving.end());
  run_rows(nx, ny, moving, "down, spans moving and growing");
  run_rows(nx, ny, {{4, 2, 6}, {5, 2, 6}, {7, 10, 12}, {8, 0, 20}, {20, 3, 3}, {19, 1, 4}, {18, 15, 19}, {0, 0, 1}},
           "gaps between runs, both ways");
  run_rows(nx, ny, {{6, 2, 6}, {7, 3, 9}, {6, 0, 4}, {5, 8, 12}, {6, 1, 2}, {7, 0, 20}}, "back and forth");
  run_rows(nx, ny, {{0, 0, 20}, {1, 0, 20}, {39, 0, 20}, {38, 0, 20}, {39, 0, 20}}, "the grid's first and last rows");
  run_rows(13, 1, {{0, 0, 12, 0}, {0, 2, 5, 3}}, "a 1-row grid");
  run_rows(13, 2, {{0, 0, 12}, {1, 2, 5, 2}, {0, 3, 4}, {1, 0, 12}}, "a 2-row grid");
  run_rows(1, 5, rows_up(0, 4, 0, 0), "a 1-column grid");
}

TEST(RowWindow, EachNodeIsReadAndWrittenBackOncePerRunOfAdjacentRows) {
  const std::size_t nx = 19, ny = 50;
  for (const auto& rows : {rows_up(0, ny - 1, 0, nx - 1), rows_down(ny - 1, 0, 0, nx - 1), rows_up(7, 44, 3, 11)}) {
    const auto [reads, writes] = most_reads_and_writes(nx, ny, rows);
    EXPECT_EQ(reads, 1);  // a window that reloaded its three rows per row would read them three times
    EXPECT_EQ(writes, 1);
  }
  // A gap: the rows on either side of it are read and written by both runs.
  std::vector<Row> gap = rows_up(0, 10, 0, nx - 1), after = rows_up(12, 20, 0, nx - 1);
  gap.insert(gap.end(), after.begin(), after.end());
  const auto [reads, writes] = most_reads_and_writes(nx, ny, gap);
  EXPECT_EQ(reads, 2);
  EXPECT_EQ(writes, 2);
}

// The kernel: SparseHeights on the window against HeightGrid, the same members, rule, stencil.
struct KernelCase {
  std::size_t nx, ny;
  const char* members;  // see members_of
};

// Members: "all"; "stripes": rows y % 5 < 2 (gaps between the visited rows, while live rows
// last); "band": a diagonal band 5 columns wide (spans move sideways from row to row);
// "seeds": a few single nodes (spans that grow mid-row as transfers spread); "edges": the
// first and last rows and columns.
template <class Active>
void add_members(Active& a, std::size_t nx, std::size_t ny, const std::string& members) {
  for (std::size_t y = 0; y < ny; ++y)
    for (std::size_t x = 0; x < nx; ++x) {
      const bool in = members == "all"       ? true
                      : members == "stripes" ? y % 5 < 2
                      : members == "band"    ? (x + 2 * nx - (y * 3) % nx) % nx < 5
                      : members == "seeds"   ? (x * 7 + y * 13) % 41 == 0
                                             : x == 0 || y == 0 || x + 1 == nx || y + 1 == ny;
      if (in) a.activate(x, y);
    }
}

template <class Real>
void kernel_matches_the_dense_grid(const KernelCase& kc, ErosionRuleKind kind, int neighbours, SweepPath path) {
  GridLayout g;
  g.nx = kc.nx, g.ny = kc.ny;
  g.dx = g.dy = 0.005;
  const auto initial = [](const Vec2& p) { return test::rough_height(p, 7, 0.005); };
  HeightGrid<Real> dense(g, initial);
  SparseHeights<Real> sparse(g, initial);
  ActiveSet dense_set(g.nx, g.ny, 2), sparse_set(g.nx, g.ny, 2);
  add_members(dense_set, g.nx, g.ny, kc.members);
  add_members(sparse_set, g.nx, g.ny, kc.members);
  const ErosionRule rule = test::rule_for(kind);
  const ErosionTables tables(g, neighbours, rule, rule.needs_gradient());
  for (int call = 0; call < 6; ++call) {  // passes in all four directions, several times
    const ErosionReport a = erode_ordered(dense, dense_set, tables, {.max_passes = 3}, path);
    const ErosionReport b = erode_ordered(sparse, sparse_set, tables, {.max_passes = 3}, path);
    ASSERT_EQ(a.transfers, b.transfers) << "call " << call;
    ASSERT_EQ(a.updates, b.updates) << "call " << call;
    ASSERT_EQ(a.active, b.active) << "call " << call;
    ASSERT_EQ(a.volume_moved_m3, b.volume_moved_m3) << "call " << call;
  }
  std::size_t differing = 0, moved = 0;
  const auto initial_grid = HeightGrid<Real>(g, initial);
  for (std::size_t iy = 0; iy < g.ny; ++iy)
    for (std::size_t ix = 0; ix < g.nx; ++ix) {
      const double zd = dense.z(g.index(ix, iy)), zs = sparse.z(ix, iy);
      differing += std::memcmp(&zd, &zs, sizeof zd) != 0;
      moved += zd != initial_grid.z(g.index(ix, iy));
    }
  EXPECT_EQ(differing, 0u);
  EXPECT_GT(moved, 0u);  // the state is rough: erosion changed heights
  EXPECT_EQ(sparse.carry_m3(), dense.carry_m3());
}

class RowWindowKernel : public ::testing::TestWithParam<KernelCase> {};

TEST_P(RowWindowKernel, SameHeightsAsTheDenseGridBitForBit) {
  for (const SweepPath path : {SweepPath::Dense, SweepPath::DenseAvx2, SweepPath::DenseBaseline}) {
    SCOPED_TRACE(static_cast<int>(path));
    kernel_matches_the_dense_grid<double>(GetParam(), ErosionRuleKind::Edge, 8, path);
    kernel_matches_the_dense_grid<float>(GetParam(), ErosionRuleKind::Edge, 8, path);
    kernel_matches_the_dense_grid<double>(GetParam(), ErosionRuleKind::Gradient, 4, path);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Layouts, RowWindowKernel,
    ::testing::Values(KernelCase{61, 47, "all"}, KernelCase{61, 47, "stripes"}, KernelCase{61, 47, "band"},
                      KernelCase{61, 47, "seeds"}, KernelCase{61, 47, "edges"}, KernelCase{141, 9, "band"},
                      KernelCase{13, 1, "all"}, KernelCase{13, 1, "seeds"}, KernelCase{29, 2, "all"},
                      KernelCase{29, 2, "seeds"}, KernelCase{19, 83, "stripes"}, KernelCase{19, 83, "band"},
                      KernelCase{3, 30, "all"}),
    [](const ::testing::TestParamInfo<KernelCase>& info) {
      return std::to_string(info.param.nx) + "x" + std::to_string(info.param.ny) + "_" + info.param.members;
    });

}  // namespace
}  // namespace sb::grid
