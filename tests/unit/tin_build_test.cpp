// Construction and queries of the TIN: flat scenes are 2 triangles, greedy insertion
// follows the terrain's detail, the triangulation is Delaunay, heights interpolate.
#include <filesystem>
#include <functional>
#include <map>
#include <random>
#include <set>

#include "common/input_error.hpp"
#include "common/png_io.hpp"
#include "tests/unit/tin_test_support.hpp"

namespace sb::tin::test {
namespace {

TEST(TinBuild, FlatSceneIsFourCornersAndTwoTriangles) {
  const Scene s = scene();
  auto t = make(s);
  const ModelStats st = t->stats();
  EXPECT_EQ(st.vertices, 4u);
  EXPECT_EQ(st.triangles, 2u);
  EXPECT_EQ(st.constrained_edges, 0u);
  EXPECT_EQ(st.active, 0u);
  EXPECT_NEAR(t->volume(), 0.5 * 0.5 * 0.1, 1e-15);
  EXPECT_DOUBLE_EQ(t->height({0.123, 0.456}), 0.1);
  EXPECT_EQ(t->max_slope_deg(), 0.0);
  SB_EXPECT_TIN_OK(*t);
}

TEST(TinBuild, GreedyInsertionFollowsTheTerrainsDetail) {
  const Scene fine = scene(kDunesScene, {"tin.tolerance_m=0.0005"});
  const Scene coarse = scene(kDunesScene, {"tin.tolerance_m=0.002"});
  const HeightField field = HeightField::from_scene(fine);
  auto t_fine = make_tin_terrain(fine, field);
  auto t_coarse = make_tin_terrain(coarse, field);
  SB_EXPECT_TIN_OK(*t_fine);
  SB_EXPECT_TIN_OK(*t_coarse);
  const std::size_t n_fine = t_fine->stats().vertices, n_coarse = t_coarse->stats().vertices;
  EXPECT_GT(n_coarse, 20u);
  EXPECT_GT(n_fine, 2 * n_coarse) << "a 4x tighter tolerance needs more vertices";
  // The error bound holds at the sample lattice; between samples it may exceed it a little.
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 0.5);
  double worst_fine = 0.0, worst_coarse = 0.0, sum_fine = 0.0;
  const int n = 4000;
  for (int i = 0; i < n; ++i) {
    const Vec2 p(u(rng), u(rng));
    const double e = std::abs(t_fine->height(p) - field(p));
    worst_fine = std::max(worst_fine, e);
    sum_fine += e;
    worst_coarse = std::max(worst_coarse, std::abs(t_coarse->height(p) - field(p)));
  }
  EXPECT_LT(worst_fine, 2.0 * 0.0005);
  EXPECT_LT(sum_fine / n, 0.5 * 0.0005);
  EXPECT_LT(worst_coarse, 2.0 * 0.002);
}

TEST(TinBuild, HeightmapSceneIsBuiltWithinTolerance) {
  // A 33 x 33 heightmap: a ramp plus a bump.
  Png16 img;
  img.width = img.height = 33;
  img.values.resize(33 * 33);
  for (std::size_t r = 0; r < 33; ++r)
    for (std::size_t c = 0; c < 33; ++c) {
      const double x = c / 32.0, y = r / 32.0;
      const double v = 0.3 * x + 0.5 * std::exp(-((x - 0.5) * (x - 0.5) + (y - 0.5) * (y - 0.5)) / 0.02);
      img.values[r * 33 + c] = static_cast<std::uint16_t>(std::lround(std::min(1.0, v) * 65535.0));
    }
  const auto path = std::filesystem::temp_directory_path() / "sb_tin_build_test_heightmap.png";
  write_png16(path, img);
  const std::string text = std::string(R"(
[domain]
size_m = [0.4, 0.4]
[terrain]
kind = "heightmap"
path = ")") + path.string() +
                           R"("
vertical_scale_m = 0.05
[tool]
radius_m = 0.02
[stroke]
path_m = [[0.2, 0.2]]
[tin]
tolerance_m = 0.0005
)";
  const Scene s = parse_scene(text, "heightmap-test");
  const HeightField field = HeightField::from_scene(s);
  auto t = make_tin_terrain(s, field);
  SB_EXPECT_TIN_OK(*t);
  EXPECT_GT(t->stats().vertices, 10u);
  EXPECT_LT(t->stats().vertices, 33u * 33u);
  for (std::size_t r = 0; r < 33; ++r)
    for (std::size_t c = 0; c < 33; ++c) {
      const Vec2 p(0.4 * c / 32.0, 0.4 * r / 32.0);
      EXPECT_NEAR(t->height(p), field(p), 0.0005 + 1e-12);
    }
  std::filesystem::remove(path);
}

