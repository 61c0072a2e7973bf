#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "common/front_pile.hpp"
#include "common/tool.hpp"

namespace sb {
namespace {

// Counts lattice points inside the footprint: area estimate from rasterisation.
double rasterised_area(const ToolStamp& s, double h) {
  const Aabb2 b = bounds(s.footprint);
  std::size_t inside = 0;
  for (double y = std::floor(b.lo.y() / h) * h + h / 2; y < b.hi.y(); y += h)
    for (double x = std::floor(b.lo.x() / h) * h + h / 2; x < b.hi.x(); x += h) inside += s.contains({x, y});
  return static_cast<double>(inside) * h * h;
}

TEST(Footprint, DiskIsAnNgonWithTheNgonsArea) {
  ToolSpec t;
  t.radius_m = 0.02;
  t.sides = 32;
  const auto poly = t.footprint_local();
  ASSERT_EQ(poly.size(), 32u);
  const double ngon = 0.5 * 32 * 0.02 * 0.02 * std::sin(2 * std::numbers::pi / 32);
  EXPECT_NEAR(signed_area(poly), ngon, 1e-15);  // counter-clockwise
}

TEST(Footprint, RasterisationMatchesPolygonArea) {
  for (ToolShape shape : {ToolShape::Disk, ToolShape::Box, ToolShape::Ellipse, ToolShape::Polygon}) {
    ToolSpec t;
    t.shape = shape;
    t.radius_m = 0.03;
    t.half_size_m = {0.03, 0.012};
    t.polygon_m = {{0.0, 0.0}, {0.04, 0.0}, {0.04, 0.03}, {0.02, 0.01}, {0.0, 0.03}};  // concave
    ToolPose pose{{0.5, 0.4}, 0.0, 0.6};
    const ToolStamp s = make_stamp(t, pose, {1.0, 0.0}, 0);
    const double exact = std::abs(signed_area(s.footprint));
    const double h = 2e-4;
    // Lattice area error is bounded by perimeter * h.
    double perimeter = 0.0;
    for (std::size_t i = 0; i < s.footprint.size(); ++i)
      perimeter += (s.footprint[(i + 1) % s.footprint.size()] - s.footprint[i]).norm();
    EXPECT_NEAR(rasterised_area(s, h), exact, perimeter * h) << to_string(shape);
  }
}

TEST(Footprint, PoseRotatesAndTranslates) {
  ToolSpec t;
  t.shape = ToolShape::Box;
  t.half_size_m = {0.02, 0.01};
  const ToolStamp s = make_stamp(t, {{1.0, 2.0}, 0.0, std::numbers::pi / 2}, {0.0, 1.0}, 0);
  EXPECT_TRUE(s.contains({1.0, 2.015}));  // long axis now along y
  EXPECT_FALSE(s.contains({1.015, 2.0}));
}

TEST(ToolBottom, SphereCapIsLowestAtTheCentre) {
  ToolSpec t;
  t.profile = BottomProfile::SphereCap;
  t.sphere_radius_m = 0.05;
  const ToolStamp s = make_stamp(t, {{0.0, 0.0}, 0.1, 0.0}, {1.0, 0.0}, 0);
  EXPECT_DOUBLE_EQ(s.bottom_z({0.0, 0.0}), 0.1);
  EXPECT_NEAR(s.bottom_z({0.03, 0.0}), 0.1 + 0.05 - 0.04, 1e-15);
}

TEST(RimRule, ZeroInsideAndBeyondBandMoreInFront) {
  ToolSpec t;
  t.radius_m = 0.02;
  t.rim.width_m = 0.01;
  t.rim.forward_bias = 0.8;
  const ToolStamp s = make_stamp(t, {{0.0, 0.0}, 0.0, 0.0}, {1.0, 0.0}, 0);
  EXPECT_EQ(s.rim_weight({0.0, 0.0}), 0.0);
  EXPECT_EQ(s.rim_weight({0.035, 0.0}), 0.0);
  const double front = s.rim_weight({0.023, 0.0});
  const double back = s.rim_weight({-0.023, 0.0});
  EXPECT_GT(front, 0.0);
  EXPECT_GT(front, 5.0 * back);
}

// A bulldozing stamp's pile takes only points ahead of the pose within the footprint's half
// width across the motion, on any heading; a stamp that does not move uses the rim all around.
TEST(FrontPile, OnlyAheadOfThePoseOnAnyHeading) {
  ToolSpec t;
  t.shape = ToolShape::Box;
  t.half_size_m = {0.01, 0.015};  // 2 cm along the motion, 3 cm across
  t.rim.model = Displacement::Bulldoze;
  for (const double heading : {0.0, 0.6, 2.0, -2.5}) {
    const Vec2 dir(std::cos(heading), std::sin(heading)), across(-dir.y(), dir.x());
    const Vec2 centre(0.3, -0.2);
    const ToolStamp s = make_stamp(t, {centre, 0.0, heading}, dir, 0);
    EXPECT_TRUE(s.bulldozes());
    EXPECT_NEAR(s.half_width_m, 0.015, 1e-12);
    auto at = [&](double along, double side) { return in_front_pile(s, centre + along * dir + side * across); };
    EXPECT_TRUE(at(0.012, 0.0)) << heading;     // just ahead
    EXPECT_TRUE(at(0.05, 0.0149)) << heading;   // ahead, at the edge of the width
    EXPECT_FALSE(at(0.05, 0.0151)) << heading;  // ahead but beside the width
    EXPECT_FALSE(at(0.005, 0.02)) << heading;   // beside the tool
    EXPECT_FALSE(at(-0.012, 0.0)) << heading;   // behind
  }
  const ToolStamp still = make_stamp(t, {{0.0, 0.0}, 0.0, 0.0}, {0.0, 0.0}, 0);
  EXPECT_FALSE(still.bulldozes());
  EXPECT_GT(still.rim_weight({-0.012, 0.0}), 0.0);
}

// A carrying stamp's pile also takes the points beside the tool back to its rear, but not the
// trench behind the pose within its width; its distance is from the faces that meet the motion,
// so beside the tool it grows towards the rear; within the slump band beside the tool it puts
// nothing until past its front. It carries on the pile of the stamp just before it, keeping
// (1 - shed)^(moved / length), and no other.
TEST(FrontPile, CarriedBesideTheToolFromStampToStamp) {
  ToolSpec t;
  t.shape = ToolShape::Box;
  t.half_size_m = {0.01, 0.015};  // 2 cm along the motion, 3 cm across
  t.rim.model = Displacement::Carry;
  t.rim.carry_shed_fraction = 0.35;
  for (const double heading : {0.0, 0.6, 2.0, -2.5}) {
    const Vec2 dir(std::cos(heading), std::sin(heading)), across(-dir.y(), dir.x());
    const Vec2 centre(0.3, -0.2);
    const ToolStamp s = make_stamp(t, {centre, 0.0, heading}, dir, 7);
    EXPECT_TRUE(s.bulldozes() && s.carries());
    const auto point = [&](double along, double side) { return Vec2(centre + along * dir + side * across); };
    EXPECT_TRUE(in_front_pile(s, point(0.05, 0.03))) << heading;     // ahead, beside the width
    EXPECT_TRUE(in_front_pile(s, point(-0.008, 0.02))) << heading;   // beside the rear half
    EXPECT_FALSE(in_front_pile(s, point(-0.012, 0.02))) << heading;  // behind the rear
    EXPECT_FALSE(in_front_pile(s, point(-0.005, 0.0))) << heading;   // behind the pose, in the width
    // The slump band beside it: no pile within it until past the front.
    EXPECT_TRUE(in_front_pile(s, point(-0.008, 0.017))) << heading;
    EXPECT_FALSE(in_front_pile(s, point(-0.008, 0.017), 0.004)) << heading;  // beside the rear half
    EXPECT_FALSE(in_front_pile(s, point(0.008, 0.017), 0.004)) << heading;   // beside the front half
    EXPECT_TRUE(in_front_pile(s, point(-0.008, 0.02), 0.004)) << heading;    // beyond the band
    EXPECT_TRUE(in_front_pile(s, point(0.012, 0.017), 0.004)) << heading;    // past the front
    EXPECT_TRUE(in_front_pile(s, point(0.005, 0.01), 0.004)) << heading;     // ahead, within the width
    // A wall cut 10 mm deep slumps about its mid-height: 5 mm / tan(repose) of the bed goes.
    EXPECT_NEAR(slump_band(s, s.pose.bottom_z + 0.01), 0.005 / s.rim.tan_repose, 1e-15) << heading;
    EXPECT_EQ(slump_band(s, s.pose.bottom_z - 0.001), 0.0) << heading;  // the tool above the bed
    EXPECT_NEAR((bed_probe(s, 0.002) - centre).dot(dir), 0.012, 1e-12) << heading;
    EXPECT_NEAR(pile_distance(s, point(0.03, 0.0)), 0.02, 1e-12) << heading;          // from the front face
    EXPECT_NEAR(pile_distance(s, point(0.0, 0.02)), std::hypot(0.01, 0.005), 1e-12);  // from its corner
    EXPECT_NEAR(pile_distance(s, point(-0.008, 0.02)), std::hypot(0.018, 0.005), 1e-12);

    const CarriedPileOrigin before = carried_origin(make_stamp(t, {point(-0.002, 0.0), 0.0, heading}, dir, 6));
    EXPECT_NEAR(carried_fraction(s, before), std::pow(0.65, 0.002 / 0.02), 1e-12) << heading;
    EXPECT_EQ(carried_fraction(make_stamp(t, {centre, 0.0, heading}, dir, 8), before), 0.0);  // not the next
    const CarriedPileOrigin far = carried_origin(make_stamp(t, {point(-0.03, 0.0), 0.0, heading}, dir, 6));
    EXPECT_EQ(carried_fraction(s, far), 0.0);  // the tool moved more than its length: a new pile
  }
  ToolSpec bulldoze = t;
  bulldoze.rim.model = Displacement::Bulldoze;
  const ToolStamp b = make_stamp(bulldoze, {{0.0, 0.0}, 0.0, 0.0}, {1.0, 0.0}, 1);
  EXPECT_FALSE(b.carries());
  EXPECT_FALSE(carried_origin(b).valid);
  EXPECT_EQ(carried_fraction(b, carried_origin(make_stamp(t, {{-0.002, 0.0}, 0.0, 0.0}, {1.0, 0.0}, 0))), 0.0);
  EXPECT_EQ(slump_band(b, 1.0), 0.0);  // only a carried pile keeps off the band
}

// The front's deflection is the width-weighted net sliding force, max(0, sin theta - mu cos theta),
// over its faces: none for a blade square to the motion on any heading, the same for every face
// of a blade turned 45 degrees, and a disk's closed form (front_pile.hpp) for any friction; a
// carrying disk keeps (1 - deflection)^(moved / length) of its pile.
TEST(FrontPile, TheFrontDeflectsByItsFacesTurnAndFriction) {
  ToolSpec box;
  box.shape = ToolShape::Box;
  box.half_size_m = {0.01, 0.015};
  box.rim.model = Displacement::Carry;
  box.rim.face_friction = 0.5;
  for (const double heading : {0.0, 0.6, 2.0, -2.5}) {
    const Vec2 dir(std::cos(heading), std::sin(heading));
    EXPECT_NEAR(front_deflection(make_stamp(box, {{0.1, 0.2}, 0.0, heading}, dir, 3)), 0.0, 1e-15) << heading;
    // Turned 45 degrees from its motion: both front faces at 45 degrees.
    const ToolStamp turned = make_stamp(box, {{0.1, 0.2}, 0.0, heading + std::numbers::pi / 4}, dir, 3);
    EXPECT_NEAR(front_deflection(turned), (1.0 - 0.5) * std::sqrt(0.5), 1e-12) << heading;
  }
  ToolSpec disk;
  disk.shape = ToolShape::Disk;
  disk.radius_m = 0.02;
  disk.sides = 4096;
  disk.rim.model = Displacement::Carry;
  for (const double mu : {0.0, 0.3, 0.5, 1.0, 10.0}) {
    disk.rim.face_friction = mu;
    const double theta0 = std::atan(mu);
    const double closed_form =
        std::max(0.0, 0.5 / (1.0 + mu * mu) - 0.5 * mu * (std::numbers::pi / 2 - theta0 - 0.5 * std::sin(2 * theta0)));
    const ToolStamp s = make_stamp(disk, {{0.0, 0.0}, 0.0, 0.7}, {0.6, 0.8}, 5);
    EXPECT_NEAR(front_deflection(s), closed_form, 1e-5) << mu;
    const CarriedPileOrigin before = carried_origin(make_stamp(disk, {{-0.0012, -0.0016}, 0.0, 0.7}, {0.6, 0.8}, 4));
    EXPECT_NEAR(carried_fraction(s, before), std::pow(1.0 - closed_form, 0.002 / 0.04), 1e-6) << mu;
  }
  disk.rim.face_friction = std::numeric_limits<double>::infinity();  // the default: the faces hold the sand
  EXPECT_EQ(front_deflection(make_stamp(disk, {{0.0, 0.0}, 0.0, 0.0}, {1.0, 0.0}, 1)), 0.0);
  EXPECT_EQ(ToolSpec{}.rim.face_friction, disk.rim.face_friction);
  disk.rim.face_friction = 0.5;
  EXPECT_NEAR(front_deflection(make_stamp(disk, {{0.0, 0.0}, 0.0, 0.0}, {1.0, 0.0}, 1)), 0.2232, 1e-4);
  disk.rim.model = Displacement::Bulldoze;  // not carried: nothing to deflect
  EXPECT_EQ(front_deflection(make_stamp(disk, {{0.0, 0.0}, 0.0, 0.0}, {1.0, 0.0}, 1)), 0.0);
}

// The level holds exactly the volume asked for over the samples given, whatever their order,
// including samples the pile does not reach; on flat ground it is a ramp at the repose slope.
TEST(FrontPile, LevelHoldsTheVolumeExactly) {
  const double tan = std::tan(33.0 * std::numbers::pi / 180.0);
  std::vector<PileSample> samples;
  for (int i = 0; i < 200; ++i)  // distances 0.5..199.5 mm, uneven heights, uneven areas
    samples.push_back({(i + 0.5) * 1e-3, 0.002 * std::sin(0.7 * i), 1e-6 * (1.0 + 0.5 * std::cos(1.3 * i))});
  std::reverse(samples.begin(), samples.end());
  for (const double volume : {1e-9, 3e-7, 2e-5, 1e-3}) {
    const double level = front_pile_level(samples, volume, tan);
    double held = 0.0;
    for (const PileSample& p : samples) held += p.area_m2 * front_pile_depth(p, level, tan);
    EXPECT_NEAR(held, volume, 1e-12 * volume) << volume;
  }
  EXPECT_TRUE(std::isnan(front_pile_level({}, 1e-6, tan)));
  // Flat ground, one column of samples 1 mm apart of 1 mm^2 each: a ramp of height H and run
  // H / tan holds H^2 / (2 tan) per unit width.
  std::vector<PileSample> flat;
  for (int i = 0; i < 1000; ++i) flat.push_back({i * 1e-4, 0.0, 1e-4});
  const double level = front_pile_level(flat, 0.02 * 0.02 / (2.0 * tan), tan);
  EXPECT_NEAR(level, 0.02, 2e-4);
}

// The flat reach holds the volume as a ramp across the blade: tan w R^2 / 2 = V.
TEST(FrontPile, FlatReachHoldsTheVolume) {
  const double tan = 0.65;
  for (const double width : {0.001, 0.03, 1.0})
    for (const double volume : {1e-9, 3.6e-5, 1e-2}) {
      const double r = front_pile_flat_reach(volume, width, tan);
      EXPECT_NEAR(tan * width * r * r / 2.0, volume, 1e-12 * volume);
    }
  EXPECT_EQ(front_pile_flat_reach(0.0, 0.03, tan), 0.0);
  EXPECT_EQ(front_pile_flat_reach(1e-6, 0.0, tan), 0.0);
}

}  // namespace
}  // namespace sb
