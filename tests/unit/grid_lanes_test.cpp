// The dense pass's AVX-512 lanes (grid/erosion_lanes_avx512.hpp): a group of 1..8 nodes
// three columns apart visited at once (erosion_visit8) leaves the grid, the rounding carry,
// the transfer count and the volumes given bit for bit as the same nodes' scalar visits
// (erosion_visit) one after the other, forwards and backwards, float and double, 4 and 8
// neighbours, edge and gradient rules, on rough states where most nodes transfer; and dense passes take those lanes
// where the CPU has them. Skipped (GTEST_SKIP, saying so) on CPUs without AVX-512; the AVX2
// and SSE2 paths are compared with each other and with the sparse grid in
// grid_dense_pass_test.cpp.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <vector>

#include "grid/erosion_kernel.hpp"
#include "grid/height_grid.hpp"
#include "grid_rough_states.hpp"

namespace sb::grid {
namespace {

constexpr double kCell = 0.005;
// 61 x 9 nodes: groups reach both ends of the interior of a row.
const GridLayout kLayout = GridLayout::covering({{0.0, 0.0}, {0.3, 0.04}}, kCell);

template <class Real>
HeightGrid<Real> rough_grid(std::uint64_t seed) {
  return HeightGrid<Real>(kLayout, [seed](const Vec2& p) { return test::rough_height(p, seed, kCell); });
}

template <class Real>
bool same_bits(const HeightGrid<Real>& a, const HeightGrid<Real>& b) {
  return std::memcmp(a.heights().data(), b.heights().data(), a.heights().size() * sizeof(Real)) == 0;
}

template <class Real, int N, bool Gradient = false>
void groups_are_scalar_visits() {
  if (!has_avx512()) GTEST_SKIP() << "this CPU has no AVX-512: the eight-lane visits are not exercised here";
  const ErosionTables tables(kLayout, N, test::rule_for(Gradient ? ErosionRuleKind::Gradient : ErosionRuleKind::Edge),
                             Gradient);
  const std::size_t nx = kLayout.nx;
  int groups = 0, moving_groups = 0;
  for (std::uint64_t seed = 1; seed <= 4; ++seed)
    for (std::size_t iy = 2; iy + 2 < kLayout.ny; ++iy)
      for (std::size_t count = 1; count <= 8; ++count)
        for (std::size_t a = 2; a + 3 * (count - 1) + 2 < nx; a += 5)
          for (const bool reverse : {false, true}) {
            HeightGrid<Real> lanes = rough_grid<Real>(seed), scalar = lanes;
            lanes.carry() = scalar.carry() = 1e-12;  // a carry owed from before, settled by the first mover
            const NodeClass& c = tables.of(a, iy);
            double given[8];
            std::size_t transfers = 0;
            const unsigned moved =
                erosion_visit8<N, Gradient>(lanes, tables, nx, iy * nx + a, count, c, reverse, given, transfers);
            unsigned expected = 0;
            std::size_t expected_transfers = 0;
            for (std::size_t i = 0; i < count; ++i) {
              const std::size_t l = reverse ? count - 1 - i : i;
              const VisitResult v = erosion_visit<N, Gradient>(scalar, tables, iy * nx + a + 3 * l, c);
              if (v.transfers == 0) continue;
              expected |= 1u << l;
              expected_transfers += static_cast<std::size_t>(v.transfers);
              ASSERT_TRUE((moved >> l) & 1u) << "lane " << l;
              EXPECT_EQ(std::memcmp(&given[l], &v.moved, sizeof(double)), 0) << "lane " << l;
            }
            ASSERT_EQ(moved, expected) << "a " << a << " count " << count;
            if (moved != 0) {
              EXPECT_EQ(transfers, expected_transfers);
            }
            ASSERT_TRUE(same_bits(lanes, scalar))
                << "seed " << seed << " row " << iy << " a " << a << " count " << count << (reverse ? " reverse" : "");
            EXPECT_EQ(std::memcmp(&lanes.carry(), &scalar.carry(), sizeof(double)), 0);
            ++groups;
            moving_groups += moved != 0;
          }
  EXPECT_GT(moving_groups, groups / 2);  // the states are rough enough to test something
}

TEST(EightLaneVisit, IsTheScalarVisitsBitForBitDoubleEight) { groups_are_scalar_visits<double, 8>(); }
TEST(EightLaneVisit, IsTheScalarVisitsBitForBitDoubleFour) { groups_are_scalar_visits<double, 4>(); }
TEST(EightLaneVisit, IsTheScalarVisitsBitForBitFloatEight) { groups_are_scalar_visits<float, 8>(); }
TEST(EightLaneVisit, IsTheScalarVisitsBitForBitFloatFour) { groups_are_scalar_visits<float, 4>(); }
TEST(EightLaneVisit, IsTheScalarVisitsBitForBitGradientDoubleEight) { groups_are_scalar_visits<double, 8, true>(); }
TEST(EightLaneVisit, IsTheScalarVisitsBitForBitGradientDoubleFour) { groups_are_scalar_visits<double, 4, true>(); }
TEST(EightLaneVisit, IsTheScalarVisitsBitForBitGradientFloatEight) { groups_are_scalar_visits<float, 8, true>(); }

// Dense passes take the widest lanes the CPU has, DenseAvx2 and DenseBaseline narrower ones.
TEST(DenseLanes, WidestTheCpuHas) {
  EXPECT_EQ(lanes_for(SweepPath::DenseBaseline), Lanes::Sse2);
  if (has_avx2()) {
    EXPECT_EQ(lanes_for(SweepPath::DenseAvx2), Lanes::Avx2);
  }
  if (!has_avx512()) GTEST_SKIP() << "this CPU has no AVX-512: dense passes run in AVX2 lanes here";
  EXPECT_EQ(lanes_for(SweepPath::Dense), Lanes::Avx512);
  EXPECT_EQ(lanes_for(SweepPath::Auto), Lanes::Avx512);
}

}  // namespace
}  // namespace sb::grid