// A 35-degree cone of 2e-5 m^3 on a 0.3 m bed 5 cm deep (cone.toml), or, with `kind` "dunes",
// dunes of the same bed.
std::string sand_terrain_scene(const std::string& terrain) {
  return R"(
[domain]
size_m = [0.3, 0.3]
[terrain]
height_m = 0.05
)" + terrain +
         R"(
[tool]
radius_m = 0.02
[stroke]
path_m = [[0.15, 0.15]]
)";
}

// The integral of (TIN - terrain) and of its square over the domain, by the midpoint rule on
// a k x k lattice.
std::pair<double, double> integrated_error(const Terrain& t, const HeightField& field, double size, int k) {
  double sum = 0.0, sum2 = 0.0;
  const double h = size / k;
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j) {
      const Vec2 p((i + 0.5) * h, (j + 0.5) * h);
      const double e = t.height(p) - field(p);
      sum += e * h * h;
      sum2 += e * e * h * h;
    }
  return {sum, std::sqrt(sum2 / (size * size))};
}

// Interpolating the terrain at the vertices errs to one side where it bends (a cone's level
// lines are circles, their chords lie inside): cone.toml's TIN held 2.7 % less sand than the
// terrain. The heights are the terrain's L2 projection onto the mesh: its sand, a smaller
// mean-square error (cone 64.6 -> 44.0 um on the run's raster), planes exact.
TEST(TinBuild, TheInitialTinHoldsTheTerrainsSand) {
  const Scene cone =
      parse_scene(sand_terrain_scene("kind = \"cone\"\nslope_deg = 35.0\nvolume_m3 = 2e-5\n"), "cone", {});
  const HeightField cone_field = HeightField::from_scene(cone);
  auto t = make_tin_terrain(cone, cone_field);
  SB_EXPECT_TIN_OK(*t);
  const double sand = t->volume() - 0.3 * 0.3 * 0.05;
  EXPECT_NEAR(sand, 2e-5, 2e-5 * 1e-5) << "interpolated: 1.944e-5";
  // A cone much smaller than the triangles a 2 mm tolerance leaves around it: the quadrature
  // cuts them to the terrain's detail (three points a triangle missed 5 % of this sand).
  const Scene small = parse_scene(sand_terrain_scene("kind = \"cone\"\nslope_deg = 35.0\nvolume_m3 = 1e-6\n"),
                                  "small cone", {"tin.tolerance_m=0.002"});
  auto ts = make_tin_terrain(small, HeightField::from_scene(small));
  EXPECT_NEAR(ts->volume() - 0.3 * 0.3 * 0.05, 1e-6, 1e-6 * 1e-3);  // measured 1.3e-4
  const auto [cone_bias, cone_rms] = integrated_error(*t, cone_field, 0.3, 1500);
  RecordProperty("cone_rms_um", std::to_string(cone_rms * 1e6));
  EXPECT_LT(std::abs(cone_bias), 2e-5 * 2e-3);  // the midpoint rule's own error at the kinks
  EXPECT_LT(cone_rms, 55e-6) << "interpolated: 65 um";

  // Dunes on a jittered lattice of initial points: the same projection.
  const Scene dunes = parse_scene(sand_terrain_scene("kind = \"dunes\"\namplitude_m = 0.02\nwavelength_m = 0.1\n"),
                                  "dunes", {"tin.initial_points=3000"});
  const HeightField dunes_field = HeightField::from_scene(dunes);
  auto d = make_tin_terrain(dunes, dunes_field);
  SB_EXPECT_TIN_OK(*d);
  const auto [dunes_bias, dunes_rms] = integrated_error(*d, dunes_field, 0.3, 1500);
  RecordProperty("dunes_bias_m3", std::to_string(dunes_bias));
  RecordProperty("dunes_rms_um", std::to_string(dunes_rms * 1e6));
  EXPECT_LT(std::abs(dunes_bias), 1e-8);

  // A plane keeps its exact heights.
  const Scene plane =
      parse_scene(sand_terrain_scene("kind = \"plane\"\nslope_deg = 20.0\n"), "plane", {"tin.initial_points=500"});
  const HeightField plane_field = HeightField::from_scene(plane);
  auto p = make_tin_terrain(plane, plane_field);
  for (const Vec3& v : p->mesh().vertices) EXPECT_EQ(v.z(), plane_field(v.head<2>()));
}

