// The erosion kernel's dense pass (grid/erosion_kernel.hpp) against its active-set sweep and
// against a plain sweep: on random rough states, both rules, 4 and 8 neighbours, float and
// double.
//   - The dense pass's shortcut (rows classed several nodes at a time, stable nodes skipped)
//     is exact: the dense grid (which takes it) and the sparse grid (which visits every node)
//     give the same heights bit for bit, with the rows classed and up to eight nodes visited
//     at once in AVX-512 lanes (SweepPath::Dense, where the CPU has them), four at once in
//     AVX2 lanes (SweepPath::DenseAvx2, where the CPU has them), or classed in SSE2 registers
//     and visited one at a time (SweepPath::DenseBaseline); also on wide rows.
//   - Dense and active-set paths conserve volume exactly (reported changes against volume()),
//     both settle, and reach surfaces within a small height tolerance of each other.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "grid/grid_terrain.hpp"
#include "grid/sparse_terrain.hpp"
#include "grid_rough_states.hpp"

namespace sb::grid {
namespace {

// A rough state: 0.1 m of sand with a random height per node of up to +-1.5 cells, on a
// 5 mm grid of 61 x 47 nodes (not square, not a multiple of the vector width).
constexpr double kCell = 0.005;
const GridLayout kLayout = GridLayout::covering({{0.0, 0.0}, {0.3, 0.23}}, kCell);

double rough(const Vec2& p, std::uint64_t seed) { return test::rough_height(p, seed, kCell); }
using Case = test::ErosionCase;
using test::name;
using test::rule_for;

// A wide one: 141 x 23 nodes, rows of three words, so the bit scans and the four-node visits
// cross word boundaries.
const GridLayout kWide = GridLayout::covering({{0.0, 0.0}, {0.7, 0.11}}, kCell);

template <class T>
std::vector<double> heights_of(const T& t) {
  const GridLayout& g = t.heights().layout();
  std::vector<double> z;
  for (std::size_t iy = 0; iy < g.ny; ++iy)
    for (std::size_t ix = 0; ix < g.nx; ++ix) z.push_back(t.heights().z(ix, iy));
  return z;
}

template <class T>
std::unique_ptr<T> rough_terrain(const Case& c, std::uint64_t seed, SweepPath path,
                                 const GridLayout& layout = kLayout) {
  auto t = std::make_unique<T>(
      layout, [seed](const Vec2& p) { return rough(p, seed); }, c.neighbours, 2);
  t->activate_all();
  t->set_sweep_path(path);
  return t;
}

class DensePass : public ::testing::TestWithParam<Case> {
 protected:
  template <class Real>
  void shortcut_is_exact(const GridLayout& layout = kLayout) {
    const Case& c = GetParam();
    const ErosionRule rule = rule_for(c.rule);
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
      auto dense = rough_terrain<GridTerrain<Real>>(c, seed, SweepPath::Dense, layout);
      auto plain = rough_terrain<SparseGridTerrain<Real>>(c, seed, SweepPath::Dense, layout);
      // SSE2 classing, one node at a time
      auto narrow = rough_terrain<GridTerrain<Real>>(c, seed, SweepPath::DenseBaseline, layout);
      // AVX2 lanes even where the CPU has AVX-512
      auto avx2 = rough_terrain<GridTerrain<Real>>(c, seed, SweepPath::DenseAvx2, layout);
      const double v0 = dense->volume();
      double tracked = v0;
      for (int call = 0; call < 5; ++call) {
        const ErosionReport a = dense->erode(rule, {.max_passes = 3});
        tracked += a.volume_change_m3;
        const ErosionReport b = plain->erode(rule, {.max_passes = 3});
        const ErosionReport n = narrow->erode(rule, {.max_passes = 3});
        const ErosionReport w = avx2->erode(rule, {.max_passes = 3});
        EXPECT_EQ(a.transfers, b.transfers);
        EXPECT_EQ(a.active, b.active);
        EXPECT_EQ(a.updates, b.updates);
        EXPECT_EQ(a.transfers, n.transfers);
        EXPECT_EQ(a.updates, n.updates);
        EXPECT_EQ(a.transfers, w.transfers);
        EXPECT_EQ(a.updates, w.updates);
        EXPECT_EQ(a.volume_moved_m3, w.volume_moved_m3);  // the same additions in the same order
        EXPECT_EQ(a.volume_moved_m3, n.volume_moved_m3);
      }
      const std::vector<double> za = heights_of(*dense), zb = heights_of(*plain), zn = heights_of(*narrow),
                                zw = heights_of(*avx2);
      std::size_t differing = 0, differing_narrow = 0, differing_avx2 = 0;
      for (std::size_t k = 0; k < za.size(); ++k) {
        differing += std::memcmp(&za[k], &zb[k], sizeof(double)) != 0;
        differing_narrow += std::memcmp(&za[k], &zn[k], sizeof(double)) != 0;
        differing_avx2 += std::memcmp(&za[k], &zw[k], sizeof(double)) != 0;
      }
      EXPECT_EQ(differing, 0u) << "seed " << seed;
      EXPECT_EQ(differing_narrow, 0u) << "seed " << seed;
      EXPECT_EQ(differing_avx2, 0u) << "seed " << seed;
      EXPECT_NEAR(tracked, dense->volume(), (c.is_float ? 1e-12 : 1e-14) * v0);  // transfers conserve volume
      EXPECT_TRUE(dense->check().ok());
    }
  }

