#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <numbers>

#include "common/reference.hpp"

namespace sb {
namespace {

StampSchedule schedule_of(const Scene& s, const HeightField& f) {
  return make_schedule(s.tool, s.stroke, [&](const Vec2& p) { return f(p); });
}

// A raster over `box` at `spacing` whose heights are z(point).
Raster sampled(const Aabb2& box, double spacing, const std::function<double(const Vec2&)>& z) {
  Raster r = Raster::covering(box, spacing);
  for (std::size_t iy = 0; iy < r.ny; ++iy)
    for (std::size_t ix = 0; ix < r.nx; ++ix) r.at(ix, iy) = z(r.point(ix, iy));
  return r;
}

// A straight line through `centre` turned `azimuth_deg` from +x, and the signed distance across it.
struct Line {
  Vec2 centre, along, across;
  Line(const Vec2& c, double azimuth_deg) : centre(c) {
    const double a = azimuth_deg * std::numbers::pi / 180.0;
    along = Vec2(std::cos(a), std::sin(a));
    across = Vec2(-along.y(), along.x());
  }
  double distance(const Vec2& p) const { return (p - centre).dot(across); }
};

Scene pile_scene() {
  return parse_scene(R"(
[domain]
size_m = [0.3, 0.3]
[terrain]
height_m = 0.05
[tool]
shape = "pour"
radius_m = 0.004
volume_m3 = 1e-6
[stroke]
path_m = [[0.15, 0.15]]
repeat = 20
[reference]
kind = "pile"
[output]
raster_m = 0.001
)",
                     "pile");
}

TEST(Reference, PileIsTheConeOfThePouredVolumeAtTheCriticalAngle) {
  const Scene s = pile_scene();
  const HeightField f = HeightField::from_scene(s);
  const StampSchedule sch = schedule_of(s, f);
  const Raster lattice = Raster::covering(s.domain.box(), s.output.raster_m);
  const auto cone = reference_raster(s, sch, f, lattice);
  ASSERT_TRUE(cone);
  // r = (3V / (pi tan 30))^(1/3) for V = 2e-5.
  const double r = std::cbrt(3 * 2e-5 / (std::numbers::pi * std::tan(std::numbers::pi / 6)));
  EXPECT_NEAR(cone->interpolate({0.15, 0.15}) - 0.05, r * std::tan(std::numbers::pi / 6), 1e-12);
  double volume = 0.0;
  for (double z : cone->values) volume += (z - 0.05) * 1e-6;
  EXPECT_NEAR(volume, 2e-5, 2e-5 * 0.01);

  const PileShape p = measure_pile(*cone, {0.15, 0.15}, 0.05);
  EXPECT_NEAR(p.flank_angle_deg, 30.0, 0.2);
  EXPECT_LT(p.roundness, 0.01);
  EXPECT_NEAR(p.radius_m, r, 0.002);

  const auto metrics = accuracy_metrics(s, sch, f, lattice, *cone);
  EXPECT_EQ(metrics["reference.rmse_m"].get<double>(), 0.0);
  EXPECT_NEAR(metrics["pile.radius_expected_m"].get<double>(), r, 1e-12);
}

TEST(Reference, RoundnessSeesADiamond) {
  const Scene s = pile_scene();
  Raster diamond = Raster::covering(s.domain.box(), 0.001);
  for (std::size_t iy = 0; iy < diamond.ny; ++iy)
    for (std::size_t ix = 0; ix < diamond.nx; ++ix) {
      const Vec2 d = diamond.point(ix, iy) - Vec2(0.15, 0.15);
      diamond.at(ix, iy) = 0.05 + std::max(0.0, 0.02 - 0.6 * (std::abs(d.x()) + std::abs(d.y())));
    }
  EXPECT_GT(measure_pile(diamond, {0.15, 0.15}, 0.05).roundness, 0.08);
}

TEST(Reference, CraterConservesTheCutVolume) {
  const Scene s = parse_scene(R"(
[domain]
size_m = [0.2, 0.2]
[terrain]
height_m = 0.1
[tool]
radius_m = 0.02
depth_m = 0.01
[stroke]
path_m = [[0.1, 0.1]]
[reference]
kind = "crater"
[output]
raster_m = 0.0005
)",
                              "crater");
  const HeightField f = HeightField::from_scene(s);
  const StampSchedule sch = schedule_of(s, f);
  const auto crater = reference_raster(s, sch, f, Raster::covering(s.domain.box(), s.output.raster_m));
  ASSERT_TRUE(crater);
  EXPECT_NEAR(crater->interpolate({0.1, 0.1}), 0.09, 1e-12);
  double change = 0.0;
  for (double z : crater->values) change += (z - 0.1) * 0.0005 * 0.0005;
  EXPECT_NEAR(change, 0.0, 0.02 * std::numbers::pi * 0.02 * 0.02 * 0.01);
}

