// The force model: penetration resistance, drag and friction from a published height patch,
// and the device-safe limit every commanded force goes through.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "common/haptics/force_model.hpp"
#include "common_haptics_test_support.hpp"

namespace sb::haptics {
namespace {

using test::disk;
using test::flat_patch;
using test::sand;

const Vec2 kCentre(0.3, 0.3);

TEST(HapticsForce, FlatToolInFlatSandFeelsStiffnessTimesDepth) {
  const ForceParams params = ForceParams::from(sand(800.0), disk(0.02));
  const HeightPatch p = flat_patch(0.1, kCentre, params);
  for (double depth : {0.001, 0.004, 0.01}) {
    const ForceOutput f = compute_force(p, Vec3(kCentre.x(), kCentre.y(), 0.1 - depth), Vec3::Zero(), 1e9);
    EXPECT_TRUE(f.in_contact);
    EXPECT_NEAR(f.penetration_m, depth, 1e-12);
    EXPECT_NEAR(f.force_n.z(), 800.0 * depth, 1e-9);
    EXPECT_EQ(f.force_n.x(), 0.0);
    EXPECT_EQ(f.force_n.y(), 0.0);
    EXPECT_NEAR(f.contact_fraction, std::min(1.0, depth / kContactDepth_m), 1e-12);  // the drag engages with depth
    // About pi r^2 / spacing^2 lattice points, and the displaced volume about pi r^2 depth.
    EXPECT_NEAR(f.displaced_m3, std::numbers::pi * 0.02 * 0.02 * depth, 0.05 * std::numbers::pi * 0.02 * 0.02 * depth);
    EXPECT_FALSE(f.outside_patch);
  }
}

TEST(HapticsForce, ToolAboveTheSandFeelsNothing) {
  const ForceParams params = ForceParams::from(sand(), disk(0.02));
  const HeightPatch p = flat_patch(0.1, kCentre, params);
  const ForceOutput f = compute_force(p, Vec3(kCentre.x(), kCentre.y(), 0.1001), Vec3(0.1, 0.2, -0.3), 1e9);
  EXPECT_FALSE(f.in_contact);
  EXPECT_EQ(f.force_n, Vec3::Zero());
  EXPECT_EQ(f.penetration_m, 0.0);
}

TEST(HapticsForce, DeviceStiffnessLimitCapsTheSpring) {
  const ForceParams params = ForceParams::from(sand(5000.0), disk(0.02));
  const HeightPatch p = flat_patch(0.1, kCentre, params);
  const ForceOutput f = compute_force(p, Vec3(kCentre.x(), kCentre.y(), 0.095), Vec3::Zero(), 1000.0);
  EXPECT_NEAR(f.force_n.z(), 1000.0 * 0.005, 1e-9);
}

TEST(HapticsForce, DragAndFrictionOpposeTheMotionOnlyInSand) {
  const ForceParams params = ForceParams::from(sand(800.0, 5.0, 0.4), disk(0.02));
  const HeightPatch p = flat_patch(0.1, kCentre, params);
  const Vec3 v(0.1, 0.0, 0.0);
  const ForceOutput f = compute_force(p, Vec3(kCentre.x(), kCentre.y(), 0.095), v, 1e9);
  const double up = 800.0 * 0.005;
  EXPECT_NEAR(f.force_n.z(), up, 1e-9);
  EXPECT_NEAR(f.force_n.x(), -5.0 * 0.1 - 0.4 * up, 1e-9);  // drag + Coulomb friction
  EXPECT_NEAR(f.force_n.y(), 0.0, 1e-12);
  // Slow motion: friction fades linearly below kFrictionVelocityEps instead of chattering.
  const double slow = 0.5 * kFrictionVelocityEps;
  const ForceOutput g = compute_force(p, Vec3(kCentre.x(), kCentre.y(), 0.095), Vec3(0.0, slow, 0.0), 1e9);
  EXPECT_NEAR(g.force_n.y(), -5.0 * slow - 0.4 * up * 0.5, 1e-9);
  // Out of the sand, moving fast: nothing.
  const ForceOutput h = compute_force(p, Vec3(kCentre.x(), kCentre.y(), 0.2), Vec3(1.0, 1.0, 1.0), 1e9);
  EXPECT_EQ(h.force_n, Vec3::Zero());
}

TEST(HapticsForce, SphereTipDisplacesLessThanAFlatBottomAtTheSameDepth) {
  const HeightPatch flat = flat_patch(0.1, kCentre, ForceParams::from(sand(), disk(0.02)));
  const HeightPatch ball = flat_patch(0.1, kCentre, ForceParams::from(sand(), disk(0.02, BottomProfile::SphereCap)));
  const Vec3 at(kCentre.x(), kCentre.y(), 0.1 - 0.01);
  const ForceOutput f = compute_force(flat, at, Vec3::Zero(), 1e9);
  const ForceOutput b = compute_force(ball, at, Vec3::Zero(), 1e9);
  EXPECT_GT(b.force_n.z(), 0.0);
  EXPECT_LT(b.force_n.z(), f.force_n.z());
  EXPECT_LT(b.contact_fraction, 1.0);
}

TEST(HapticsForce, ASlopeUnderHalfTheToolGivesHalfTheContact) {
  // Sand only on x > centre: half of the footprint touches it.
  const ForceParams params = ForceParams::from(sand(), disk(0.02));
  const HeightPatch p = test::patch([](const Vec2& q) { return q.x() > kCentre.x() ? 0.1 : 0.05; }, kCentre, params);
  const ForceOutput f = compute_force(p, Vec3(kCentre.x(), kCentre.y(), 0.09), Vec3::Zero(), 1e9);
  EXPECT_NEAR(f.contact_fraction, 0.5, 0.06);
  EXPECT_NEAR(f.force_n.z(), 800.0 * 0.01 * f.contact_fraction, 1e-9);
}

TEST(HapticsForce, ToolBeyondThePatchFeelsNothingAndSaysSo) {
  const ForceParams params = ForceParams::from(sand(), disk(0.02));
  const HeightPatch p = flat_patch(0.1, kCentre, params);
  const ForceOutput far = compute_force(p, Vec3(kCentre.x() + 1.0, kCentre.y(), 0.05), Vec3::Zero(), 1e9);
  EXPECT_TRUE(far.outside_patch);
  EXPECT_EQ(far.force_n, Vec3::Zero());
  const ForceOutput edge = compute_force(p, Vec3(kCentre.x() + 0.035, kCentre.y(), 0.09), Vec3::Zero(), 1e9);
  EXPECT_TRUE(edge.outside_patch);
  EXPECT_GT(edge.force_n.z(), 0.0);
}

TEST(HapticsForce, InvalidPatchOrNonFinitePoseGivesNoForce) {
  const ForceParams params = ForceParams::from(sand(), disk(0.02));
  HeightPatch p = flat_patch(0.1, kCentre, params);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(compute_force(p, Vec3(nan, 0.3, 0.05), Vec3::Zero(), 1e9).force_n, Vec3::Zero());
  p.valid = false;
  EXPECT_EQ(compute_force(p, Vec3(kCentre.x(), kCentre.y(), 0.05), Vec3::Zero(), 1e9).force_n, Vec3::Zero());
}

TEST(HapticsForce, RotatedBoxFeelsTheSameInFlatSand) {
  ToolSpec box;
  box.shape = ToolShape::Box;
  box.half_size_m = Vec2(0.03, 0.01);
  for (double heading : {0.0, 0.3, 1.2, 2.5}) {
    const HeightPatch p = flat_patch(0.1, kCentre, ForceParams::from(sand(), box, heading));
    const ForceOutput f = compute_force(p, Vec3(kCentre.x(), kCentre.y(), 0.096), Vec3::Zero(), 1e9);
    EXPECT_NEAR(f.force_n.z(), 800.0 * 0.004, 1e-9) << heading;
    EXPECT_NEAR(f.displaced_m3, 0.06 * 0.02 * 0.004, 0.15 * 0.06 * 0.02 * 0.004) << heading;
  }
}

TEST(HapticsForce, LimitForceKeepsEveryForceFiniteAndWithinTheLimit) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  LimitedForce l = limit_force(Vec3(nan, 0.0, 1.0), 5.0);
  EXPECT_TRUE(l.nonfinite);
  EXPECT_EQ(l.force_n, Vec3::Zero());
  l = limit_force(Vec3(0.0, inf, 0.0), 5.0);
  EXPECT_TRUE(l.nonfinite);
  EXPECT_EQ(l.force_n, Vec3::Zero());
  l = limit_force(Vec3(0.0, 3.0, 4.0), 5.0);
  EXPECT_FALSE(l.clamped);
  EXPECT_EQ(l.force_n, Vec3(0.0, 3.0, 4.0));
  l = limit_force(Vec3(1e300, -1e300, 1e300), 5.0);
  EXPECT_TRUE(l.force_n.allFinite());
  EXPECT_LE(l.force_n.norm(), 5.0);

  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> mag(-12.0, 12.0), limit(0.1, 20.0);
  for (int i = 0; i < 100000; ++i) {
    const Vec3 f(std::pow(10.0, mag(rng)) * (i % 2 ? 1 : -1), std::pow(10.0, mag(rng)), -std::pow(10.0, mag(rng)));
    const double lim = limit(rng);
    const LimitedForce r = limit_force(f, lim);
    ASSERT_TRUE(r.force_n.allFinite()) << i;
    ASSERT_LE(r.force_n.norm(), lim) << i;
    if (!r.clamped) {
      ASSERT_EQ(r.force_n, f);
    }
  }
}

TEST(HapticsForce, RandomSandAndPosesGiveFiniteForces) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    const double a = 0.05 * u(rng), k = 20.0 + 200.0 * u(rng);
    ToolSpec tool = disk(0.005 + 0.04 * u(rng), trial % 2 ? BottomProfile::SphereCap : BottomProfile::Flat);
    const ForceParams params =
        ForceParams::from(sand(5000.0 * u(rng), 50.0 * u(rng), 2.0 * u(rng)), tool, 6.0 * u(rng));
    const HeightPatch p = test::patch(
        [&](const Vec2& q) { return 0.1 + a * std::sin(k * q.x()) * std::cos(k * q.y()); }, kCentre, params);
    const Vec3 pos(kCentre.x() + 0.1 * (u(rng) - 0.5), kCentre.y() + 0.1 * (u(rng) - 0.5), 0.05 + 0.1 * u(rng));
    const Vec3 vel = Vec3(u(rng) - 0.5, u(rng) - 0.5, u(rng) - 0.5) * 10.0;
    const ForceOutput f = compute_force(p, pos, vel, 3000.0);
    ASSERT_TRUE(f.force_n.allFinite()) << trial;
    ASSERT_GE(f.penetration_m, 0.0);
    ASSERT_GE(f.force_n.z(), -50.0 * 10.0 * 1.0);  // only drag can pull down
    const LimitedForce l = limit_force(f.force_n, 8.0);
    ASSERT_LE(l.force_n.norm(), 8.0);
  }
}

}  // namespace
}  // namespace sb::haptics