  template <class Real>
  void paths_agree() {
    const Case& c = GetParam();
    const ErosionRule rule = rule_for(c.rule);
    const double v_tol = (c.is_float ? 1e-12 : 1e-14);
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
      std::vector<double> settled[2];
      const SweepPath paths[2] = {SweepPath::Dense, SweepPath::ActiveSet};
      for (int p = 0; p < 2; ++p) {
        auto t = rough_terrain<GridTerrain<Real>>(c, seed, paths[p]);
        const double v0 = t->volume();
        double tracked = v0;
        ErosionReport r;
        for (int call = 0; call < 200 && (call == 0 || r.active > 0); ++call) {
          r = t->erode(rule, {.max_passes = 50});
          tracked += r.volume_change_m3;
        }
        EXPECT_EQ(r.active, 0u) << "path " << p << " did not settle";
        EXPECT_NEAR(tracked, t->volume(), v_tol * v0) << "path " << p;
        EXPECT_NEAR(t->volume() + t->heights().carry_m3(), v0, v_tol * v0) << "path " << p;  // the carry is owed
        EXPECT_TRUE(t->check().ok());
        settled[p] = heights_of(*t);
      }
      // Settled surfaces are not unique (which node gives first decides where a grain
      // stops), so the paths may differ where the active set leaves out a node the dense pass
      // visits; on these states they measure identical (0 cells apart).
      double worst = 0.0, mean = 0.0;
      for (std::size_t k = 0; k < settled[0].size(); ++k) {
        const double d = std::abs(settled[0][k] - settled[1][k]);
        worst = std::max(worst, d);
        mean += d / static_cast<double>(settled[0].size());
      }
      RecordProperty("worst_over_cell_" + std::to_string(seed), std::to_string(worst / kCell));
      EXPECT_LE(worst, 1.0 * kCell) << "seed " << seed;
      EXPECT_LE(mean, 0.05 * kCell) << "seed " << seed;
    }
  }
};

TEST_P(DensePass, ShortcutGivesThePlainSweepBitForBit) {
  if (GetParam().is_float)
    shortcut_is_exact<float>();
  else
    shortcut_is_exact<double>();
}

TEST_P(DensePass, ShortcutGivesThePlainSweepBitForBitOnWideRows) {
  if (GetParam().is_float)
    shortcut_is_exact<float>(kWide);
  else
    shortcut_is_exact<double>(kWide);
}

// A pass over spans this large is split into two bands and a seam (dense_pass_splits), and the
// bands run on two threads where the store allows (double, HeightGrid): the heights, counts
// and moved volumes are the same bit for bit on one thread or two, dense or sparse, every
// lane width; volume is conserved; and the split pass settles as the unsplit one does.
// 301 x 241 nodes (not a multiple of anything): 72,541 nodes, 241 rows.
const GridLayout kTall = GridLayout::covering({{0.0, 0.0}, {1.5, 1.2}}, kCell);

