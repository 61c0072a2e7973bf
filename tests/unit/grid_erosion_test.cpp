// Erosion on the grid: relaxes to the critical angle, conserves volume, stays inside the
// active set, obeys its budget, and is deterministic.
#include <cmath>

#include "grid_test_support.hpp"

namespace sb::grid::test {
namespace {

template <class Real>
class GridErosion : public ::testing::Test {};
TYPED_TEST_SUITE(GridErosion, StorageTypes, StorageName);

// A column of sand poured onto flat ground, 0.24 m tall and 4 cm wide.
ToolStamp column() { return sb::test::pour_at({0.25, 0.25}, 0.0201, 3e-4); }

TYPED_TEST(GridErosion, FullRelaxationEndsAtTheCriticalAngle) {
  for (const int neighbours : {8, 4}) {
    for (const double angle : {30.0, 34.0}) {
      SCOPED_TRACE(std::to_string(neighbours) + " neighbours, " + std::to_string(angle) + " degrees");
      const Scene s = scene(
          {"grid.neighbours=" + std::to_string(neighbours), "material.critical_angle_deg=" + std::to_string(angle)});
      const auto t = make_grid<TypeParam>(s);
      t->stamp(column());
      const double v0 = t->volume();
      ASSERT_GT(t->max_slope_deg(), 80.0);

      const ErosionReport r = t->erode(rule_of(s), {.max_passes = 1000000});
      EXPECT_EQ(r.active, 0u);
      EXPECT_EQ(t->stats().active, 0u);
      EXPECT_GT(r.transfers, 1000u);
      EXPECT_GT(r.volume_moved_m3, 1e-4);
      EXPECT_LT(r.passes, 1000000);
      // Settled: no slope beyond the critical angle (plus the settle tolerance, 0.1 deg).
      EXPECT_LE(t->max_slope_deg(), angle + 0.5);
      EXPECT_GE(t->max_slope_deg(), angle - 2.0);  // and a pile, not a puddle
      EXPECT_NEAR(t->volume(), v0, kVolumeTolerance<TypeParam> * v0);
      SB_EXPECT_CHECK_OK(*t);
      // The pile is as wide as a cone of that volume at that angle (R^3 = 3V / (pi tan)).
      const double cone_r = std::cbrt(3.0 * 3e-4 / (M_PI * std::tan(deg_to_rad(angle))));
      EXPECT_GT(t->height({0.25 + 0.6 * cone_r, 0.25}), kSand<TypeParam> + 1e-3);
      EXPECT_EQ(t->height({0.25 + 1.5 * cone_r, 0.25}), kSand<TypeParam>);
    }
  }
}

TYPED_TEST(GridErosion, TouchesOnlyTheActiveSet) {
  // A plane below the angle of repose (16.7 degrees) with a trench cut into it: the
  // trench's walls collapse, and nothing far from them is read as changed or kept active.
  // (Sweeps are live -- a run of unstable nodes ahead of the cursor moves in the same pass
  // -- so a pass is not limited to one ring; on a plane steeper than the angle of repose
  // the whole plane would rightly slide.)
  const Scene s = scene();
  const auto plane = [](const Vec2& p) { return 0.1 + 0.3 * p.x(); };
  const auto t = make_grid<TypeParam>(s, plane);
  ASSERT_LT(t->max_slope_deg(), 25.0);
  const std::vector<TypeParam> before = t->heights().heights();
  const ToolStamp st = stamp_at(s, {0.12, 0.12}, plane({0.12, 0.12}) - 0.01);
  t->stamp(st);
  const int passes = 10;
  const ErosionReport r = t->erode(rule_of(s), {.max_passes = passes});
  EXPECT_EQ(r.passes, passes);
  EXPECT_GT(r.transfers, 0u);
  SB_EXPECT_CHECK_OK(*t);

  // A 1 cm wall at 30 degrees reaches 1.7 cm beyond it; 4 cm is generous, the grid is 50 cm.
  const GridLayout& g = t->layout();
  const Aabb2 reach = st.influence_bounds().expanded(0.04);
  std::size_t changed_outside_stamp = 0;
  for (std::size_t iy = 0; iy < g.ny; ++iy)
    for (std::size_t ix = 0; ix < g.nx; ++ix) {
      const std::uint32_t k = g.index(ix, iy);
      const Vec2 p = g.position(ix, iy);
      if (!reach.contains(p)) {
        ASSERT_TRUE(same_bits(t->heights().heights()[k], before[k])) << ix << "," << iy;
        ASSERT_FALSE(t->active_set().contains(k)) << ix << "," << iy;
      }
      if (!st.influence_bounds().contains(p) && t->heights().heights()[k] != before[k]) ++changed_outside_stamp;
    }
  EXPECT_GT(changed_outside_stamp, 0u);  // erosion did spread beyond the stamp
}

TYPED_TEST(GridErosion, ConservesVolumeAndMovesMaterialDownhill) {
  const Scene s = scene();
  const auto t = make_grid<TypeParam>(s);
  t->stamp(column());
  const double v0 = t->volume();
  const GridLayout& g = t->layout();
  const std::uint32_t centre = g.nearest({0.25, 0.25}), outside = g.nearest({0.25 + 0.025, 0.25});
  const double z_centre = t->heights().z(centre), z_outside = t->heights().z(outside);
  for (int step = 0; step < 20; ++step) {
    const ErosionReport r = t->erode(rule_of(s), {.max_passes = 4});
    EXPECT_LE(r.passes, 4);
    EXPECT_NEAR(t->volume(), v0, kVolumeTolerance<TypeParam> * v0);
    SB_EXPECT_CHECK_OK(*t);
  }
  EXPECT_LT(t->heights().z(centre), z_centre);
  EXPECT_GT(t->heights().z(outside), z_outside);
}

TYPED_TEST(GridErosion, ObeysTheUpdateBudget) {
  const Scene s = scene();
  const auto t = make_grid<TypeParam>(s);
  t->stamp(column());
  const std::size_t active = t->stats().active;
  // The nodes poured on and their neighbours.
  const GridLayout& g = t->layout();
  std::size_t poured_and_neighbours = 0;
  for (std::size_t iy = 1; iy + 1 < g.ny; ++iy)
    for (std::size_t ix = 1; ix + 1 < g.nx; ++ix) {
      bool near = false;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) near = near || t->heights().z(g.index(ix + dx, iy + dy)) != kSand<TypeParam>;
      poured_and_neighbours += near;
    }
  ASSERT_EQ(active, poured_and_neighbours);
  ErosionReport r = t->erode(rule_of(s), {.max_passes = 50, .max_updates = 150});
  EXPECT_EQ(r.updates, 150u);
  EXPECT_EQ(r.passes, 2);
  // The budget ran out in the second pass; the nodes it did not reach are still active.
  EXPECT_GE(r.active, active);
  SB_EXPECT_CHECK_OK(*t);
  r = t->erode(rule_of(s), {.max_passes = 0});
  EXPECT_EQ(r.passes, 0);
  EXPECT_EQ(r.updates, 0u);
  r = t->erode(rule_of(s), {.max_passes = 1000000});
  EXPECT_EQ(r.active, 0u);
  SB_EXPECT_CHECK_OK(*t);
}

TYPED_TEST(GridErosion, IdleNodesLeaveAfterIdlePasses) {
  // On both sweeps: the active set's (which visits the members) and the dense pass (which
  // visits their row spans).
  for (const SweepPath path : {SweepPath::ActiveSet, SweepPath::Dense}) {
    const Scene s = scene({"erosion.idle_passes=3"});
    const auto t = make_grid<TypeParam>(s);
    t->set_sweep_path(path);
    ToolStamp drop = column();
    drop.pour_volume_m3 = 1e-9;  // a film far below the angle of repose
    t->stamp(drop);
    const std::size_t active = t->stats().active;
    ASSERT_GT(active, 49u);
    const std::size_t visited = path == SweepPath::Dense ? t->active_set().spans().nodes : active;
    ErosionReport r = t->erode(rule_of(s), {.max_passes = 2});
    EXPECT_EQ(r.passes, 2);
    EXPECT_EQ(r.transfers, 0u);
    EXPECT_EQ(r.updates, 2 * visited);
    EXPECT_EQ(r.active, active);
    SB_EXPECT_CHECK_OK(*t);
    r = t->erode(rule_of(s), {.max_passes = 5});
    EXPECT_EQ(r.passes, 1);
    EXPECT_EQ(r.active, 0u);
    SB_EXPECT_CHECK_OK(*t);
    r = t->erode(rule_of(s), {.max_passes = 5});
    EXPECT_EQ(r.passes, 0);
  }
}

TYPED_TEST(GridErosion, SameInputGivesTheSameSurface) {
  const Scene s = scene({"terrain.kind=\"dunes\"", "stroke.repeat=2"});
  const StampSchedule schedule = schedule_of(s);
  std::vector<TypeParam> heights[2];
  std::size_t transfers[2] = {0, 0};
  for (int run = 0; run < 2; ++run) {
    const auto t = make_grid<TypeParam>(s);
    for (const ToolStamp& st : schedule.stamps) {
      t->stamp(st);
      transfers[run] += t->erode(rule_of(s), {.max_passes = 4}).transfers;
    }
    heights[run] = t->heights().heights();
  }
  EXPECT_GT(transfers[0], 0u);
  EXPECT_EQ(transfers[0], transfers[1]);
  ASSERT_EQ(heights[0].size(), heights[1].size());
  EXPECT_EQ(std::memcmp(heights[0].data(), heights[1].data(), heights[0].size() * sizeof(TypeParam)), 0);
}

}  // namespace
}  // namespace sb::grid::test