std::vector<Vec3> jittered_points(std::size_t n, double size, std::uint64_t seed,
                                  const std::function<double(const Vec2&)>& z) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.05, 0.95);
  const auto side = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(n))));
  const double cell = size / static_cast<double>(side);
  std::vector<Vec3> pts;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 p((static_cast<double>(i % side) + u(rng)) * cell, (static_cast<double>(i / side) + u(rng)) * cell);
    pts.emplace_back(p.x(), p.y(), z(p));
  }
  return pts;
}

// The empty-circle test on the exported mesh (O(triangles * vertices)).
std::size_t non_delaunay_triangles(const SurfaceMesh& m, double rel_tolerance) {
  std::size_t bad = 0;
  for (const auto& tri : m.triangles) {
    const Vec2 a = m.vertices[tri[0]].head<2>(), b = m.vertices[tri[1]].head<2>(), c = m.vertices[tri[2]].head<2>();
    const Vec2 ab = b - a, ac = c - a;
    const double d = 2.0 * cross2(ab, ac);
    const Vec2 centre = a + Vec2(ac.y() * ab.squaredNorm() - ab.y() * ac.squaredNorm(),
                                 ab.x() * ac.squaredNorm() - ac.x() * ab.squaredNorm()) /
                                d;
    const double r2 = (centre - a).squaredNorm();
    for (std::size_t k = 0; k < m.vertices.size(); ++k) {
      if (k == tri[0] || k == tri[1] || k == tri[2]) continue;
      if ((m.vertices[k].head<2>() - centre).squaredNorm() < r2 * (1.0 - rel_tolerance)) {
        ++bad;
        break;
      }
    }
  }
  return bad;
}

TEST(TinBuild, FromPointsIsTheDelaunayTriangulationOfThePoints) {
  const Scene s = scene();
  const auto pts = jittered_points(400, 0.5, 11, [](const Vec2& p) { return 0.1 + 0.05 * p.x(); });
  auto t = make_tin_terrain_from_points(s, pts);
  SB_EXPECT_TIN_OK(*t);
  EXPECT_EQ(t->stats().vertices, 404u);
  const SurfaceMesh m = t->mesh();
  EXPECT_EQ(m.triangles.size(), t->stats().triangles);
  EXPECT_EQ(non_delaunay_triangles(m, 1e-9), 0u);
  for (const Vec3& p : pts) EXPECT_NEAR(t->height(p.head<2>()), p.z(), 1e-15);
}

TEST(TinBuild, DelaunayAwayFromConstraintsAfterStamps) {
  const Scene s = scene();
  const auto pts = jittered_points(900, 0.5, 5, [](const Vec2& p) { return 0.1 + 0.02 * std::sin(20.0 * p.x()); });
  auto t = make_tin_terrain_from_points(s, pts);
  for (int k = 0; k < 5; ++k) t->stamp(stamp_at(s, {0.2 + 0.01 * k, 0.25}, 0.09, {1, 0}, k));
  SB_EXPECT_TIN_OK(*t);  // includes CGAL's constrained Delaunay test of every edge
  // Locally Delaunay across every unconstrained edge (equivalent to constrained Delaunay).
  const SurfaceMesh m = t->mesh();
  ASSERT_GT(m.constrained_edges.size(), 0u);
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<std::uint32_t>> apex;
  for (const auto& tri : m.triangles)
    for (int i = 0; i < 3; ++i) {
      const std::uint32_t a = tri[(i + 1) % 3], b = tri[(i + 2) % 3];
      apex[{std::min(a, b), std::max(a, b)}].push_back(tri[i]);
    }
  std::set<std::pair<std::uint32_t, std::uint32_t>> constrained;
  for (const auto& e : m.constrained_edges) constrained.insert({std::min(e[0], e[1]), std::max(e[0], e[1])});
  std::size_t checked = 0, illegal = 0;
  for (const auto& [edge, apices] : apex) {
    if (apices.size() != 2 || constrained.count(edge)) continue;
    const Vec2 a = m.vertices[edge.first].head<2>(), b = m.vertices[edge.second].head<2>();
    const Vec2 c = m.vertices[apices[0]].head<2>(), d = m.vertices[apices[1]].head<2>();
    // d inside the circle through a, b, c (orientation-independent form).
    const Vec2 ad = a - d, bd = b - d, cd = c - d;
    const double det =
        ad.squaredNorm() * cross2(bd, cd) - bd.squaredNorm() * cross2(ad, cd) + cd.squaredNorm() * cross2(ad, bd);
    const double orient = cross2(b - a, c - a);
    const double scale = ad.squaredNorm() * bd.norm() * cd.norm() + 1e-300;
    if (det * (orient > 0 ? 1.0 : -1.0) > 1e-9 * scale) ++illegal;
    ++checked;
  }
  EXPECT_GT(checked, 1000u);
  EXPECT_EQ(illegal, 0u);
}