TEST_P(DensePass, SplitPassIsTheSameOnOneThreadOrTwo) {
  const Case& c = GetParam();
  const ErosionRule rule = rule_for(c.rule);
  const auto run = [&]<class Real>(Real) {
    auto two = rough_terrain<GridTerrain<Real>>(c, 7, SweepPath::Dense, kTall);
    ASSERT_TRUE(dense_pass_splits(two->active_set().spans()));
    two->set_threads(2);
    auto one = rough_terrain<GridTerrain<Real>>(c, 7, SweepPath::Dense, kTall);
    auto sparse = rough_terrain<SparseGridTerrain<Real>>(c, 7, SweepPath::Dense, kTall);
    sparse->set_threads(2);  // runs its bands one after the other: its store is not shared
    auto narrow = rough_terrain<GridTerrain<Real>>(c, 7, SweepPath::DenseBaseline, kTall);
    narrow->set_threads(2);
    const double v0 = two->volume();
    double tracked = v0;
    for (int call = 0; call < 3; ++call) {  // passes in both y and x directions
      const ErosionReport a = two->erode(rule, {.max_passes = 2});
      tracked += a.volume_change_m3;
      for (auto* other : {static_cast<Terrain*>(one.get()), static_cast<Terrain*>(sparse.get()),
                          static_cast<Terrain*>(narrow.get())}) {
        const ErosionReport b = other->erode(rule, {.max_passes = 2});
        EXPECT_EQ(a.transfers, b.transfers);
        EXPECT_EQ(a.updates, b.updates);
        EXPECT_EQ(a.active, b.active);
        EXPECT_EQ(a.volume_moved_m3, b.volume_moved_m3);
      }
    }
    const std::vector<double> z = heights_of(*two);
    for (const std::vector<double>& other : {heights_of(*one), heights_of(*sparse), heights_of(*narrow)}) {
      std::size_t differing = 0;
      for (std::size_t k = 0; k < z.size(); ++k) differing += std::memcmp(&z[k], &other[k], sizeof(double)) != 0;
      EXPECT_EQ(differing, 0u);
    }
    EXPECT_NEAR(tracked, two->volume(), (c.is_float ? 1e-12 : 1e-14) * v0);
    EXPECT_TRUE(two->check().ok());
    // On to rest: the split passes settle, within a cell of the active-set sweep's surface.
    auto by_set = rough_terrain<GridTerrain<Real>>(c, 7, SweepPath::ActiveSet, kTall);
    for (Terrain* t : {static_cast<Terrain*>(two.get()), static_cast<Terrain*>(by_set.get())}) {
      ErosionReport r;
      for (int call = 0; call < 100 && (call == 0 || r.active > 0); ++call) r = t->erode(rule, {.max_passes = 50});
      EXPECT_EQ(r.active, 0u);
    }
    const std::vector<double> settled = heights_of(*two), reference = heights_of(*by_set);
    double worst = 0.0;
    for (std::size_t k = 0; k < settled.size(); ++k) worst = std::max(worst, std::abs(settled[k] - reference[k]));
    EXPECT_LE(worst, 1.0 * kCell);
  };
  if (c.is_float)
    run(0.0f);
  else
    run(0.0);
}

TEST_P(DensePass, ConservesAndSettlesCloseToTheActiveSetPath) {
  if (GetParam().is_float)
    paths_agree<float>();
  else
    paths_agree<double>();
}

INSTANTIATE_TEST_SUITE_P(RulesStencilsStorage, DensePass, test::erosion_cases(),
                         [](const ::testing::TestParamInfo<Case>& info) { return name(info.param); });
// The edge rule, 4 neighbours, float (the four-node visits with rounding, on the smaller stencil).
INSTANTIATE_TEST_SUITE_P(EdgeFourFloat, DensePass, ::testing::Values(Case{ErosionRuleKind::Edge, 4, true}),
                         [](const ::testing::TestParamInfo<Case>& info) { return name(info.param); });

// The dense pass keeps the active set word by word: the same members as activate_block per
// centre, across word boundaries and at the grid's edges; idle members leave after idle_passes.
TEST(DensePassActiveSet, AssignBlocksIsActivateBlockPerCentre) {
  for (const std::size_t nx : {std::size_t{5}, std::size_t{64}, std::size_t{130}}) {
    const std::size_t ny = 7;
    ActiveSet by_blocks(nx, ny, 2), by_words(nx, ny, 2);
    std::vector<std::uint64_t> centres(by_words.words_per_row() * ny, 0);
    std::uint64_t h = 12345;
    for (std::size_t iy = 0; iy < ny; ++iy)
      for (std::size_t ix = 0; ix < nx; ++ix) {
        h = h * 6364136223846793005ull + 1442695040888963407ull;
        if ((h >> 60) != 0 && ix != 63 && ix != 64 && ix != nx - 1) continue;  // sparse, plus word edges
        by_blocks.activate_block(ix, iy);
        centres[iy * by_words.words_per_row() + ix / 64] |= std::uint64_t{1} << (ix % 64);
      }
    by_words.assign_blocks(centres, 0, ny - 1);
    EXPECT_EQ(by_words.size(), by_blocks.size()) << nx;
    for (std::size_t iy = 0; iy < ny; ++iy)
      for (std::size_t ix = 0; ix < nx; ++ix) ASSERT_EQ(by_words.contains(ix, iy), by_blocks.contains(ix, iy));
    std::vector<std::string> problems;
    by_words.check(problems);
    EXPECT_TRUE(problems.empty()) << ::testing::PrintToString(problems);
    // Members of no block count an idle visit: with idle_passes = 2 they stay one pass more.
    const std::vector<std::uint64_t> none(centres.size(), 0);
    const std::size_t members = by_words.size();
    by_words.assign_blocks(none, 0, ny - 1);
    EXPECT_EQ(by_words.size(), members);
    by_words.assign_blocks(none, 0, ny - 1);
    EXPECT_EQ(by_words.size(), 0u);
    by_words.check(problems);
    EXPECT_TRUE(problems.empty()) << ::testing::PrintToString(problems);
  }
}

