// Display change tracking (Terrain::changes_since, lattice_heights) on the lattice back-ends,
// each built through sb::make_terrain (grid in double and float, sparse): after random stamps,
// erosion steps and settling with the cascade, every node whose height changed lies in a
// rectangle the terrain reported; a stamp reports only tiles near its footprint; a terrain left
// alone reports nothing. The TIN has no lattice and does not track (a display rebuilds its mesh).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "common/height_field.hpp"
#include "common/scene.hpp"
#include "harness/run/backends.hpp"
#include "terrain_test_support.hpp"

namespace sb {
namespace {

// 0.6 m at 2 mm: 301 x 301 nodes, 5 x 5 tiles of 64.
Scene lattice_scene(const std::vector<std::string>& overrides) {
  return parse_scene(test::flat_sand_scene("0.6", "0.1", test::kDisk2cm, R"(
[stroke]
path_m = [[0.1, 0.3], [0.2, 0.3]]
spacing_m = 0.005
[grid]
cell_m = 0.002
)"),
                     "test", overrides);
}

struct Backend {
  const char* name;
  std::vector<std::string> overrides;
};

const Backend kLatticeBackends[] = {{"grid", {}}, {"grid", {"grid.storage=float"}}, {"sparse", {}}};

// Every node's height minus the sand's 0.1 m, as the display reads it.
std::vector<float> read_all(const Terrain& t, const HeightLattice& l) {
  std::vector<float> z(l.nx * l.ny);
  t.lattice_heights({0, 0, l.nx, l.ny}, 0.1, z.data(), l.nx);
  return z;
}

bool covered(const std::vector<NodeRect>& rects, std::size_t x, std::size_t y) {
  for (const NodeRect& r : rects)
    if (x >= r.x0 && x < r.x1 && y >= r.y0 && y < r.y1) return true;
  return false;
}

// Every changed node in a reported rectangle; returns how many nodes changed.
std::size_t expect_covered(const std::vector<float>& before, const std::vector<float>& after, const SurfaceChanges& c,
                           const HeightLattice& l, const std::string& what) {
  EXPECT_TRUE(c.tracked) << what;
  std::size_t changed = 0, missed = 0;
  for (std::size_t y = 0; y < l.ny; ++y)
    for (std::size_t x = 0; x < l.nx; ++x) {
      if (before[y * l.nx + x] == after[y * l.nx + x]) continue;
      ++changed;
      if (!covered(c.rects, x, y)) ++missed;
    }
  EXPECT_EQ(missed, 0u) << what << ": " << missed << " of " << changed << " changed nodes outside the reported tiles";
  return changed;
}

TEST(DisplayChanges, EveryChangedHeightIsInAReportedTileAfterRandomStrokes) {
  for (const Backend& b : kLatticeBackends) {
    const Scene s = lattice_scene(b.overrides);
    const HeightField field = HeightField::from_scene(s);
    auto t = make_terrain(b.name, s, field);
    const std::string who = std::string(b.name) + (b.overrides.empty() ? "" : " " + b.overrides[0]);
    const std::optional<HeightLattice> lattice = t->lattice();
    ASSERT_TRUE(lattice) << who;
    const HeightLattice& l = *lattice;
    EXPECT_EQ(l.nx, 301u);

    // The first call reports the whole lattice.
    SurfaceChanges first = t->changes_since(0);
    ASSERT_TRUE(first.tracked);
    std::size_t nodes = 0;
    for (const NodeRect& r : first.rects) nodes += (r.x1 - r.x0) * (r.y1 - r.y0);
    EXPECT_EQ(nodes, l.nx * l.ny) << who;
    std::uint64_t version = first.version;
    EXPECT_TRUE(t->changes_since(version).rects.empty()) << who << ": nothing happened";
    version = t->changes_since(version).version;

    const ErosionRule rule = test::rule_of(s);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> pos(0.05, 0.55), depth(0.004, 0.015);
    std::size_t changed_total = 0;
    std::vector<float> before = read_all(*t, l);
    for (int i = 0; i < 12; ++i) {
      // A stamp: its tiles lie within a tile of its footprint's box (the rim included).
      const Vec2 xy(pos(rng), pos(rng));
      const ToolStamp stamp = test::stamp_at(s, xy, 0.1 - depth(rng), {1.0, 0.5}, static_cast<std::uint32_t>(i));
      t->stamp(stamp);
      SurfaceChanges c = t->changes_since(version);
      version = c.version;
      std::vector<float> after = read_all(*t, l);
      changed_total += expect_covered(before, after, c, l, who + " stamp " + std::to_string(i));
      const double reach = 0.02 * 4 + 64 * 0.002;  // the disk, its rim band, and one tile
      for (const NodeRect& r : c.rects) {
        const double x0 = r.x0 * l.dx, x1 = (r.x1 - 1) * l.dx, y0 = r.y0 * l.dy, y1 = (r.y1 - 1) * l.dy;
        EXPECT_LT(x0, xy.x() + reach) << who;
        EXPECT_GT(x1, xy.x() - reach) << who;
        EXPECT_LT(y0, xy.y() + reach) << who;
        EXPECT_GT(y1, xy.y() - reach) << who;
      }
      before = std::move(after);
      // Erosion steps, and now and then a settling budget (the cascade's coarse levels too).
      for (int k = 0; k < 3; ++k) {
        const ErosionBudget budget =
            (i % 4 == 3 && k == 2) ? ErosionBudget{.max_passes = 64, .settling = true} : ErosionBudget{.max_passes = 4};
        t->erode(rule, budget);
        c = t->changes_since(version);
        version = c.version;
        after = read_all(*t, l);
        changed_total += expect_covered(before, after, c, l, who + " erosion after stamp " + std::to_string(i));
        before = std::move(after);
      }
    }
    EXPECT_GT(changed_total, 1000u) << who << ": the strokes changed the surface";
    // At rest (or merely left alone) nothing more is reported.
    EXPECT_TRUE(t->changes_since(version).rects.empty()) << who;
  }
}

TEST(DisplayChanges, TheTinHasNoLatticeAndDoesNotTrack) {
  const Scene s = lattice_scene({});
  const HeightField field = HeightField::from_scene(s);
  auto t = make_terrain("tin", s, field);
  EXPECT_FALSE(t->lattice());
  EXPECT_FALSE(t->changes_since(0).tracked);
}

}  // namespace
}  // namespace sb
