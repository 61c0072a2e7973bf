// Tool stamps on the grid with the rim rule: depth reached, volume conserved, rim weighted
// forwards, pours.
#include <cmath>

#include "grid_test_support.hpp"

namespace sb::grid::test {
namespace {

template <class Real>
class GridStamp : public ::testing::Test {};
TYPED_TEST_SUITE(GridStamp, StorageTypes, StorageName);

// The rim rule on the grid (tool.displacement = "rim"); bulldozing: terrain_bulldoze_test.cpp.
Scene rim_scene(std::vector<std::string> overrides = {}, const std::string& text = flat_scene(kDisk)) {
  overrides.insert(overrides.begin(), "tool.displacement=\"rim\"");
  return scene(overrides, text);
}

TYPED_TEST(GridStamp, CutsToTheToolDepthAndConservesVolume) {
  const Scene s = rim_scene();
  const auto t = make_grid<TypeParam>(s);
  const double v0 = t->volume();
  const ToolStamp st = stamp_at(s, {0.25, 0.25}, 0.09);
  const StampReport r = t->stamp(st);

  // About the disk's area times the depth (the disk is a 32-gon, sampled at nodes).
  EXPECT_NEAR(r.volume_removed_m3, M_PI * 0.03 * 0.03 * 0.01, 0.05 * M_PI * 0.03 * 0.03 * 0.01);
  EXPECT_NEAR(r.volume_deposited_m3, r.volume_removed_m3, 1e-14 * r.volume_removed_m3);
  EXPECT_NEAR(t->volume(), v0, kVolumeTolerance<TypeParam> * v0);
  EXPECT_GT(r.elements_touched, 100u);

  const GridLayout& g = t->layout();
  std::size_t inside = 0, rim = 0;
  for (std::size_t iy = 0; iy < g.ny; ++iy)
    for (std::size_t ix = 0; ix < g.nx; ++ix) {
      const Vec2 p = g.position(ix, iy);
      const double z = t->heights().z(ix, iy);
      if (st.contains(p)) {
        ++inside;
        EXPECT_NEAR(z, 0.09, sizeof(TypeParam) == 8 ? 0.0 : 2e-8) << ix << "," << iy;
      } else if (const double w = st.rim_weight(p); w > 0.0) {
        ++rim;
        if (w > 1e-3) {
          EXPECT_GT(z, kSand<TypeParam>) << ix << "," << iy;
        }
      } else {
        EXPECT_EQ(z, kSand<TypeParam>) << ix << "," << iy;
      }
    }
  EXPECT_EQ(inside + rim, r.elements_touched);
  SB_EXPECT_CHECK_OK(*t);
}

TYPED_TEST(GridStamp, RimGetsMoreInFrontThanBehind) {
  const Scene s = rim_scene();
  const auto t = make_grid<TypeParam>(s);
  const Vec2 centre{0.25, 0.25};
  const Vec2 motion = Vec2(1.0, 0.5).normalized();
  const ToolStamp st = stamp_at(s, centre, 0.09, motion);
  t->stamp(st);
  const GridLayout& g = t->layout();
  double front = 0.0, behind = 0.0;
  for (std::size_t iy = 0; iy < g.ny; ++iy)
    for (std::size_t ix = 0; ix < g.nx; ++ix) {
      const Vec2 p = g.position(ix, iy);
      if (st.contains(p)) continue;
      const double added = g.area(ix, iy) * (t->heights().z(ix, iy) - kSand<TypeParam>);
      ((p - centre).dot(motion) > 0.0 ? front : behind) += added;
    }
  EXPECT_GT(behind, 0.0);          // forward_bias 0.8 < 1 leaves some behind
  EXPECT_GT(front, 3.0 * behind);  // and most in front
}

TYPED_TEST(GridStamp, NothingOutsideTheInfluenceBoundsChanges) {
  // Rough initial terrain: a stamp that visited too much would show.
  const Scene s = rim_scene({"terrain.kind=\"dunes\"", "terrain.amplitude_m=0.05"});
  const auto t = make_grid<TypeParam>(s);
  const std::vector<TypeParam> before = t->heights().heights();
  const ToolStamp st = stamp_at(s, {0.2, 0.3}, 0.05);
  t->stamp(st);
  const GridLayout& g = t->layout();
  const Aabb2 window = st.influence_bounds();
  std::size_t changed = 0;
  for (std::size_t iy = 0; iy < g.ny; ++iy)
    for (std::size_t ix = 0; ix < g.nx; ++ix) {
      const std::uint32_t k = g.index(ix, iy);
      if (t->heights().heights()[k] == before[k]) continue;
      ++changed;
      EXPECT_TRUE(window.contains(g.position(ix, iy))) << ix << "," << iy;
    }
  EXPECT_GT(changed, 100u);
}

TYPED_TEST(GridStamp, ActiveSetHoldsTheChangedNodesAndTheirNeighbours) {
  const Scene s = rim_scene();
  const auto t = make_grid<TypeParam>(s);
  const std::vector<TypeParam> before = t->heights().heights();
  t->stamp(stamp_at(s, {0.25, 0.25}, 0.09));
  const GridLayout& g = t->layout();
  for (std::size_t iy = 0; iy < g.ny; ++iy)
    for (std::size_t ix = 0; ix < g.nx; ++ix) {
      if (t->heights().heights()[g.index(ix, iy)] == before[g.index(ix, iy)]) continue;
      EXPECT_TRUE(t->active_set().contains(g.index(ix, iy)));
      t->stencil().for_each(g, ix, iy, [&](std::size_t jx, std::size_t jy, int) {
        EXPECT_TRUE(t->active_set().contains(g.index(jx, jy)));
      });
    }
  SB_EXPECT_CHECK_OK(*t);
}

TYPED_TEST(GridStamp, SphereCapReachesItsProfile) {
  const Scene s = rim_scene({"tool.profile=\"sphere_cap\"", "tool.sphere_radius_m=0.05"});
  const auto t = make_grid<TypeParam>(s);
  const double v0 = t->volume();
  const ToolStamp st = stamp_at(s, {0.25, 0.25}, 0.085);
  const StampReport r = t->stamp(st);
  EXPECT_NEAR(r.volume_deposited_m3, r.volume_removed_m3, 1e-14 * r.volume_removed_m3);
  EXPECT_NEAR(t->volume(), v0, kVolumeTolerance<TypeParam> * v0);
  const GridLayout& g = t->layout();
  for (std::size_t iy = 0; iy < g.ny; ++iy)
    for (std::size_t ix = 0; ix < g.nx; ++ix) {
      const Vec2 p = g.position(ix, iy);
      if (!st.contains(p)) continue;
      EXPECT_NEAR(t->heights().z(ix, iy), std::min(kSand<TypeParam>, st.bottom_z(p)), 2e-8);
    }
}

// A box whose edges fall half way between nodes and a rim band narrower than that gap:
// the band holds no node, so the deposit goes to the nearest nodes outside instead.
TYPED_TEST(GridStamp, RimNarrowerThanACellStillReceivesTheVolume) {
  const Scene s = rim_scene({}, flat_scene("shape = \"box\"\nsize_m = [0.025, 0.025]\nrim_width_m = 0.001\n"));
  const auto t = make_grid<TypeParam>(s);
  const double v0 = t->volume();
  const ToolStamp st = stamp_at(s, {0.25, 0.25}, 0.09);
  const GridLayout& g = t->layout();
  for (std::size_t iy = 0; iy < g.ny; ++iy)
    for (std::size_t ix = 0; ix < g.nx; ++ix) ASSERT_EQ(st.rim_weight(g.position(ix, iy)), 0.0);

  const StampReport r = t->stamp(st);
  EXPECT_NEAR(r.volume_removed_m3, 0.025 * 0.025 * 0.01, 1e-9);  // 5 x 5 nodes, a full cell each
  EXPECT_NEAR(r.volume_deposited_m3, r.volume_removed_m3, 1e-14 * r.volume_removed_m3);
  EXPECT_NEAR(t->volume(), v0, kVolumeTolerance<TypeParam> * v0);
  EXPECT_GT(r.elements_touched, 25u);
  // The deposit lands on the ring of nodes just outside the box.
  EXPECT_GT(t->heights().z(g.nearest({0.25 + 0.015, 0.25})), kSand<TypeParam>);
  EXPECT_EQ(t->heights().z(g.nearest({0.25 + 0.03, 0.25})), kSand<TypeParam>);
  SB_EXPECT_CHECK_OK(*t);
}

TYPED_TEST(GridStamp, ToolAtTheDomainEdgeConservesVolume) {
  // Moving off the domain with every bit of rim bias forwards: the rim in front is clipped.
  const Scene s = rim_scene({"tool.rim_forward_bias=1.0"});
  const auto t = make_grid<TypeParam>(s);
  const double v0 = t->volume();
  for (const Vec2& xy : {Vec2(0.49, 0.25), Vec2(0.5, 0.5), Vec2(-0.02, 0.1), Vec2(0.25, 0.515)}) {
    const StampReport r = t->stamp(stamp_at(s, xy, 0.09, (xy - Vec2(0.25, 0.25)).normalized()));
    EXPECT_GT(r.volume_removed_m3, 0.0) << xy.transpose();
    EXPECT_NEAR(r.volume_deposited_m3, r.volume_removed_m3, 1e-14 * r.volume_removed_m3);
    EXPECT_NEAR(t->volume(), v0, kVolumeTolerance<TypeParam> * v0);
    SB_EXPECT_CHECK_OK(*t);
  }
}

TYPED_TEST(GridStamp, ToolLargerThanTheDomainCutsNothing) {
  const Scene s = rim_scene({}, flat_scene("shape = \"box\"\nsize_m = [2.0, 2.0]\n"));
  const auto t = make_grid<TypeParam>(s);
  const std::vector<TypeParam> before = t->heights().heights();
  const StampReport r = t->stamp(stamp_at(s, {0.25, 0.25}, 0.0));
  EXPECT_EQ(r.volume_removed_m3, 0.0);
  EXPECT_EQ(r.volume_deposited_m3, 0.0);
  EXPECT_EQ(r.elements_touched, 0u);
  EXPECT_EQ(t->heights().heights(), before);
  EXPECT_EQ(t->stats().active, 0u);
}

TYPED_TEST(GridStamp, ToolAboveTheSurfaceCutsNothing) {
  const Scene s = rim_scene();
  const auto t = make_grid<TypeParam>(s);
  const StampReport r = t->stamp(stamp_at(s, {0.25, 0.25}, 0.2));
  EXPECT_EQ(r.volume_removed_m3, 0.0);
  EXPECT_EQ(r.elements_touched, 0u);
  EXPECT_EQ(t->stats().active, 0u);
}

TYPED_TEST(GridStamp, PourAddsExactlyItsVolume) {
  const Scene s = scene({}, flat_scene("shape = \"pour\"\nradius_m = 0.02\nvolume_m3 = 1e-4\n"));
  const auto t = make_grid<TypeParam>(s);
  double expected = t->volume();
  // Inside, at the border, outside the domain, and narrower than a cell.
  const std::vector<std::pair<Vec2, double>> pours = {
      {{0.25, 0.25}, 0.0201}, {{0.0, 0.31}, 0.02}, {{0.7, -0.2}, 0.02}, {{0.1234, 0.3456}, 0.001}};
  for (const auto& [xy, radius] : pours) {
    ToolSpec spec = s.tool;
    spec.radius_m = radius;
    ToolPose pose;
    pose.xy = xy;
    const StampReport r = t->stamp(make_stamp(spec, pose, Vec2::Zero(), 0));
    EXPECT_EQ(r.volume_removed_m3, 0.0);
    EXPECT_NEAR(r.volume_deposited_m3, 1e-4, 1e-18);
    EXPECT_GE(r.elements_touched, 1u);
    expected += 1e-4;
    EXPECT_NEAR(t->volume(), expected, kVolumeTolerance<TypeParam> * expected) << xy.transpose();
    SB_EXPECT_CHECK_OK(*t);
  }
}

// The sand lands as a cone of the pour radius handed to the nodes by their bilinear weights:
// centred on the pour point wherever it lies between nodes, within the radius and a cell of it,
// highest at the node nearest to it. (Spread evenly over the nodes within the radius, these
// pours landed centred 0.2 to 1.7 mm off their points on this 5 mm grid.)
TYPED_TEST(GridStamp, APourLandsCentredOnItsPoint) {
  const Scene s = scene({}, flat_scene("shape = \"pour\"\nradius_m = 0.02\nvolume_m3 = 1e-4\n"));
  for (const auto& [xy, radius] : std::vector<std::pair<Vec2, double>>{
           {{0.25, 0.25}, 0.02}, {{0.2512, 0.2471}, 0.02}, {{0.1234, 0.3456}, 0.0123}, {{0.3011, 0.1987}, 0.001}}) {
    const auto t = make_grid<TypeParam>(s);
    ToolSpec spec = s.tool;
    spec.radius_m = radius;
    ToolPose pose;
    pose.xy = xy;
    t->stamp(make_stamp(spec, pose, Vec2::Zero(), 0));
    const GridLayout& g = t->layout();
    double mass = 0.0, peak = 0.0;
    Vec2 moment(0.0, 0.0);
    std::uint32_t peak_node = 0;
    for (std::uint32_t k = 0; k < g.nodes(); ++k) {
      const double m = (t->heights().z(k) - kSand<TypeParam>)*g.area(k);
      if (m == 0.0) continue;
      const auto [ix, iy] = g.split(k);
      const Vec2 p = g.position(ix, iy);
      EXPECT_LE((p - xy).norm(), radius + g.diagonal()) << "sand beyond the radius and a cell";
      mass += m;
      moment += m * p;
      if (m > peak) peak = m, peak_node = k;
    }
    EXPECT_NEAR(mass, 1e-4, sizeof(TypeParam) == 8 ? 1e-17 : 1e-11);
    EXPECT_LT((moment / mass - xy).norm(), sizeof(TypeParam) == 8 ? 1e-12 : 1e-6) << xy.transpose();
    if (radius > g.dx) {
      EXPECT_EQ(peak_node, g.nearest(xy)) << xy.transpose();
    }
  }
}

}  // namespace
}  // namespace sb::grid::test