TEST(TinBuild, FromPointsRefusesBadPoints) {
  const Scene s = scene();
  EXPECT_THROW(make_tin_terrain_from_points(s, {Vec3(0.6, 0.1, 0.1)}), InputError);
  EXPECT_THROW(make_tin_terrain_from_points(s, {Vec3(std::nan(""), 0.1, 0.1)}), InputError);
  EXPECT_THROW(make_tin_terrain_from_points(s, {Vec3(0.1, 0.1, INFINITY)}), InputError);
  auto t = make_tin_terrain_from_points(s, {});
  EXPECT_EQ(t->stats().triangles, 2u);
}

TEST(TinBuild, HeightInterpolatesAndRefusesNonFiniteQueries) {
  const Scene s = scene();
  auto t = make_tin_terrain_from_points(s, {Vec3(0.25, 0.25, 0.3)});
  EXPECT_DOUBLE_EQ(t->height({0.25, 0.25}), 0.3);
  // Halfway from the centre to a corner (height 0.3 -> 0.3: corners take the nearest point's).
  EXPECT_NEAR(t->height({0.1, 0.1}), 0.3, 1e-12);
  // Outside the domain the height is the border's.
  EXPECT_NEAR(t->height({-1.0, 0.25}), t->height({0.0, 0.25}), 1e-15);
  EXPECT_THROW(t->height({std::nan(""), 0.1}), InputError);
  SB_EXPECT_TIN_OK(*t);
}

TEST(TinBuild, WalksFromTheLastLocatedFaceAreShort) {
  const Scene s = scene();
  auto t = make_tin_terrain_from_points(s, jittered_points(10000, 0.5, 2, [](const Vec2&) { return 0.1; }));
  const std::uint64_t before = t->stats().walk_steps;
  const int queries = 2000;
  for (int i = 0; i < queries; ++i) t->height({0.01 + 0.48 * i / queries, 0.25});
  const double per_query = static_cast<double>(t->stats().walk_steps - before) / queries;
  // Consecutive queries 0.24 mm apart on a 5 mm mesh: about one face each.
  EXPECT_LT(per_query, 3.0);
  EXPECT_GE(per_query, 1.0);
}

TEST(TinBuild, SampleAgreesWithHeight) {
  const Scene s = scene(kDunesScene);
  auto t = make(s);
  Raster r = Raster::covering(s.domain.box(), 0.01);
  t->sample(r);
  ASSERT_EQ(r.values.size(), r.nx * r.ny);
  for (std::size_t iy = 0; iy < r.ny; iy += 7)
    for (std::size_t ix = 0; ix < r.nx; ix += 5) EXPECT_DOUBLE_EQ(r.at(ix, iy), t->height(r.point(ix, iy)));
}

TEST(TinBuild, MeshExportMatchesStats) {
  const Scene s = scene(kDunesScene);
  auto t = make(s);
  t->stamp(stamp_at(s, {0.25, 0.25}, 0.07));
  const SurfaceMesh m = t->mesh();
  const ModelStats st = t->stats();
  EXPECT_EQ(m.vertices.size(), st.vertices);
  EXPECT_EQ(m.triangles.size(), st.triangles);
  EXPECT_EQ(m.constrained_edges.size(), st.constrained_edges);
  double volume = 0.0;
  for (const auto& tri : m.triangles) {
    const Vec3 &a = m.vertices[tri[0]], &b = m.vertices[tri[1]], &c = m.vertices[tri[2]];
    const double area = 0.5 * cross2((b - a).head<2>(), (c - a).head<2>());
    EXPECT_GT(area, 0.0) << "triangles are counter-clockwise";
    volume += area * (a.z() + b.z() + c.z()) / 3.0;
  }
  EXPECT_NEAR(volume, t->volume(), 1e-15);
}

}  // namespace
}  // namespace sb::tin::test
