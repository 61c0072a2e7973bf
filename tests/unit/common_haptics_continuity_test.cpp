// The force model is continuous in the tool's pose and velocity: a tool moved by a small step
// changes the force by a small amount, across contact onset and across the patch's lattice
// lines, for every tool shape and bottom profile.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "common/haptics/force_model.hpp"
#include "common_haptics_test_support.hpp"

namespace sb::haptics {
namespace {

using test::disk;
using test::sand;

const Vec2 kCentre(0.3, 0.3);

ToolSpec box(double sx, double sy) {
  ToolSpec t;
  t.shape = ToolShape::Box;
  t.half_size_m = Vec2(0.5 * sx, 0.5 * sy);
  return t;
}

ToolSpec ellipse(double sx, double sy) {
  ToolSpec t;
  t.shape = ToolShape::Ellipse;
  t.half_size_m = Vec2(0.5 * sx, 0.5 * sy);
  t.sides = 24;
  return t;
}

// Sand 0.1 m high with bumps of +-1 mm and a gentle slope: every lattice point differs.
double bumpy(const Vec2& q) {
  return 0.1 + 0.02 * (q.x() - kCentre.x()) + 0.001 * std::sin(517.0 * q.x()) * std::cos(431.0 * q.y());
}

// The largest force change between consecutive poses of `path` (velocity held), in N.
template <class Path>
double largest_step(const HeightPatch& p, int steps, Path path, const Vec3& velocity) {
  double worst = 0.0;
  Vec3 last = compute_force(p, path(0), velocity, 1e9).force_n;
  for (int i = 1; i <= steps; ++i) {
    const Vec3 f = compute_force(p, path(i), velocity, 1e9).force_n;
    worst = std::max(worst, (f - last).norm());
    last = f;
  }
  return worst;
}

TEST(HapticsContinuity, AFlatToolMeetingFlatSandFeelsTheDragGrowFromZero) {
  // Lowered at 0.2 m/s in 1 um steps from 1 mm above the sand to 3 mm into it. The spring
  // alone changes by k dz = 0.8 mN a step; the old model's drag switched on at once
  // (b v = 1 N in one step).
  const ForceParams params = ForceParams::from(sand(800.0, 5.0), disk(0.02));
  const HeightPatch p = test::flat_patch(0.1, kCentre, params);
  const Vec3 v(0.0, 0.0, -0.2);
  const double worst = largest_step(
      p, 4000, [&](int i) { return Vec3(kCentre.x(), kCentre.y(), 0.101 - 1e-6 * i); }, v);
  // Bound: k dz + b |v| dz / kContactDepth_m, with margin for rounding.
  EXPECT_LE(worst, 1.2 * (800.0 * 1e-6 + 5.0 * 0.2 * 1e-6 / kContactDepth_m));
  const ForceOutput deep = compute_force(p, Vec3(kCentre.x(), kCentre.y(), 0.097), v, 1e9);
  EXPECT_NEAR(deep.force_n.z(), 800.0 * 0.003 + 5.0 * 0.2, 1e-9);  // k d + b v once fully engaged
}

TEST(HapticsContinuity, AToolSlidingAcrossLatticeLinesChangesTheForceALittle) {
  // Every shape, flat and sphere-cap bottoms, at several headings, slid 6 mm (about four
  // lattice spacings) in 1 um steps through bumpy sand, 4 mm deep, at 0.1 m/s.
  std::vector<ToolSpec> tools{disk(0.02), disk(0.02, BottomProfile::SphereCap), box(0.04, 0.02), ellipse(0.03, 0.015)};
  for (std::size_t t = 0; t < tools.size(); ++t) {
    for (double heading : {0.0, 0.4, 1.1}) {
      const ForceParams params = ForceParams::from(sand(800.0, 5.0, 0.4), tools[t], heading);
      const HeightPatch p = test::patch(bumpy, kCentre, params);
      const Vec2 dir(std::cos(0.3 + heading), std::sin(0.3 + heading));
      const Vec3 v(0.1 * dir.x(), 0.1 * dir.y(), 0.0);
      const double worst = largest_step(
          p, 6000,
          [&](int i) {
            const Vec2 xy = kCentre - 0.003 * dir + 1e-6 * i * dir;
            return Vec3(xy.x(), xy.y(), 0.096);
          },
          v);
      // The force's slope along the path is at most k (1 + mu) times the sand's slope (0.02
      // plus the bumps' 0.52 at most), so a 1 um step moves it by at most 0.6 mN.
      EXPECT_LE(worst, 1e-3) << "tool " << t << " heading " << heading;
    }
  }
}

TEST(HapticsContinuity, TurningAToolChangesTheForceALittle) {
  const ToolSpec tool = box(0.04, 0.02);
  double worst = 0.0;
  Vec3 last = Vec3::Zero();
  for (int i = 0; i <= 2000; ++i) {
    const double heading = 1e-4 * i;  // 0.2 rad in 0.1 mrad steps: corners sweep 2 um a step
    const ForceParams params = ForceParams::from(sand(), tool, heading);
    const HeightPatch p = test::patch(bumpy, kCentre, params);
    const Vec3 f = compute_force(p, Vec3(kCentre.x(), kCentre.y(), 0.097), Vec3::Zero(), 1e9).force_n;
    if (i > 0) worst = std::max(worst, (f - last).norm());
    last = f;
  }
  EXPECT_LE(worst, 2e-3);
}

TEST(HapticsContinuity, RandomSmallStepsGiveSmallForceChanges) {
  // Random tools, poses and velocities in bumpy sand, each moved by a random 1 um step (and
  // its velocity by 0.01 mm/s): the force changes by at most the model's Lipschitz bound.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<ToolSpec> tools{disk(0.02), disk(0.015, BottomProfile::SphereCap), box(0.04, 0.02), ellipse(0.03, 0.015)};
  double worst = 0.0;
  for (int trial = 0; trial < 2000; ++trial) {
    const ForceParams params = ForceParams::from(sand(800.0, 5.0, 0.4), tools[trial % tools.size()], 3.0 * u(rng));
    const HeightPatch p = test::patch(bumpy, kCentre, params);
    const Vec3 x(kCentre.x() + 0.005 * u(rng), kCentre.y() + 0.005 * u(rng), 0.1 + 0.006 * u(rng));
    const Vec3 v(0.1 * u(rng), 0.1 * u(rng), 0.1 * u(rng));
    const Vec3 dx = 1e-6 * Vec3(u(rng), u(rng), u(rng)).normalized();
    const Vec3 dv = 1e-5 * Vec3(u(rng), u(rng), u(rng)).normalized();
    const Vec3 a = compute_force(p, x, v, 1e9).force_n;
    const Vec3 b = compute_force(p, x + dx, v + dv, 1e9).force_n;
    worst = std::max(worst, (b - a).norm());
  }
  // k |dx| (1 + mu) (1 + slope) + b |dv| + b |v| |dx| / kContactDepth_m + the friction's turn
  // mu k d |dv| / max(|v_xy|, kFrictionVelocityEps): a few mN for these ranges.
  EXPECT_LE(worst, 0.01);
}

TEST(HapticsContinuity, AFootprintSmallerThanACellStillFeelsTheSandContinuously) {
  // A 1 mm disk on a lattice of about 1.7 mm: the footprint is integrated, not sampled, so
  // it feels k d wherever it is and nothing jumps as it crosses lattice lines.
  const ForceParams params = ForceParams::from(sand(800.0), disk(0.0005));
  HeightPatch p = test::patch([](const Vec2&) { return 0.1; }, kCentre, ForceParams::from(sand(800.0), disk(0.02)));
  p.params = params;
  const double worst = largest_step(
      p, 4000, [&](int i) { return Vec3(kCentre.x() + 1e-6 * i, kCentre.y() + 0.3e-6 * i, 0.098); }, Vec3::Zero());
  EXPECT_LE(worst, 1e-9);
  const ForceOutput f = compute_force(p, Vec3(kCentre.x() + 0.0011, kCentre.y(), 0.098), Vec3::Zero(), 1e9);
  EXPECT_NEAR(f.force_n.z(), 800.0 * 0.002, 1e-9);
}

TEST(HapticsContinuity, TheHeldForceIsTheSpringAtTheMeanDepthOfTheFootprint) {
  // Sand tilted along x under a flat disk: the mean depth under the footprint is the depth at
  // its centre (area-weighted; the disk is symmetric), for every position between lattice
  // points.
  const ForceParams params = ForceParams::from(sand(800.0), disk(0.02));
  const HeightPatch p = test::patch([](const Vec2& q) { return 0.1 + 0.1 * (q.x() - kCentre.x()); }, kCentre, params);
  for (double shift : {0.0, 0.0003, 0.0007, 0.0011}) {
    const Vec3 at(kCentre.x() + shift, kCentre.y(), 0.092);
    const ForceOutput f = compute_force(p, at, Vec3::Zero(), 1e9);
    const double depth = 0.1 + 0.1 * shift - 0.092;
    EXPECT_NEAR(f.penetration_m, depth, 1e-9) << shift;
    EXPECT_NEAR(f.force_n.z(), 800.0 * depth, 1e-6) << shift;
  }
}

}  // namespace
}  // namespace sb::haptics
