// The grid kernel's scalar visit (erosion_visit, the rule unrolled over node-class tables) and
// the shared rule (sb::erosion_transfers, common/erosion.hpp) agree: for every node of a rough
// grid (interior, border and corner classes), both rules and both stencils, the visit leaves
// the heights the shared rule's transfers give. The neighbours, their areas (trapezoid rule)
// and the central-difference gradient are built here from the layout, independently of the
// kernel's tables; the two compute in different orders, so they agree to rounding.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "common/erosion.hpp"
#include "grid/erosion_kernel.hpp"
#include "grid/height_grid.hpp"
#include "grid/stencil.hpp"
#include "grid_rough_states.hpp"

namespace sb::grid {
namespace {

constexpr double kCell = 0.005;
const GridLayout kLayout = GridLayout::covering({{0.0, 0.0}, {0.04, 0.03}}, kCell);

// The node's share of the domain along one axis: half a cell on the border.
double axis_weight(std::size_t i, std::size_t n, double d) { return i == 0 || i + 1 == n ? 0.5 * d : d; }
double node_area(std::size_t ix, std::size_t iy) {
  return axis_weight(ix, kLayout.nx, kLayout.dx) * axis_weight(iy, kLayout.ny, kLayout.dy);
}

// One-sided on the border, central inside: (z[+] - z[-]) / (run between them).
double difference(const HeightGrid<double>& g, std::size_t ix, std::size_t iy, bool along_x) {
  const std::size_t n = along_x ? kLayout.nx : kLayout.ny, i = along_x ? ix : iy;
  const std::size_t lo = i > 0 ? i - 1 : i, hi = i + 1 < n ? i + 1 : i;
  const double zl = along_x ? g.z(lo, iy) : g.z(ix, lo), zh = along_x ? g.z(hi, iy) : g.z(ix, hi);
  return (zh - zl) / (static_cast<double>(hi - lo) * (along_x ? kLayout.dx : kLayout.dy));
}

struct RuleCase {
  ErosionRuleKind kind;
  int neighbours;
};

class GridRule : public ::testing::TestWithParam<RuleCase> {};

template <int N, bool Gradient>
void visits_agree_with_the_shared_rule(ErosionRuleKind kind) {
  const ErosionRule rule = test::rule_for(kind);
  const ErosionTables tables(kLayout, N, rule, Gradient);
  std::size_t moving = 0;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const HeightGrid<double> start(kLayout, [seed](const Vec2& p) { return test::rough_height(p, seed, kCell); });
    for (std::size_t iy = 0; iy < kLayout.ny; ++iy) {
      for (std::size_t ix = 0; ix < kLayout.nx; ++ix) {
        SCOPED_TRACE("seed " + std::to_string(seed) + ", node (" + std::to_string(ix) + ", " + std::to_string(iy) +
                     ")");
        // The shared rule on neighbours built from the layout.
        std::vector<ErosionNeighbour> nbrs;
        std::vector<std::uint32_t> index;
        for (int s = 0; s < N; ++s) {
          const auto jx = static_cast<std::ptrdiff_t>(ix) + kStencilOffsets[s][0];
          const auto jy = static_cast<std::ptrdiff_t>(iy) + kStencilOffsets[s][1];
          if (jx < 0 || jy < 0 || jx >= static_cast<std::ptrdiff_t>(kLayout.nx) ||
              jy >= static_cast<std::ptrdiff_t>(kLayout.ny))
            continue;
          const double dx = kStencilOffsets[s][0] * kLayout.dx, dy = kStencilOffsets[s][1] * kLayout.dy;
          const auto ux = static_cast<std::size_t>(jx), uy = static_cast<std::size_t>(jy);
          nbrs.push_back({start.z(ux, uy), std::hypot(dx, dy), node_area(ux, uy), dx, dy});
          index.push_back(kLayout.index(ux, uy));
        }
        const SurfaceGradient g{difference(start, ix, iy, true), difference(start, ix, iy, false)};
        std::vector<double> out(nbrs.size());
        const double area_i = node_area(ix, iy);
        const double total = erosion_transfers(start.z(ix, iy), area_i, g, nbrs, rule, out);

        HeightGrid<double> grid = start;
        const VisitResult v = erosion_visit<N, Gradient>(grid, tables, kLayout.index(ix, iy), tables.of(ix, iy));
        EXPECT_NEAR(v.moved, total, 1e-12 * total + 1e-20);
        int receivers = 0;
        for (std::size_t j = 0; j < nbrs.size(); ++j) {
          receivers += out[j] > 0.0;
          EXPECT_NEAR(grid.z(index[j]), nbrs[j].z + out[j] / nbrs[j].area, 1e-14) << "neighbour " << j;
        }
        EXPECT_EQ(v.transfers, receivers);
        EXPECT_NEAR(grid.z(ix, iy), start.z(ix, iy) - total / area_i, 1e-14);
        moving += v.transfers > 0;
      }
    }
  }
  // The states are rough enough that most nodes move, so the comparison is not of zeros.
  EXPECT_GT(moving, kLayout.nodes());
}

TEST_P(GridRule, ScalarVisitIsTheSharedRule) {
  const RuleCase c = GetParam();
  const bool gradient = c.kind == ErosionRuleKind::Gradient;
  if (c.neighbours == 8)
    gradient ? visits_agree_with_the_shared_rule<8, true>(c.kind) : visits_agree_with_the_shared_rule<8, false>(c.kind);
  else
    gradient ? visits_agree_with_the_shared_rule<4, true>(c.kind) : visits_agree_with_the_shared_rule<4, false>(c.kind);
}

INSTANTIATE_TEST_SUITE_P(RulesAndStencils, GridRule,
                         ::testing::Values(RuleCase{ErosionRuleKind::Edge, 8}, RuleCase{ErosionRuleKind::Edge, 4},
                                           RuleCase{ErosionRuleKind::Gradient, 8},
                                           RuleCase{ErosionRuleKind::Gradient, 4}),
                         [](const auto& info) {
                           return std::string(to_string(info.param.kind)) + "_" + std::to_string(info.param.neighbours);
                         });

}  // namespace
}  // namespace sb::grid
