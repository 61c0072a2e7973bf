// The multi-resolution settling cascade (grid/multires_settle.hpp), on rough states with a pit
// to fill (sand must travel many cells): both rules, 4 and 8 neighbours, float and double,
// sizes that are not powers of two (37 x 53, 61 x 47), strips as thin as a grid gets (2 x N,
// N x 2: one axis never halved) and a grid too small for any coarse level.
//   - The cascade conserves volume to rounding (double: 1e-12 relative; float: the stored
//     volume plus the rounding carry).
//   - No level's relaxation raises its energy, and the fine energy after the cascade is not
//     above the energy before it.
//   - Settling with the cascade ends at repose under the fine rule (a pass over every node
//     moves nothing), and the dense and sparse grids stay identical bit for bit.
//   - Small budgets (the stroke's and the interactive steps') never take the cascade.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "grid/grid_terrain.hpp"
#include "grid/multires_settle.hpp"
#include "grid/sparse_terrain.hpp"
#include "grid_rough_states.hpp"

namespace sb::grid {
namespace {

constexpr double kCell = 0.005;

// Sand 0.1 m deep, rough by up to +-1.5 cells per node (test::rough_height), with a pit 3 cm
// deep over the middle third of the domain: its walls collapse over many cells.
double rough_pit(const Vec2& p, const Aabb2& box, std::uint64_t seed) {
  const Vec2 size = box.hi - box.lo;
  const Vec2 rel(p.x() - box.lo.x(), p.y() - box.lo.y());
  const bool pit = std::abs(rel.x() - size.x() / 2) <= size.x() / 6 && std::abs(rel.y() - size.y() / 2) <= size.y() / 6;
  return test::rough_height(p, seed, kCell) - (pit ? 0.03 : 0.0);
}

// nx x ny nodes on the 5 mm grid.
GridLayout layout_of(std::size_t nx, std::size_t ny) {
  return GridLayout::covering({{0.0, 0.0}, {kCell * static_cast<double>(nx - 1), kCell * static_cast<double>(ny - 1)}},
                              kCell);
}

template <class Grid>
double energy(const Grid& g) {
  const GridLayout& l = g.layout();
  double e = 0.0;
  for (std::size_t iy = 0; iy < l.ny; ++iy)
    for (std::size_t ix = 0; ix < l.nx; ++ix) {
      const double z = g.z(ix, iy);
      e += l.area(ix, iy) * z * z * 0.5;
    }
  return e;
}

using Case = test::ErosionCase;
using test::name;
using test::rule_for;

struct Size {
  std::size_t nx, ny;
  bool has_levels;  // an axis of 16 nodes or more
};
const Size kSizes[] = {{37, 53, true}, {61, 47, true}, {2, 150, true}, {150, 2, true}, {9, 12, false}};

class Multires : public ::testing::TestWithParam<Case> {
 protected:
  template <class Real>
  void cascade_conserves_and_lowers_energy() {
    const Case& c = GetParam();
    const ErosionRule rule = rule_for(c.rule);
    for (const Size& size : kSizes) {
      const GridLayout layout = layout_of(size.nx, size.ny);
      HeightGrid<Real> grid(layout, [&](const Vec2& p) { return rough_pit(p, layout.box(), 7); });
      ActiveSet active(layout.nx, layout.ny, 2);
      active.activate_all();
      const ErosionTables tables(layout, c.neighbours, rule, rule.needs_gradient());
      const double v0 = grid.volume() + grid.carry_m3(), e0 = energy(grid);
      const MultiresReport m = multires_settle(grid, active, tables, {.measure_energy = true});
      const std::string where = std::to_string(size.nx) + " x " + std::to_string(size.ny);
      ASSERT_EQ(!m.levels.empty(), size.has_levels) << where;
      EXPECT_NEAR(grid.volume() + grid.carry_m3(), v0, 1e-12 * v0) << where;
      bool moved = false;
      for (const MultiresLevelReport& l : m.levels) {
        EXPECT_LE(l.energy_after, l.energy_before * (1.0 + 1e-14)) << where << ", level " << l.nx << " x " << l.ny;
        moved |= l.changed > 0;
      }
      if (size.has_levels) {
        EXPECT_TRUE(moved) << where << ": the pit should move sand on some level";
      }
      // Float rounds each stored height (the carry keeps the volume, not the energy).
      const double e_tol = std::is_same_v<Real, float> ? 1e-7 : 1e-14;
      EXPECT_LE(energy(grid), e0 * (1.0 + e_tol)) << where;
      if (size.has_levels) {
        EXPECT_GT(m.fine_changed, 0u) << where;
      }
      std::vector<std::string> problems;
      active.check(problems);
      EXPECT_TRUE(problems.empty()) << where;
    }
  }

