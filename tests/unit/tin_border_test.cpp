// Stamps that cross the domain's border, one after another along a stroke: their contours
// meet the border at new points each time. Left at arbitrary distances, two border vertices a
// hair apart had tiny areas that throttled every transfer through them, and the stroke
// leaving the domain in the stability matrix never settled (44.7 degrees after 20000 passes).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

#include "tin_test_support.hpp"

namespace sb::tin::test {
namespace {

// The stroke runs out of the 0.5 m domain at x = 0.5 with stamps every 2.5 mm.
const std::vector<std::string> kLeaving = {"stroke.path_m=[[0.3, 0.25], [0.6, 0.25]]", "stroke.spacing_m=0.0025"};

TEST(TinBorder, AStrokeLeavingTheDomainSettles) {
  const Scene s = scene(kFlatScene, kLeaving);  // the default rule
  auto t = make(s);
  for (const ToolStamp& st : schedule_of(s).stamps) step(*t, s, st);
  EXPECT_TRUE(relax(*t, s, 20000));
  SB_EXPECT_TIN_OK(*t);
  EXPECT_LT(t->max_slope_deg(), s.material.critical_angle_deg + s.erosion.settle_tolerance_deg + 1e-6);
}

TEST(TinBorder, CrossingsDoNotCrowdTheBorder) {
  const Scene s = scene(kFlatScene, kLeaving);
  auto t = make(s);
  for (const ToolStamp& st : schedule_of(s).stamps) step(*t, s, st);
  // The border x = 0.5 between the stroke's crossings: neighbouring vertices on it.
  std::vector<double> ys;
  for (const Vec3& v : t->mesh().vertices)
    if (v.x() == 0.5) ys.push_back(v.y());
  std::sort(ys.begin(), ys.end());
  ASSERT_GT(ys.size(), 4u);
  double closest = 1.0;
  for (std::size_t i = 1; i < ys.size(); ++i) closest = std::min(closest, ys[i] - ys[i - 1]);
  // The contour gap is 5 % of the 2 cm radius (1 mm); crossings snap within a quarter of it.
  EXPECT_GT(closest, 0.25e-3 * 0.99);
}

// A pile poured on a narrow strip: the domain's first diagonal lies 1.9 degrees from the
// border, and halving edges at such angles again and again put vertices microns from it, the
// apices of slivers that throttled every transfer: the pile never settled (facets at 88 degrees
// after 20000 passes, 127 M updates). Middles that close to the border now go onto it.
TEST(TinBorder, APileOnANarrowStripSettles) {
  for (const char* width : {"0.01", "0.02"}) {
    SCOPED_TRACE(width);
    const double w = std::stod(width);
    const Scene s = scene(kPileScene, {std::string("domain.size_m=[0.3, ") + width + "]",
                                       "stroke.path_m=[[0.15, " + std::to_string(w / 2) + "]]"});
    auto t = make(s);
    for (const ToolStamp& st : schedule_of(s).stamps) step(*t, s, st);
    ASSERT_TRUE(relax(*t, s, 20000));
    SB_EXPECT_TIN_OK(*t);
    EXPECT_LT(t->max_slope_deg(), s.material.critical_angle_deg + s.erosion.settle_tolerance_deg + 1e-6);
    // No vertex a hair inside the long sides.
    for (const Vec3& v : t->mesh().vertices)
      EXPECT_TRUE(v.y() == 0.0 || v.y() == w || (v.y() > 1e-4 && v.y() < w - 1e-4)) << v.transpose();
  }
}

}  // namespace
}  // namespace sb::tin::test