TEST(Reference, TrenchWallAngleAndDepth) {
  Raster initial = Raster::covering({{0, 0}, {0.2, 0.2}}, 0.001), trench = initial;
  const double t = std::tan(std::numbers::pi / 6);
  for (std::size_t iy = 0; iy < initial.ny; ++iy)
    for (std::size_t ix = 0; ix < initial.nx; ++ix) {
      initial.at(ix, iy) = 0.1;
      const double d = std::abs(initial.point(ix, iy).y() - 0.1);  // trench along x at y = 0.1
      trench.at(ix, iy) = std::min(0.1, 0.09 + std::max(0.0, d - 0.01) * t);
    }
  const TrenchShape s = measure_trench(trench, initial, {0.02, 0.1}, {0.18, 0.1});
  EXPECT_NEAR(s.depth_m, 0.01, 1e-9);
  EXPECT_NEAR(s.wall_angle_deg, 30.0, 0.5);
}

// A trench along azimuth 22.5 degrees (between the grid's stencil directions) whose walls stand
// at 30 degrees on one side and 34 on the other: the section statistics see both.
TEST(Reference, TrenchSectionStatisticsAtAnAzimuth) {
  const Aabb2 box{{0, 0}, {0.3, 0.3}};
  const Line line({0.15, 0.15}, 22.5);
  const Raster initial = sampled(box, 0.001, [](const Vec2&) { return 0.1; });
  const Raster trench = sampled(box, 0.001, [&](const Vec2& p) {
    const double d = line.distance(p), t = std::tan((d > 0 ? 34.0 : 30.0) * std::numbers::pi / 180.0);
    return std::min(0.1, 0.09 + std::max(0.0, std::abs(d) - 0.01) * t);
  });
  const TrenchShape s = measure_trench(trench, initial, line.centre - 0.1 * line.along, line.centre + 0.1 * line.along);
  EXPECT_EQ(s.sections, 22);
  EXPECT_NEAR(s.depth_m, 0.01, 1e-6);
  EXPECT_NEAR(s.wall_angle_deg, 34.0, 0.2);
  EXPECT_NEAR(s.wall_angle_min_deg, 30.0, 0.2);
  EXPECT_NEAR(s.wall_angle_mean_deg, 32.0, 0.2);
  EXPECT_NEAR(s.wall_angle_spread_deg, 2.0, 0.1);
  EXPECT_NEAR(s.worst_error_deg(31.0), 3.0, 0.2);
}

// A ridge of triangular section at 67.5 degrees, flanks at 30 degrees, 10 mm high: measured as
// the walls of the negated surface, with the crest's height above the initial surface.
TEST(Reference, RidgeFlanksAtAnAzimuth) {
  const Aabb2 box{{0, 0}, {0.3, 0.3}};
  const Line line({0.15, 0.15}, 67.5);
  const double t = std::tan(std::numbers::pi / 6);
  const Raster initial = sampled(box, 0.001, [](const Vec2&) { return 0.05; });
  const Raster ridge =
      sampled(box, 0.001, [&](const Vec2& p) { return 0.05 + std::max(0.0, 0.01 - std::abs(line.distance(p)) * t); });
  const TrenchShape s = measure_ridge(ridge, initial, line.centre - 0.1 * line.along, line.centre + 0.1 * line.along);
  EXPECT_EQ(s.sections, 22);
  EXPECT_NEAR(s.depth_m, 0.01, 5e-4);  // bilinear interpolation cuts the sharp crest
  EXPECT_NEAR(s.wall_angle_mean_deg, 30.0, 0.2);
  EXPECT_NEAR(s.wall_angle_deg, 30.0, 0.3);
  EXPECT_LT(s.wall_angle_spread_deg, 0.2);
}

