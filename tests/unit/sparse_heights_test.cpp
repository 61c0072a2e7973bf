// SparseHeights: the sparse grid's storage on OpenVDB against the dense HeightGrid -- the
// same heights bit for bit after the same writes, leaves only where blocks differ, tiles
// pruned back, and its byte count against the allocator and OpenVDB's memUsage().
#include "grid/sparse_heights.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "common/height_field.hpp"
#include "counting_allocator.hpp"
#include "grid/height_grid.hpp"
#include "grid_test_support.hpp"

namespace sb::grid::test {
namespace {

template <class Real>
class SparseHeightsTest : public ::testing::Test {};
TYPED_TEST_SUITE(SparseHeightsTest, StorageTypes, StorageName);

// 101 x 101 nodes (a partial block at each far edge) over a 0.5 m square.
GridLayout layout_101() { return GridLayout::covering({{0.0, 0.0}, {0.5, 0.5}}, 0.005); }
double flat(const Vec2&) { return 0.1; }
double wavy(const Vec2& p) { return 0.1 + 0.01 * std::sin(37.0 * p.x()) * std::cos(23.0 * p.y()); }

template <class Real>
void expect_same_heights(const SparseHeights<Real>& sparse, const HeightGrid<Real>& dense) {
  const GridLayout& g = dense.layout();
  std::size_t differ = 0;
  for (std::size_t iy = 0; iy < g.ny; ++iy)
    for (std::size_t ix = 0; ix < g.nx; ++ix)
      if (!same_bits(static_cast<Real>(sparse.z(ix, iy)), static_cast<Real>(dense.z(ix, iy)))) ++differ;
  EXPECT_EQ(differ, 0u);
}

template <class Real>
void expect_check_ok(const SparseHeights<Real>& h) {
  std::vector<std::string> problems;
  h.check(problems);
  EXPECT_TRUE(problems.empty()) << ::testing::PrintToString(problems);
}

TYPED_TEST(SparseHeightsTest, FlatSandIsAllBackground) {
  const SparseHeights<TypeParam> h(layout_101(), flat);
  const HeightGrid<TypeParam> dense(layout_101(), flat);
  EXPECT_EQ(h.background(), static_cast<TypeParam>(0.1));
  const SparseTreeCounts c = h.counts();
  EXPECT_EQ(c.leaves, 0u);
  EXPECT_EQ(c.tile_blocks, 0u);
  EXPECT_EQ(c.internal, 0u);
  expect_same_heights(h, dense);
  EXPECT_EQ(h.volume(), dense.volume());
  EXPECT_EQ(h.height({0.1234, 0.4321}), dense.height({0.1234, 0.4321}));
  // 13 x 13 blocks: the table and the tree object, nothing per node.
  EXPECT_LE(h.bytes(), 13u * 13u * 17u + 1232u);
  expect_check_ok(h);
}

TYPED_TEST(SparseHeightsTest, EveryNodeDifferentCostsAFewPerCentMoreThanDense) {
  const SparseHeights<TypeParam> h(layout_101(), wavy);
  const HeightGrid<TypeParam> dense(layout_101(), wavy);
  expect_same_heights(h, dense);
  EXPECT_EQ(h.volume(), dense.volume());
  EXPECT_EQ(h.counts().leaves, 13u * 13u);
  // 8 + 40/64 bytes a node in double, 4 + 40/64 in float; the last block row and column
  // overhang the grid by 3 nodes (104^2 / 101^2 = 1.06).
  const double per_node = static_cast<double>(h.bytes()) / static_cast<double>(dense.layout().nodes());
  // The table, the tree object and 4 internal nodes add 0.4 bytes a node on a grid this
  // small, 0.13 on a large one.
  EXPECT_LE(per_node, (sizeof(TypeParam) + 0.625) * 1.061 + 0.7);
  expect_check_ok(h);
}

TYPED_TEST(SparseHeightsTest, WritesMatchTheDenseGridAndCreateLeavesOnlyWhereTheyChangeSomething) {
  SparseHeights<TypeParam> h(layout_101(), flat);
  HeightGrid<TypeParam> dense(layout_101(), flat);
  const GridLayout g = layout_101();
  // Writing the background changes nothing.
  h.set(g.index(50, 50), 0.1);
  dense.set(g.index(50, 50), 0.1);
  EXPECT_EQ(h.counts().leaves, 0u);
  // One node of one block.
  h.set(g.index(50, 50), 0.09);
  dense.set(g.index(50, 50), 0.09);
  EXPECT_EQ(h.counts().leaves, 1u);
  // Random writes all over, in float with the rounding carry running through both.
  std::mt19937 rng(7);
  std::uniform_int_distribution<std::uint32_t> node(0, static_cast<std::uint32_t>(g.nodes() - 1));
  std::uniform_real_distribution<double> dz(-0.01, 0.01);
  for (int i = 0; i < 3000; ++i) {
    const std::uint32_t k = node(rng);
    const double target = dense.z(k) + dz(rng);
    h.set(k, target);
    dense.set(k, target);
  }
  expect_same_heights(h, dense);
  EXPECT_EQ(h.carry_m3(), dense.carry_m3());
  EXPECT_EQ(h.volume(), dense.volume());
  for (double x : {0.0, 0.013, 0.2501, 0.5})
    for (double y : {0.0, 0.0071, 0.333, 0.5}) EXPECT_EQ(h.height({x, y}), dense.height({x, y}));
  expect_check_ok(h);  // every node read through OpenVDB's accessor at its mapped voxel
}

TYPED_TEST(SparseHeightsTest, BlocksThatSettleUniformArePrunedBackToTiles) {
  // Heights a float holds exactly, so that the rounding carry stays zero.
  const auto bed = [](const Vec2&) { return 0.125; };
  SparseHeights<TypeParam> h(layout_101(), bed);
  const GridLayout g = layout_101();
  const auto fill = [&](std::size_t x0, std::size_t x1, std::size_t y0, std::size_t y1, double z) {
    for (std::size_t iy = y0; iy <= y1; ++iy)
      for (std::size_t ix = x0; ix <= x1; ++ix) h.set(g.index(ix, iy), z);
  };
  // Block (2, 3) dug to 6.25 cm; block (12, 12) (the corner: 5 x 5 nodes inside the grid,
  // the rest of its leaf outside) raised, one node first; one node of block (5, 5) nudged.
  fill(16, 23, 24, 31, 0.0625);
  fill(100, 100, 100, 100, 0.25);
  EXPECT_EQ(h.counts().leaves, 2u);
  EXPECT_EQ(h.prune(), 1u);  // the dug block
  fill(96, 100, 96, 100, 0.25);
  h.set(g.index(41, 42), 0.1875);
  EXPECT_EQ(h.counts().leaves, 2u);
  expect_check_ok(h);
  EXPECT_EQ(h.prune(), 1u);  // the corner
  SparseTreeCounts c = h.counts();
  EXPECT_EQ(c.leaves, 1u);
  EXPECT_EQ(c.tile_blocks, 2u);
  EXPECT_EQ(h.z(20, 27), 0.0625);
  EXPECT_EQ(h.z(100, 100), 0.25);
  expect_check_ok(h);
  // Nothing written since: nothing to prune.
  EXPECT_EQ(h.prune(), 0u);
  // Back to the background everywhere: no leaf, no tile, no internal node.
  h.set(g.index(41, 42), 0.125);
  fill(96, 100, 96, 100, 0.125);  // a tile block's first write creates its leaf again
  fill(16, 23, 24, 31, 0.125);
  EXPECT_EQ(h.prune(), 3u);
  c = h.counts();
  EXPECT_EQ(c.leaves, 0u);
  EXPECT_EQ(c.tile_blocks, 0u);
  EXPECT_EQ(c.internal, 0u);
  expect_check_ok(h);
}

TYPED_TEST(SparseHeightsTest, UniformBlocksAwayFromTheBackgroundStartAsTiles) {
  // A plateau at 12 cm over x < 0.2025 (nodes x <= 40), flat 10 cm elsewhere: the blocks
  // wholly on the plateau (columns 0..4) are tiles, those straddling its edge (column 5)
  // leaves.
  const auto plateau = [](const Vec2& p) { return p.x() < 0.2025 ? 0.12 : 0.1; };
  const SparseHeights<TypeParam> h(layout_101(), plateau);
  const HeightGrid<TypeParam> dense(layout_101(), plateau);
  EXPECT_EQ(h.background(), static_cast<TypeParam>(0.1));  // 13 x 8 blocks against 13 x 5
  const SparseTreeCounts c = h.counts();
  EXPECT_EQ(c.leaves, 13u);
  EXPECT_EQ(c.tile_blocks, 13u * 5u);
  expect_same_heights(h, dense);
  expect_check_ok(h);
}

TYPED_TEST(SparseHeightsTest, BytesMatchTheAllocatorAndOpenVdbsMemUsage) {
  const auto bed = [](const Vec2&) { return 0.125; };  // a height float holds exactly
  {  // OpenVDB allocates a few bytes once, on its first prune; not part of any model.
    SparseHeights<TypeParam> warm(layout_101(), bed);
    for (std::uint32_t iy = 0; iy < 8; ++iy)
      for (std::uint32_t ix = 0; ix < 8; ++ix) warm.set(iy * 101 + ix, 0.25);
    ASSERT_EQ(warm.prune(), 1u);
  }
  const long long before = ::sb::test::live_heap_bytes();
  const auto held = [&] { return static_cast<std::size_t>(::sb::test::live_heap_bytes() - before); };
  const GridLayout g = layout_101();
  auto h = std::make_unique<SparseHeights<TypeParam>>(g, bed);
  // OpenVDB's estimate leaves out the root map's nodes (64 or 72 bytes each) and 4 bytes of
  // each internal node (its transient data), and counts the root node (72 bytes) twice.
  const auto expect_mem_usage_close = [&] {
    const std::size_t root_entry = sizeof(TypeParam) == 8 ? 72 : 64;
    const SparseTreeCounts c = h->counts();
    EXPECT_EQ(h->tree_bytes() + 72, h->tree_mem_usage() + c.root_entries * root_entry + 4 * c.internal)
        << "bytes " << h->bytes() << " memUsage " << h->tree_mem_usage();
  };
  EXPECT_EQ(held(), sizeof(SparseHeights<TypeParam>) + h->bytes());
  expect_mem_usage_close();
  std::mt19937 rng(3);
  std::uniform_int_distribution<std::uint32_t> node(0, static_cast<std::uint32_t>(g.nodes() - 1));
  for (int round = 0; round < 4; ++round) {
    for (int i = 0; i < 40; ++i) h->set(node(rng), 0.125 + 0.0625 * round);
    EXPECT_EQ(held(), sizeof(SparseHeights<TypeParam>) + h->bytes());
    expect_mem_usage_close();
  }
  for (std::uint32_t k = 0; k < g.nodes(); ++k) h->set(k, 0.125);
  h->prune();
  EXPECT_EQ(held(), sizeof(SparseHeights<TypeParam>) + h->bytes());
  EXPECT_EQ(h->counts().leaves, 0u);
  h.reset();
  EXPECT_EQ(held(), 0u);
}

// Building holds one block's heights at a time, not the grid's: a 4096 x 4096 bed (16.8 M
// nodes, 134 MB as doubles) peaks at the model's own bytes and the first pass's two entries
// per block.
TYPED_TEST(SparseHeightsTest, BuildingALargeBedHoldsNoCopyOfTheGrid) {
  const GridLayout g = GridLayout::covering({{0.0, 0.0}, {4.095, 4.095}}, 0.001);
  ASSERT_EQ(g.nodes(), 4096u * 4096u);
  const auto bed = [](const Vec2& p) { return p.x() < 0.5 && p.y() < 0.5 ? 0.1 + 0.01 * p.x() : 0.1; };
  const long long before = ::sb::test::live_heap_bytes();
  ::sb::test::reset_peak_heap_bytes();
  const SparseHeights<TypeParam> h(g, bed);
  const long long peak = ::sb::test::peak_heap_bytes() - before;
  const double blocks = static_cast<double>(g.nodes()) / 64.0;
  const double first_pass = blocks * static_cast<double>(sizeof(TypeParam) + 1);
  EXPECT_LE(static_cast<double>(peak), static_cast<double>(sizeof(h) + h.bytes()) + first_pass + (1 << 20))
      << "model " << h.bytes() << " bytes";
  EXPECT_LT(static_cast<double>(peak), 0.1 * static_cast<double>(g.nodes() * sizeof(TypeParam)));
  EXPECT_GT(h.counts().leaves, 0u);  // the sloped corner is stored
}

TEST(SparseHeightsMapping, EveryNodeOfABlockHasItsOwnVoxel) {
  std::vector<int> seen(64, 0);
  for (std::size_t y = 0; y < 8; ++y)
    for (std::size_t x = 0; x < 8; ++x) ++seen[SparseHeights<double>::voxel_offset(x + 8 * 3, y + 8 * 5)];
  EXPECT_TRUE(std::all_of(seen.begin(), seen.end(), [](int n) { return n == 1; }));
}

TEST(SparseHeightsSizes, TinyAndLongThinGrids) {
  for (const Aabb2& box : {Aabb2{{0.0, 0.0}, {0.001, 0.001}}, Aabb2{{-1.0, 2.0}, {2.0, 2.02}}}) {
    const GridLayout g = GridLayout::covering(box, 0.005);
    SparseHeights<double> h(g, wavy);
    HeightGrid<double> dense(g, wavy);
    h.set(g.index(g.nx - 1, g.ny - 1), 0.3);
    dense.set(g.index(g.nx - 1, g.ny - 1), 0.3);
    expect_same_heights(h, dense);
    EXPECT_EQ(h.volume(), dense.volume());
    expect_check_ok(h);
  }
}

}  // namespace
}  // namespace sb::grid::test
