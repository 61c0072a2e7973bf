// The polygon helpers of common/geometry.hpp that stamps are built from: offsets, clipping,
// convexity, corner cutting, segment distances.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "common/geometry.hpp"

namespace sb {
namespace {

std::vector<Vec2> ngon(std::size_t n, double r, Vec2 c = {0.0, 0.0}) {
  std::vector<Vec2> p;
  for (std::size_t k = 0; k < n; ++k) {
    const double t = 2.0 * std::numbers::pi * static_cast<double>(k) / static_cast<double>(n);
    p.push_back(c + r * Vec2(std::cos(t), std::sin(t)));
  }
  return p;
}

TEST(Polygon, ConvexityNeedsOneLeftTurnAroundAndNoRightTurn) {
  EXPECT_TRUE(is_convex_polygon(ngon(5, 1.0)));
  EXPECT_TRUE(is_convex_polygon(std::vector<Vec2>{{0, 0}, {1, 0}, {1, 1}, {0, 1}}));
  EXPECT_FALSE(is_convex_polygon(std::vector<Vec2>{{0, 0}, {2, 0}, {1, 0.5}, {2, 2}, {0, 2}}));  // a notch
  // A pentagram turns left at every corner, but twice around.
  const std::vector<Vec2> p = ngon(5, 1.0);
  EXPECT_FALSE(is_convex_polygon(std::vector<Vec2>{p[0], p[2], p[4], p[1], p[3]}));
  std::vector<Vec2> cw = ngon(6, 1.0);
  std::reverse(cw.begin(), cw.end());
  EXPECT_FALSE(is_convex_polygon(cw));
}

TEST(Polygon, OffsetKeepsTheGapFromEveryEdge) {
  for (const std::vector<Vec2>& poly : {ngon(16, 0.02), std::vector<Vec2>{{0, 0}, {3, 0}, {3, 1}, {0, 1}}}) {
    const double gap = 0.001;
    const std::vector<Vec2> out = offset_polygon(poly, gap);
    ASSERT_EQ(out.size(), poly.size());
    for (const Vec2& q : out) {
      EXPECT_FALSE(point_in_polygon(poly, q));
      // The mitre point is at the gap from both edges of its corner, the nearest ones.
      EXPECT_GE(distance_to_boundary(poly, q), gap * (1.0 - 1e-9));
    }
    EXPECT_GT(signed_area(out), signed_area(poly));
    EXPECT_TRUE(is_convex_polygon(out));
  }
  // A needle's mitre is cut to 4 gaps.
  const std::vector<Vec2> needle{{0, 0}, {1, 0}, {0, 0.01}};
  for (const Vec2& q : offset_polygon(needle, 0.01)) EXPECT_LE(distance_to_boundary(needle, q), 0.04 + 1e-12);
}

TEST(Polygon, ClippingToABoxPutsCutPointsExactlyOnItsSides) {
  const Aabb2 box{{0.0, 0.0}, {1.0, 1.0}};
  const std::vector<Vec2> square{{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}};
  const std::vector<Vec2> clipped = clip_to_box(square, box);
  EXPECT_NEAR(std::abs(signed_area(clipped)), 0.25, 1e-15);
  for (const Vec2& p : clipped) EXPECT_TRUE(box.contains(p));
  std::size_t on_sides = 0;
  for (const Vec2& p : clipped) on_sides += p.x() == 0.0 || p.y() == 0.0;
  EXPECT_GE(on_sides, 3u);
  EXPECT_TRUE(clip_to_box(ngon(8, 0.1, {3.0, 3.0}), box).empty());
  const std::vector<Vec2> inside = ngon(8, 0.1, {0.5, 0.5});
  EXPECT_EQ(clip_to_box(inside, box), inside);
  EXPECT_TRUE(on_same_box_side({0.0, 0.2}, {0.0, 0.7}, box));
  EXPECT_FALSE(on_same_box_side({0.0, 0.2}, {0.3, 0.0}, box));
}

TEST(Polygon, NearDuplicatesGoCyclically) {
  std::vector<Vec2> p{{0, 0}, {1e-13, 0}, {1, 0}, {1, 1}, {0, 1e-13}};
  drop_near_duplicates(p, 1e-12);
  EXPECT_EQ(p.size(), 3u);
}

TEST(Polygon, SegmentDistances) {
  EXPECT_DOUBLE_EQ(distance_between_segments({0, 0}, {1, 1}, {0, 1}, {1, 0}), 0.0);  // crossing
  EXPECT_DOUBLE_EQ(distance_between_segments({0, 0}, {1, 0}, {0, 2}, {1, 2}), 2.0);  // parallel
  EXPECT_DOUBLE_EQ(distance_between_segments({0, 0}, {1, 0}, {2, 1}, {3, 5}), std::sqrt(2.0));
  const std::vector<Vec2> square{{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  EXPECT_TRUE(segment_near_polygon({0.4, 0.4}, {0.6, 0.6}, square, 0.0));  // inside
  EXPECT_TRUE(segment_near_polygon({1.05, -1}, {1.05, 2}, square, 0.1));
  EXPECT_FALSE(segment_near_polygon({1.2, -1}, {1.2, 2}, square, 0.1));
}

TEST(Polygon, CornersCutEvenlyToTheSameArea) {
  const std::vector<Vec2> disk = ngon(32, 0.02, {0.3, 0.2});
  EXPECT_EQ(corners_to_keep(32, 13, 64), 16u);
  EXPECT_EQ(corners_to_keep(4096, 13, 64), 16u);
  EXPECT_EQ(corners_to_keep(4096, 100, 64), 64u);
  EXPECT_EQ(corners_to_keep(37, 13, 64), 37u);    // a prime: all, when within the limit
  EXPECT_EQ(corners_to_keep(4093, 13, 64), 13u);  // else as wanted, unevenly
  EXPECT_EQ(corners_to_keep(12, 13, 64), 12u);
  EXPECT_EQ(corners_to_keep(16, 13, 64), 16u);
  const std::vector<Vec2> cut = fewer_corners(disk, 16);
  ASSERT_EQ(cut.size(), 16u);
  EXPECT_TRUE(is_convex_polygon(cut));
  EXPECT_NEAR(signed_area(cut), signed_area(disk), 1e-15);
  // Regular in, regular out: every edge of the same length.
  for (std::size_t i = 0; i < cut.size(); ++i)
    EXPECT_NEAR((cut[(i + 1) % 16] - cut[i]).norm(), (cut[1] - cut[0]).norm(), 1e-15);
  EXPECT_EQ(fewer_corners(disk, 40), disk);
  EXPECT_NEAR(perimeter(std::vector<Vec2>{{0, 0}, {2, 0}, {2, 1}, {0, 1}}), 6.0, 1e-15);
}

TEST(Polygon, BoxesUniteAndIntersect) {
  const Aabb2 a{{0, 0}, {2, 1}}, b{{1, -1}, {3, 0.5}};
  const Aabb2 u = united(a, b), i = intersection(a, b);
  EXPECT_EQ(u.lo, Vec2(0, -1));
  EXPECT_EQ(u.hi, Vec2(3, 1));
  EXPECT_EQ(i.lo, Vec2(1, 0));
  EXPECT_EQ(i.hi, Vec2(2, 0.5));
}

}  // namespace
}  // namespace sb