// The plane terrain of a scene at 30 degrees toward 67.5 degrees: the fit and the local slopes
// find it; a step across the middle leaves the fit near 30 but not the steepest local slope.
TEST(Reference, PlaneSlopeAzimuthAndLocalSlopes) {
  const Scene s = parse_scene(R"(
[domain]
size_m = [0.2, 0.2]
[terrain]
kind = "plane"
height_m = 0.1
slope_deg = 30.0
azimuth_deg = 67.5
[tool]
shape = "pour"
radius_m = 0.004
volume_m3 = 1e-9
[stroke]
path_m = [[0.1, 0.1]]
[reference]
kind = "plane"
[output]
raster_m = 0.0025
)",
                              "plane");
  const HeightField f = HeightField::from_scene(s);
  const Raster plane = sampled(s.domain.box(), s.output.raster_m, [&](const Vec2& p) { return f(p); });
  const auto m = accuracy_metrics(s, schedule_of(s, f), f, plane, plane);
  EXPECT_NEAR(m["plane.slope_deg"].get<double>(), 30.0, 1e-9);
  EXPECT_NEAR(m["plane.slope_error_deg"].get<double>(), 0.0, 1e-9);
  EXPECT_NEAR(m["plane.azimuth_deg"].get<double>(), 67.5, 1e-9);
  EXPECT_NEAR(m["plane.rms_m"].get<double>(), 0.0, 1e-12);
  EXPECT_NEAR(m["plane.slope_mean_deg"].get<double>(), 30.0, 1e-9);
  EXPECT_NEAR(m["plane.slope_max_deg"].get<double>(), 30.0, 1e-9);

  // A 2 mm step down where x crosses the centre.
  const Raster stepped =
      sampled(s.domain.box(), s.output.raster_m, [&](const Vec2& p) { return f(p) - (p.x() > 0.1 ? 0.002 : 0.0); });
  const PlaneShape p = measure_plane(stepped);
  EXPECT_NEAR(p.slope_deg, 30.0, 1.5);
  EXPECT_NEAR(p.slope_mean_deg, 30.0, 1.5);
  EXPECT_GT(p.slope_max_deg, 35.0);
}

// A cone terrain standing at the critical angle is its own pile reference: its sand counts in
// the reference's volume, its base is terrain.height_m (not the initial surface), and its
// centre is the domain's, wherever the disturbance is poured.
TEST(Reference, ConeTerrainAtCriticalIsThePileReference) {
  const Scene s = parse_scene(R"(
[domain]
size_m = [0.3, 0.3]
[terrain]
kind = "cone"
height_m = 0.05
slope_deg = 30.0
volume_m3 = 2e-5
[tool]
shape = "pour"
radius_m = 0.004
volume_m3 = 1e-12
[stroke]
path_m = [[0.16, 0.14]]
[reference]
kind = "pile"
[output]
raster_m = 0.001
)",
                              "cone");
  const HeightField f = HeightField::from_scene(s);
  const Raster cone = sampled(s.domain.box(), s.output.raster_m, [&](const Vec2& p) { return f(p); });
  // Its volume above the base, by the raster (the cone's rim falls between samples).
  double volume = 0.0;
  for (double z : cone.values) volume += (z - 0.05) * cone.spacing_m * cone.spacing_m;
  EXPECT_NEAR(volume, 2e-5, 2e-5 * 1e-3);
  const auto m = accuracy_metrics(s, schedule_of(s, f), f, cone, cone);
  EXPECT_LT(m["reference.rmse_m"].get<double>(), 1e-6);
  EXPECT_NEAR(m["pile.radius_expected_m"].get<double>(), 0.03210, 1e-5);
  EXPECT_NEAR(m["pile.height_m"].get<double>(), 0.03210 * std::tan(deg_to_rad(30.0)), 1e-4);
  EXPECT_NEAR(m["pile.flank_angle_deg"].get<double>(), 30.0, 0.2);
  EXPECT_LT(m["pile.roundness"].get<double>(), 0.01);
}

}  // namespace
}  // namespace sb
