// Inputs found by the stamp fuzzer (tests/fuzz/stamp_fuzz.cpp) that once broke the TIN.
#include <gtest/gtest.h>

#include "harness/run/backends.hpp"
#include "harness/run/runner.hpp"

namespace sb {
namespace {

// A 5.1 cm disk whose footprint only grazes the domain's lower border: its clipped contours
// made CGAL throw "Unauthorized intersections of constraints" (exit 1, internal error).
TEST(TinFuzzRegression, FootprintGrazingTheBorder) {
  const PreparedScene p = prepare_scene(parse_scene(R"(
[domain]
size_m = [0.2, 0.2]
[terrain]
height_m = 0.05
[stroke]
path_m = [[0.1, 0.1]]
)",
                                                    "fuzz"));
  auto tin = make_terrain("tin", p.scene, p.initial);
  ToolSpec tool = p.scene.tool;
  tool.radius_m = 0.05099923704890517;
  tool.rim.width_m = tool.radius_m / 2;
  const ToolPose pose{{0.021696040283817802, -0.048832684824902724}, 0.020235294117647063, 0.0};
  const double before = tin->volume();
  EXPECT_NO_THROW(tin->stamp(make_stamp(tool, pose, Vec2::Zero(), 0)));
  const IntegrityReport r = tin->check();
  EXPECT_TRUE(r.ok()) << (r.problems.empty() ? "" : r.problems.front());
  EXPECT_TRUE(std::isfinite(tin->volume()));
  EXPECT_NEAR(tin->volume(), before, 1e-3 * before);
  tin->erode(p.rule, ErosionBudget{3});
  EXPECT_TRUE(tin->check().ok());
}

}  // namespace
}  // namespace sb
