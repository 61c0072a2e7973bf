// TinTerrain::sample (tin/sample.cpp): rasterising the faces gives the heights height()'s walks
// give, at every raster point -- inside faces, on edges and vertices, beyond the domain -- and
// each route is taken where its cost says.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "common/raster.hpp"
#include "tin_test_support.hpp"

namespace sb::tin::test {
namespace {

// Every raster point against a walk to it (the walks end in either face on an edge: the two
// interpolations agree to a few units in the last place of heights ~0.1 m).
void expect_sample_matches_height(const Terrain& t, Raster r, const std::string& what) {
  t.sample(r);
  ASSERT_EQ(r.values.size(), r.nx * r.ny) << what;
  std::size_t bad = 0;
  for (std::size_t iy = 0; iy < r.ny; ++iy)
    for (std::size_t ix = 0; ix < r.nx; ++ix) {
      const double walked = t.height(r.point(ix, iy));
      if (!(std::abs(r.at(ix, iy) - walked) <= 1e-14) && bad++ < 5)
        ADD_FAILURE() << what << ": point (" << ix << ", " << iy << ") sampled " << r.at(ix, iy) << ", walked "
                      << walked;
    }
  EXPECT_EQ(bad, 0u) << what;
}

// Rasters that divide the domain, do not, start and end beyond it, and a coarse one (fewer
// points than a quarter of the faces: the walks' route).
void expect_all_rasters_match(const Terrain& t, const Scene& s, const std::string& what) {
  const Aabb2 box = s.domain.box();
  expect_sample_matches_height(t, Raster::covering(box, 0.005), what + ", 5 mm");
  expect_sample_matches_height(t, Raster::covering(box, 0.0037), what + ", 3.7 mm");
  const Aabb2 wider{box.lo - Vec2(0.013, 0.021), box.hi + Vec2(0.017, 0.011)};
  expect_sample_matches_height(t, Raster::covering(wider, 0.0041), what + ", beyond the domain");
  expect_sample_matches_height(t, Raster::covering(box, 0.1), what + ", coarse");
}

TEST(TinSample, MatchesHeightOnAHeightmapTin) {
  const Scene s = scene(kDunesScene);
  auto t = make(s);
  expect_all_rasters_match(*t, s, "dunes");
}

TEST(TinSample, MatchesHeightAfterStampsAndErosion) {
  const Scene s = scene(kFlatScene);
  auto t = make(s);
  for (const ToolStamp& st : schedule_of(s).stamps) step(*t, s, st);
  ASSERT_GT(t->stats().constrained_edges, 0u);
  expect_all_rasters_match(*t, s, "stroke");
}

TEST(TinSample, MatchesHeightOnAnInitialPointsTin) {
  const Scene s = scene(kDunesScene, {"tin.initial_points=3000"});
  auto t = make(s);
  ASSERT_GT(t->stats().vertices, 2900u);
  expect_all_rasters_match(*t, s, "initial points");
}

TEST(TinSample, MatchesHeightOnRingsOfPoints) {
  // Rings of points (and the domain's corners, which every TIN has): long thin faces between
  // the outer ring and the corners, fans of faces meeting at the rings.
  const Scene s = scene();
  std::vector<Vec3> pts;
  for (int i = 0; i < 40; ++i) {
    const double a = 2.0 * 3.14159265358979 * i / 40.0;
    for (double r : {0.05, 0.12, 0.2})
      pts.push_back({0.25 + r * std::cos(a), 0.25 + r * std::sin(a), 0.1 + 0.3 * r * std::sin(3.0 * a)});
  }
  auto t = make_tin_terrain_from_points(s, pts);
  SB_ASSERT_TIN_OK(*t);
  expect_all_rasters_match(*t, s, "points");
}

TEST(TinSample, VerticesGetTheirOwnHeights) {
  // A flat scene's TIN is its four corners: a raster through them hits them exactly.
  const Scene s = scene();
  auto t = make(s);
  Raster r = Raster::covering(s.domain.box(), 0.05);
  t->sample(r);
  EXPECT_EQ(r.at(0, 0), 0.1);
  EXPECT_EQ(r.at(r.nx - 1, r.ny - 1), 0.1);
}

TEST(TinSample, RasterisesDenseRastersAndWalksToSparseOnes) {
  const Scene s = scene(kDunesScene);
  auto t = make(s);
  const std::size_t faces = t->stats().triangles;
  Raster dense = Raster::covering(s.domain.box(), 0.0025);
  ASSERT_GT(dense.nx * dense.ny, faces);
  std::uint64_t before = t->stats().walk_steps;
  t->sample(dense);
  // Only points on edges that both faces' rounded tests declined are walked to.
  EXPECT_LT(t->stats().walk_steps - before, dense.nx * dense.ny / 100);
  Raster sparse = Raster::covering(s.domain.box(), 0.1);
  ASSERT_LT(4 * sparse.nx * sparse.ny, faces);
  before = t->stats().walk_steps;
  t->sample(sparse);
  EXPECT_GE(t->stats().walk_steps - before, sparse.nx * sparse.ny);
}

}  // namespace
}  // namespace sb::tin::test
