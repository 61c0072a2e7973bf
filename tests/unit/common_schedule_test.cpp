#include <gtest/gtest.h>

#include <cmath>

#include "common/schedule.hpp"

namespace sb {
namespace {

ToolSpec disk() {
  ToolSpec t;
  t.shape = ToolShape::Disk;
  t.radius_m = 0.02;
  t.depth_m = 0.01;
  return t;
}

double flat(const Vec2&) { return 0.1; }

TEST(Schedule, StampsExactlyAtTheSpacingWithBothEnds) {
  Stroke s;
  s.path_m = {{0.0, 0.0}, {0.1, 0.0}};
  s.spacing_m = 0.03;  // 0.1 is not a whole number of spacings
  const StampSchedule sch = make_schedule(disk(), s, flat);
  ASSERT_EQ(sch.stamps.size(), 5u);  // 0, .03, .06, .09, .10
  EXPECT_DOUBLE_EQ(sch.stamps.front().pose.xy.x(), 0.0);
  EXPECT_DOUBLE_EQ(sch.stamps.back().pose.xy.x(), 0.1);
  for (std::size_t i = 1; i + 1 < sch.stamps.size(); ++i)
    EXPECT_NEAR((sch.stamps[i].pose.xy - sch.stamps[i - 1].pose.xy).norm(), 0.03, 1e-12);
  EXPECT_NEAR(sch.length_m, 0.1, 1e-15);
}

TEST(Schedule, WholeNumberOfSpacingsHasNoDuplicateEnd) {
  Stroke s;
  s.path_m = {{0.0, 0.0}, {0.1, 0.0}};
  s.spacing_m = 0.025;
  const StampSchedule sch = make_schedule(disk(), s, flat);
  ASSERT_EQ(sch.stamps.size(), 5u);
  EXPECT_DOUBLE_EQ(sch.stamps.back().pose.xy.x(), 0.1);
}

TEST(Schedule, SpacingFollowsArcLengthAroundCorners) {
  Stroke s;
  s.path_m = {{0.0, 0.0}, {0.05, 0.0}, {0.05, 0.05}};
  s.spacing_m = 0.02;
  const StampSchedule sch = make_schedule(disk(), s, flat);
  ASSERT_EQ(sch.stamps.size(), 6u);  // arc 0, .02, .04, .06, .08, .10
  EXPECT_NEAR(sch.stamps[3].pose.xy.x(), 0.05, 1e-12);
  EXPECT_NEAR(sch.stamps[3].pose.xy.y(), 0.01, 1e-12);
  EXPECT_NEAR(sch.stamps[3].motion_dir.y(), 1.0, 1e-12);
  EXPECT_NEAR(sch.stamps.back().pose.xy.y(), 0.05, 1e-12);
}

TEST(Schedule, DepthBelowInitialSurfaceOrZPerWaypoint) {
  Stroke s;
  s.path_m = {{0.0, 0.0}, {0.1, 0.0}};
  s.spacing_m = 0.05;
  auto slope = [](const Vec2& p) { return 0.1 + p.x(); };
  const StampSchedule a = make_schedule(disk(), s, slope);
  EXPECT_NEAR(a.stamps[1].pose.bottom_z, 0.1 + 0.05 - 0.01, 1e-15);
  s.z_m = {0.2, 0.0};
  const StampSchedule b = make_schedule(disk(), s, slope);
  EXPECT_NEAR(b.stamps[1].pose.bottom_z, 0.1, 1e-15);
}

TEST(Schedule, OnePointWithRepeatGivesIdenticalStampsAndGenerations) {
  Stroke s;
  s.path_m = {{0.3, 0.3}};
  s.repeat = 7;
  const StampSchedule sch = make_schedule(disk(), s, flat);
  ASSERT_EQ(sch.stamps.size(), 7u);
  for (std::size_t i = 0; i < 7; ++i) {
    EXPECT_EQ(sch.stamps[i].generation, i);
    EXPECT_EQ(sch.stamps[i].pose.xy, Vec2(0.3, 0.3));
  }
}

}  // namespace
}  // namespace sb