// The sparse grid's bit-plane idle counts, 64 nodes a word at once, count as one node at a time:
// the same nodes leave on every round, for idle_passes from 1 to 9 (one to four planes, and
// idle_passes a power of two, whose counts carry out of the planes).
TEST(DensePassActiveSet, BitPlaneCountsAWordAsNodeByNode) {
  for (const std::uint16_t idle_passes : {1, 2, 3, 4, 5, 8, 9}) {
    BitPlaneIdleCounts by_node(130, 3, 3, idle_passes), by_word(130, 3, 3, idle_passes);
    std::uint64_t h = 99 + idle_passes;
    for (int round = 0; round < 60; ++round) {
      const std::size_t y = static_cast<std::size_t>(round) % 3, w = static_cast<std::size_t>(round / 3) % 3;
      h = h * 6364136223846793005ull + 1442695040888963407ull;
      const std::uint64_t kept = h ^ (h >> 29) ^ (round % 4 == 0 ? ~std::uint64_t{0} : 0);
      std::uint64_t expected = 0;
      for (unsigned b = 0; b < 64; ++b)
        if ((kept >> b) & 1u && by_node.count_up(w * 64 + b, y, idle_passes)) expected |= std::uint64_t{1} << b;
      ASSERT_EQ(by_word.count_up_word(y, w, kept, idle_passes), expected) << idle_passes << " round " << round;
      if (round % 7 == 6) by_node.reset(y, 10, 100), by_word.reset(y, 10, 100);
    }
  }
}

// Given the columns that hold every member and centre, assign_blocks leaves the words outside
// them alone and gives the same set as over whole rows (ranges starting and ending at word
// edges, inside words, and at the grid's edges).
TEST(DensePassActiveSet, AssignBlocksOverColumnsIsOverWholeRows) {
  const std::size_t nx = 200, ny = 6;
  for (const auto& [x0, x1] :
       {std::pair<std::size_t, std::size_t>{60, 140}, {64, 127}, {63, 128}, {0, 199}, {150, 199}}) {
    ActiveSet whole(nx, ny, 2), ranged(nx, ny, 2);
    std::vector<std::uint64_t> centres(whole.words_per_row() * ny, 0);
    std::uint64_t h = 777;
    for (std::size_t iy = 0; iy < ny; ++iy)
      for (std::size_t ix = x0; ix <= x1; ++ix) {
        h = h * 6364136223846793005ull + 1442695040888963407ull;
        if ((h >> 61) == 0) centres[iy * whole.words_per_row() + ix / 64] |= std::uint64_t{1} << (ix % 64);
        if ((h >> 58) % 8 == 1) whole.activate(ix, iy), ranged.activate(ix, iy);  // members before the pass
      }
    for (int pass = 0; pass < 3; ++pass) {  // fresh blocks, then idle visits
      whole.assign_blocks(pass == 0 ? centres : std::vector<std::uint64_t>(centres.size(), 0), 0, ny - 1);
      ranged.assign_blocks(pass == 0 ? centres : std::vector<std::uint64_t>(centres.size(), 0), 0, ny - 1, x0, x1);
      ASSERT_EQ(ranged.size(), whole.size()) << x0 << ".." << x1 << " pass " << pass;
      for (std::size_t iy = 0; iy < ny; ++iy)
        for (std::size_t ix = 0; ix < nx; ++ix) ASSERT_EQ(ranged.contains(ix, iy), whole.contains(ix, iy));
      std::vector<std::string> problems;
      ranged.check(problems);
      EXPECT_TRUE(problems.empty()) << ::testing::PrintToString(problems);
    }
  }
}

// Which stores run a split pass's bands at once (the rest run them one after the other, with
// the same heights): double heights in one array only.
TEST(DensePassChoice, BandsRunTogetherOnDoubleArraysOnly) {
  EXPECT_TRUE(bands_run_together<HeightGrid<double>>());
  EXPECT_FALSE(bands_run_together<HeightGrid<float>>());  // the rounding carry chains the writes
  EXPECT_FALSE(bands_run_together<SparseHeights<double>>());
}

// Auto takes the dense pass when many nodes are members, the active-set sweep when few.
TEST(DensePassChoice, DenseWhenManyActive) {
  EXPECT_TRUE(dense_pass_pays(1000, 8000));
  EXPECT_FALSE(dense_pass_pays(999, 8000));
}

}  // namespace
}  // namespace sb::grid
