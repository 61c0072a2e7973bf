// The grid as a model of a surface: layout, interpolation, exact volume, mesh, stats.
#include <cmath>
#include <limits>

#include "grid_test_support.hpp"

namespace sb::grid::test {
namespace {

TEST(GridLayout, CoversTheDomainExactlyWithNearlySquareCells) {
  const Aabb2 domain{{0.2, -0.1}, {0.2 + 0.7071067811865476, -0.1 + 0.35}};
  const GridLayout g = GridLayout::covering(domain, 0.005);
  EXPECT_EQ(g.nx, 142u);  // round(141.42) + 1
  EXPECT_EQ(g.ny, 71u);   // 70 + 1
  EXPECT_NEAR(g.position(g.nx - 1, g.ny - 1).x(), domain.hi.x(), 1e-12);
  EXPECT_NEAR(g.position(g.nx - 1, g.ny - 1).y(), domain.hi.y(), 1e-12);
  EXPECT_NE(g.dx, g.dy);
  EXPECT_NEAR(g.diagonal(), std::hypot(g.dx, g.dy), 1e-15);
  // Area weights sum to the domain's area.
  double area = 0.0;
  for (std::size_t iy = 0; iy < g.ny; ++iy)
    for (std::size_t ix = 0; ix < g.nx; ++ix) area += g.area(ix, iy);
  EXPECT_NEAR(area, 0.7071067811865476 * 0.35, 1e-13);
  EXPECT_DOUBLE_EQ(g.area(0, 0), 0.25 * g.dx * g.dy);
  EXPECT_DOUBLE_EQ(g.area(0, 5), 0.5 * g.dx * g.dy);
  EXPECT_DOUBLE_EQ(g.area(7, 5), g.dx * g.dy);
}

TEST(GridLayout, TinyDomainStillHasTwoNodesPerAxis) {
  const GridLayout g = GridLayout::covering({{0.0, 0.0}, {0.001, 0.001}}, 0.01);
  EXPECT_EQ(g.nx, 2u);
  EXPECT_EQ(g.ny, 2u);
  EXPECT_DOUBLE_EQ(g.dx, 0.001);
}

TEST(GridLayout, NodesInBoxAreClippedAndClosed) {
  const GridLayout g = GridLayout::covering({{0.0, 0.0}, {1.0, 1.0}}, 0.1);  // 11 x 11
  NodeRange r = g.nodes_in({{0.15, -5.0}, {0.3, 0.2}});
  ASSERT_FALSE(r.empty);
  EXPECT_EQ(r.x0, 2u);
  EXPECT_EQ(r.x1, 3u);
  EXPECT_EQ(r.y0, 0u);
  EXPECT_EQ(r.y1, 2u);
  EXPECT_TRUE(g.nodes_in({{1.5, 0.0}, {2.0, 1.0}}).empty);
  EXPECT_TRUE(g.nodes_in({{0.11, 0.11}, {0.19, 0.19}}).empty);  // between nodes
  EXPECT_EQ(g.nodes_in({{-1.0, -1.0}, {2.0, 2.0}}).count(), 121u);
  EXPECT_EQ(g.nearest({0.26, 5.0}), g.index(3, 10));
}

template <class Real>
class GridModel : public ::testing::Test {};
TYPED_TEST_SUITE(GridModel, StorageTypes, StorageName);

// The trapezoid weights integrate the bilinear interpolant exactly, so any surface of the
// form a + bx + cy + dxy has its analytic volume.
TYPED_TEST(GridModel, VolumeIsTheExactIntegralOfABilinearSurface) {
  const Scene s = scene({"domain.size_m=[0.7071067811865476, 0.3]", "domain.origin_m=[0.1, 0.2]"});
  const auto z = [](const Vec2& p) { return 0.25 + 0.5 * p.x() + 0.125 * p.y() + 0.5 * p.x() * p.y(); };
  const auto t = make_grid<TypeParam>(s, z);
  const double x0 = 0.1, x1 = 0.1 + 0.7071067811865476, y0 = 0.2, y1 = 0.5;
  const double w = x1 - x0, h = y1 - y0;
  const double exact = 0.25 * w * h + 0.5 * (x1 * x1 - x0 * x0) / 2 * h + 0.125 * (y1 * y1 - y0 * y0) / 2 * w +
                       0.5 * (x1 * x1 - x0 * x0) / 2 * (y1 * y1 - y0 * y0) / 2;
  // Float storage rounds each height once: relative error ~6e-8 at most, far less on average.
  const double tol = sizeof(TypeParam) == 8 ? 1e-14 : 1e-7;
  EXPECT_NEAR(t->volume(), exact, tol * exact);
  // And the interpolant reproduces the surface between nodes.
  EXPECT_NEAR(t->height({0.3337, 0.4123}), z({0.3337, 0.4123}), sizeof(TypeParam) == 8 ? 1e-14 : 1e-6);
}

TYPED_TEST(GridModel, HeightIsBilinearAndClampedToTheDomain) {
  const Scene s = scene({"terrain.kind=\"dunes\"", "terrain.amplitude_m=0.03"});
  const auto t = make_grid<TypeParam>(s);
  const GridLayout& g = t->layout();
  // At a node: the node's height.
  EXPECT_EQ(t->height(g.position(17, 23)), t->heights().z(17, 23));
  // Half way along an edge: the mean of its two nodes.
  const Vec2 mid = 0.5 * (g.position(17, 23) + g.position(18, 23));
  EXPECT_NEAR(t->height(mid), 0.5 * (t->heights().z(17, 23) + t->heights().z(18, 23)), 1e-15);
  // Outside the domain: the nearest border point.
  EXPECT_EQ(t->height({-1.0, -1.0}), t->heights().z(0, 0));
  EXPECT_EQ(t->height({9.0, g.position(0, 40).y()}), t->heights().z(g.nx - 1, 40));
}

TYPED_TEST(GridModel, SampleAgreesWithHeight) {
  const Scene s = scene({"terrain.kind=\"dunes\""});
  const auto t = make_grid<TypeParam>(s);
  t->stamp(stamp_at(s, {0.2, 0.3}, 0.08));
  Raster r = Raster::covering({{-0.01, 0.003}, {0.49, 0.51}}, 0.0033);  // off the grid's lattice
  ASSERT_GT(r.nx * r.ny, 10000u);
  t->sample(r);
  for (std::size_t iy = 0; iy < r.ny; ++iy)
    for (std::size_t ix = 0; ix < r.nx; ++ix) ASSERT_EQ(r.at(ix, iy), t->height(r.point(ix, iy)));
  SB_EXPECT_CHECK_OK(*t);
}

TYPED_TEST(GridModel, MeshHasEveryNodeAndTwoTrianglesPerCell) {
  const Scene s = scene({"domain.size_m=[0.5, 0.3]"});
  const auto t = make_grid<TypeParam>(s);
  t->stamp(stamp_at(s, {0.25, 0.15}, 0.09));
  const SurfaceMesh m = t->mesh();
  const GridLayout& g = t->layout();
  ASSERT_EQ(m.vertices.size(), g.nx * g.ny);
  ASSERT_EQ(m.triangles.size(), 2 * (g.nx - 1) * (g.ny - 1));
  EXPECT_TRUE(m.constrained_edges.empty());
  double area = 0.0;
  for (const auto& tri : m.triangles) {
    for (std::uint32_t v : tri) ASSERT_LT(v, m.vertices.size());
    const Vec3& a = m.vertices[tri[0]];
    const Vec3& b = m.vertices[tri[1]];
    const Vec3& c = m.vertices[tri[2]];
    const double signed_area = 0.5 * cross2((b - a).head<2>(), (c - a).head<2>());
    ASSERT_GT(signed_area, 0.0);  // counter-clockwise from above
    area += signed_area;
  }
  EXPECT_NEAR(area, 0.5 * 0.3, 1e-12);
  EXPECT_EQ(m.vertices[g.index(20, 10)].z(), t->heights().z(20, 10));
}

TYPED_TEST(GridModel, StatsCountNodesAndBytes) {
  const Scene s = scene();
  const auto t = make_grid<TypeParam>(s);
  const GridLayout& g = t->layout();
  ModelStats st = t->stats();
  EXPECT_EQ(st.cells, g.nx * g.ny);
  EXPECT_EQ(st.vertices, 0u);
  EXPECT_EQ(st.triangles, 0u);
  EXPECT_EQ(st.active, 0u);
  // Heights plus the active set: a 2-byte idle count and a bit per node (rows padded to
  // 64 bits), a 4-byte count per row. It does not grow with the number of members; a stamp adds
  // only the pile it leaves for the next to carry on (none from a stamp that does not move).
  const std::size_t fixed = g.nx * g.ny * (sizeof(TypeParam) + sizeof(std::uint16_t)) + g.ny * ((g.nx + 63) / 64) * 8 +
                            g.ny * sizeof(std::uint32_t);
  EXPECT_EQ(st.bytes, fixed);
  t->stamp(stamp_at(s, {0.25, 0.25}, 0.09));
  st = t->stats();
  EXPECT_GT(st.active, 0u);
  EXPECT_EQ(st.active, t->active_set().size());
  EXPECT_EQ(st.bytes, fixed + t->carried_pile().base.capacity() * sizeof(t->carried_pile().base[0]));
  t->erode(rule_of(s), {.max_passes = 3});
  EXPECT_EQ(t->stats().active, t->active_set().size());
  SB_EXPECT_CHECK_OK(*t);
}

TYPED_TEST(GridModel, SimplifyIsANoOp) {
  const Scene s = scene();
  const auto t = make_grid<TypeParam>(s);
  t->stamp(stamp_at(s, {0.25, 0.25}, 0.09));
  const std::vector<TypeParam> before = t->heights().heights();
  const SimplifyReport r = t->simplify({});
  EXPECT_EQ(r.candidates, 0u);
  EXPECT_EQ(r.removed, 0u);
  EXPECT_EQ(t->heights().heights(), before);
  EXPECT_EQ(t->name(), "grid");
}

TYPED_TEST(GridModel, MaxSlopeFollowsTheStencil) {
  // A plane rising 0.5 m per metre along x: 26.57 degrees between axis neighbours; along a
  // diagonal of a square cell the slope is smaller, so 4 and 8 neighbours agree.
  const auto plane = [](const Vec2& p) { return 0.5 * p.x(); };
  for (int n : {4, 8}) {
    const Scene s = scene({"grid.neighbours=" + std::to_string(n)});
    const auto t = make_grid<TypeParam>(s, plane);
    // Float heights near 0.35 m are good to 3e-8 m: 1e-4 of a degree over a 5 mm cell.
    EXPECT_NEAR(t->max_slope_deg(), rad_to_deg(std::atan(0.5)), 1e-3) << n << " neighbours";
  }
  // A single raised node: the slope to its axis neighbours is the steepest.
  const Scene s = scene();
  const GridLayout g = GridLayout::covering(s.domain.box(), s.grid.cell_m);
  const Vec2 peak = g.position(50, 50);
  const auto spike = [&](const Vec2& p) { return (p - peak).norm() < 1e-9 ? 0.005 : 0.0; };
  const auto t = make_grid<TypeParam>(s, spike);
  EXPECT_NEAR(t->max_slope_deg(), 45.0, 1e-4);
}

// Moving volume between random nodes of a float grid: each write rounds, the carry hands
// the error on, and the stored volume stays what it was to the last bit of the sum.
TEST(GridHeights, FloatWritesCarryTheirRoundingError) {
  const GridLayout g = GridLayout::covering({{0.0, 0.0}, {0.3, 0.2}}, 0.01);
  HeightGrid<float> h(g, [](const Vec2& p) { return 0.1 + 0.9 * p.x() * p.y(); });
  const double v0 = h.volume();
  std::uint64_t seed = 12345;
  const auto next = [&seed] { return (seed = seed * 6364136223846793005ULL + 1442695040888963407ULL) >> 11; };
  for (int i = 0; i < 100000; ++i) {
    const auto a = static_cast<std::uint32_t>(next() % g.nodes()), b = static_cast<std::uint32_t>(next() % g.nodes());
    if (a == b) continue;
    const double volume = 1e-9 * static_cast<double>(next() % 1000) / 1000.0;
    h.set(a, h.z(a) - volume / g.area(a));
    h.set(b, h.z(b) + volume / g.area(b));
  }
  EXPECT_NEAR(h.volume() + h.carry_m3(), v0, 1e-15 * v0);
  EXPECT_LE(std::abs(h.carry_m3()), 0.5 * std::numeric_limits<float>::epsilon() * g.dx * g.dy);
  EXPECT_NEAR(h.volume(), v0, 1e-14 * v0);
}

TEST(GridFactory, FollowsTheSceneStorageNeighboursAndThreads) {
  const Scene sd = scene();
  const auto d = make_grid_terrain(sd, HeightField::from_scene(sd));
  const auto* dg = dynamic_cast<const GridTerrain<double>*>(d.get());
  ASSERT_NE(dg, nullptr);
  EXPECT_EQ(dg->stencil().size, 8);
  EXPECT_EQ(dg->layout().nx, 101u);
  EXPECT_EQ(dg->threads(), 1u);

  const Scene sf = scene({"grid.storage=float", "grid.neighbours=4", "grid.threads=2"});
  const auto f = make_grid_terrain(sf, HeightField::from_scene(sf));
  const auto* fg = dynamic_cast<const GridTerrain<float>*>(f.get());
  ASSERT_NE(fg, nullptr);
  EXPECT_EQ(fg->stencil().size, 4);
  EXPECT_EQ(fg->threads(), 2u);
  EXPECT_NEAR(f->volume(), 0.5 * 0.5 * 0.1, 1e-9);
  SB_EXPECT_CHECK_OK(*f);
}

TEST(GridFactory, RejectsABadStencil) {
  const Scene s = scene();
  const GridLayout g = GridLayout::covering(s.domain.box(), s.grid.cell_m);
  const auto zero = [](const Vec2&) { return 0.0; };
  EXPECT_THROW(GridTerrain<double>(g, zero, 6, 2), std::invalid_argument);
  EXPECT_THROW(GridTerrain<float>(g, zero, 8, 0), std::invalid_argument);
}

}  // namespace
}  // namespace sb::grid::test
