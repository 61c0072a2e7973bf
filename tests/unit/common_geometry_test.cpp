#include <gtest/gtest.h>

#include "common/geometry.hpp"
#include "common/metrics.hpp"
#include "common/raster.hpp"

namespace sb {
namespace {

TEST(Geometry, PolygonBasics) {
  std::vector<Vec2> sq{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  EXPECT_DOUBLE_EQ(signed_area(sq), 1.0);
  EXPECT_TRUE(point_in_polygon(sq, {0.5, 0.5}));
  EXPECT_FALSE(point_in_polygon(sq, {1.5, 0.5}));
  EXPECT_DOUBLE_EQ(distance_to_boundary(sq, {0.5, 0.25}), 0.25);
  EXPECT_TRUE(is_simple_polygon(sq));
  std::vector<Vec2> bowtie{{0, 0}, {1, 1}, {1, 0}, {0, 1}};
  EXPECT_FALSE(is_simple_polygon(bowtie));
  std::vector<Vec2> cw(sq.rbegin(), sq.rend());
  EXPECT_DOUBLE_EQ(signed_area(make_ccw(cw)), 1.0);
}

TEST(Raster, CoversTheBoxAndInterpolatesBilinearly) {
  Raster r = Raster::covering({{0.0, 0.0}, {1.0, 0.5}}, 0.25);
  EXPECT_EQ(r.nx, 5u);
  EXPECT_EQ(r.ny, 3u);
  for (std::size_t iy = 0; iy < r.ny; ++iy)
    for (std::size_t ix = 0; ix < r.nx; ++ix) r.at(ix, iy) = 2.0 * r.point(ix, iy).x() + r.point(ix, iy).y();
  EXPECT_NEAR(r.interpolate({0.3, 0.1}), 0.7, 1e-12);
  EXPECT_NEAR(r.interpolate({1.0, 0.5}), 2.5, 1e-12);
  EXPECT_NEAR(r.interpolate({2.0, 0.5}), 2.5, 1e-12);  // clamped
}

TEST(Metrics, PercentileInterpolates) {
  EXPECT_DOUBLE_EQ(percentile({3.0, 1.0, 2.0, 4.0}, 0.5), 2.5);
  EXPECT_DOUBLE_EQ(percentile({5.0}, 0.95), 5.0);
  EXPECT_DOUBLE_EQ(percentile({}, 0.5), 0.0);
}

}  // namespace
}  // namespace sb

#include "common/point_sets.hpp"

namespace sb {
namespace {

TEST(PointSets, JitteredLatticeCoversTheDomainDeterministically) {
  DomainSpec d{{1e6, 2.0}, {0.7, 0.35}};
  const auto a = jittered_lattice(d, 200, 0.5, 3), b = jittered_lattice(d, 200, 0.5, 3);
  EXPECT_EQ(a, b);
  EXPECT_NEAR(static_cast<double>(a.size()), 200.0, 20.0);
  for (const Vec2& p : a) EXPECT_TRUE(d.box().contains(p));
  const auto exact = jittered_lattice(d, 200, 0.0, 3);
  EXPECT_EQ(exact.front(), d.origin_m);
  EXPECT_NE(a[30], exact[30]);  // an interior point moved
}

}  // namespace
}  // namespace sb