  template <class Real>
  void settles_to_repose_like_the_sparse_grid() {
    const Case& c = GetParam();
    const ErosionRule rule = rule_for(c.rule);
    for (const Size& size : kSizes) {
      const GridLayout layout = layout_of(size.nx, size.ny);
      const auto z0 = [&](const Vec2& p) { return rough_pit(p, layout.box(), 11); };
      GridTerrain<Real> dense(layout, z0, c.neighbours, 2);
      SparseGridTerrain<Real> sparse(layout, z0, c.neighbours, 2);
      dense.activate_all();
      sparse.activate_all();
      const double v0 = dense.volume();
      double tracked = v0;
      ErosionReport r;
      for (int call = 0; call < 400 && (call == 0 || r.active > 0); ++call) {
        r = dense.erode(rule, {.max_passes = 64});
        tracked += r.volume_change_m3;
        const ErosionReport rs = sparse.erode(rule, {.max_passes = 64});
        EXPECT_EQ(r.transfers, rs.transfers);
      }
      const std::string where = std::to_string(size.nx) + " x " + std::to_string(size.ny);
      ASSERT_EQ(r.active, 0u) << where << " did not settle";
      EXPECT_NEAR(tracked, dense.volume(), 1e-12 * v0) << where;
      EXPECT_NEAR(dense.volume() + dense.heights().carry_m3(), v0, 1e-12 * v0) << where;
      std::size_t differing = 0;
      for (std::size_t iy = 0; iy < layout.ny; ++iy)
        for (std::size_t ix = 0; ix < layout.nx; ++ix) {
          const double a = dense.heights().z(ix, iy), b = sparse.heights().z(ix, iy);
          differing += std::memcmp(&a, &b, sizeof a) != 0;
        }
      EXPECT_EQ(differing, 0u) << where;
      // At repose under the fine rule: a pass over every node, without the cascade, moves
      // nothing with the edge rule. With the gradient rule the fine passes alone also leave a
      // few nodes that such a pass still moves (2 of 2867 on 61 x 47, 8 neighbours, without
      // the cascade: the active set's own limit, not the cascade's), so a few are allowed.
      dense.set_multires(false);
      dense.activate_all();
      const std::size_t allowed = c.rule == ErosionRuleKind::Edge ? 0 : 4;
      EXPECT_LE(dense.erode(rule, {.max_passes = 1}).transfers, allowed) << where;
      EXPECT_TRUE(dense.check().ok()) << where;
    }
  }
};

TEST_P(Multires, CascadeConservesVolumeAndNeverRaisesEnergy) {
  if (GetParam().is_float)
    cascade_conserves_and_lowers_energy<float>();
  else
    cascade_conserves_and_lowers_energy<double>();
}

TEST_P(Multires, SettlesToReposeUnderTheFineRuleLikeTheSparseGrid) {
  if (GetParam().is_float)
    settles_to_repose_like_the_sparse_grid<float>();
  else
    settles_to_repose_like_the_sparse_grid<double>();
}

INSTANTIATE_TEST_SUITE_P(RulesStencilsStorage, Multires, test::erosion_cases(),
                         [](const ::testing::TestParamInfo<Case>& info) { return name(info.param); });

// The cascade takes far fewer passes than the fine passes alone on a 121 x 121 pit, and
// ends within a cell of their surface (settled surfaces are not unique).
TEST(MultiresSettling, FewerPassesAndCloseToTheFinePassesAlone) {
  const GridLayout layout = layout_of(121, 121);
  const ErosionRule rule = rule_for(ErosionRuleKind::Gradient);
  const auto z0 = [&](const Vec2& p) { return rough_pit(p, layout.box(), 3); };
  int passes[2] = {0, 0};
  std::vector<double> settled[2];
  for (int with = 0; with < 2; ++with) {
    GridTerrain<double> t(layout, z0, 8, 2);
    t.activate_all();
    t.set_multires(with == 1);
    ErosionReport r;
    for (int call = 0; call < 400 && (call == 0 || r.active > 0); ++call) {
      r = t.erode(rule, {.max_passes = 64});
      passes[with] += r.passes;
    }
    ASSERT_EQ(r.active, 0u);
    for (std::size_t iy = 0; iy < layout.ny; ++iy)
      for (std::size_t ix = 0; ix < layout.nx; ++ix) settled[with].push_back(t.heights().z(ix, iy));
  }
  RecordProperty("passes_fine_only", passes[0]);
  RecordProperty("passes_with_cascade", passes[1]);
  EXPECT_LT(passes[1] * 2, passes[0]);
  double worst = 0.0, mean = 0.0;
  for (std::size_t k = 0; k < settled[0].size(); ++k) {
    const double d = std::abs(settled[0][k] - settled[1][k]);
    worst = std::max(worst, d);
    mean += d / static_cast<double>(settled[0].size());
  }
  EXPECT_LE(worst, 2.0 * kCell);
  EXPECT_LE(mean, 0.1 * kCell);
}

// Budgets below 32 passes (the stroke's and interactive steps) never take the cascade: the
// same heights as with the cascade switched off.
TEST(MultiresSettling, SmallBudgetsStayOnTheFinePasses) {
  const GridLayout layout = layout_of(61, 47);
  const ErosionRule rule = rule_for(ErosionRuleKind::Edge);
  const auto z0 = [&](const Vec2& p) { return rough_pit(p, layout.box(), 5); };
  GridTerrain<double> on(layout, z0, 8, 2), off(layout, z0, 8, 2);
  on.activate_all();
  off.activate_all();
  off.set_multires(false);
  for (int step = 0; step < 20; ++step) {
    on.erode(rule, {.max_passes = 4});
    off.erode(rule, {.max_passes = 4});
  }
  EXPECT_EQ(on.heights().heights(), off.heights().heights());
}

}  // namespace
}  // namespace sb::grid
