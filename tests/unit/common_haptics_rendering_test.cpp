// Force rendering (common/haptics/rendering.hpp): the blend across height patches, the
// passivity observer and controller, the virtual coupling and the force-rate limit, on their
// own and in the servo tick against a stiff wall.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "common/haptics/force_blend.hpp"
#include "common/haptics/passivity.hpp"
#include "common/haptics/servo_core.hpp"
#include "common/haptics/shared_pose_device.hpp"
#include "common/haptics/virtual_coupling.hpp"
#include "common/input_error.hpp"
#include "common/scene.hpp"
#include "common_haptics_test_support.hpp"

namespace sb::haptics {
namespace {

const Vec2 kCentre(0.3, 0.3);
constexpr double kDt = 0.001;

using test::limits;
using test::publish;

TEST(HapticsForceBlend, CarriesTheJumpAndFadesItLinearlyWithinTheBlendTime) {
  ForceBlend blend(0.05);
  blend.jump(Vec3(0, 0, 5.0), Vec3(0, 0, 1.0));  // the new patch feels 4 N less
  EXPECT_TRUE(blend.offset().isApprox(Vec3(0, 0, 4.0)));
  double previous = blend.offset().z();
  int ticks = 0;
  while (blend.active()) {
    blend.advance(kDt);
    const double now = blend.offset().z();
    EXPECT_NEAR(previous - now, 4.0 / 50.0, 1e-9);  // the same step every tick
    previous = now;
    ++ticks;
  }
  EXPECT_EQ(ticks, 50);
  EXPECT_EQ(blend.offset(), Vec3::Zero());
}

TEST(HapticsForceBlend, APatchMidBlendAddsToWhatIsLeftAndRestarts) {
  ForceBlend blend(0.01);
  blend.jump(Vec3(0, 0, 2.0), Vec3::Zero());
  for (int i = 0; i < 5; ++i) blend.advance(kDt);
  EXPECT_NEAR(blend.offset().z(), 1.0, 1e-12);
  blend.jump(Vec3(1.0, 0, 0), Vec3::Zero());
  EXPECT_TRUE(blend.offset().isApprox(Vec3(1.0, 0, 1.0)));
  for (int i = 0; i < 10; ++i) blend.advance(kDt);
  EXPECT_FALSE(blend.active());
  EXPECT_EQ(blend.offset(), Vec3::Zero());
  ForceBlend off(0.0);  // blending off: nothing carried
  off.jump(Vec3(0, 0, 3.0), Vec3::Zero());
  EXPECT_EQ(off.offset(), Vec3::Zero());
}

TEST(HapticsPassivity, ObserverBooksTheWorkOfTheForceHeldOverEachPeriod) {
  PassivityController pc(1.0);
  pc.observe(Vec3(0, 0, 0));
  pc.sent(Vec3(0, 0, 2.0));      // pushing up...
  pc.observe(Vec3(0, 0, 0.01));  // ...while the hand rises 1 cm: 0.02 J to the hand
  EXPECT_NEAR(pc.energy_j(), 0.02, 1e-15);
  pc.sent(Vec3(0, 0, 2.0));
  pc.observe(Vec3(0, 0, 0.0));  // pressed back down: the hand gives it back
  EXPECT_NEAR(pc.energy_j(), 0.0, 1e-15);
  EXPECT_NEAR(pc.energy_max_j(), 0.02, 1e-15);
}

TEST(HapticsPassivity, ControllerDampsExactlyTheExcessAndOnlyThen) {
  PassivityController pc(10.0);
  pc.observe(Vec3::Zero());
  const Vec3 v(0, 0, 0.1);
  // E = 0 and the force would do 1 N * 0.1 m/s * 1 ms = 1e-4 J of work: damped to zero work.
  Vec3 f = pc.control(Vec3(0, 0, 1.0), v, kDt);
  EXPECT_TRUE(pc.active_now());
  EXPECT_NEAR(f.dot(v) * kDt, 0.0, 1e-15);
  // Against the motion (work done by the hand): untouched.
  f = pc.control(Vec3(0, 0, -1.0), v, kDt);
  EXPECT_FALSE(pc.active_now());
  EXPECT_EQ(f, Vec3(0, 0, -1.0));
  // The damping force is bounded.
  PassivityController weak(0.1);
  weak.observe(Vec3::Zero());
  f = weak.control(Vec3(0, 0, 1.0), v, kDt);
  EXPECT_NEAR(f.z(), 0.9, 1e-12);
  EXPECT_EQ(weak.active_ticks(), 1u);
}

TEST(HapticsVirtualCoupling, RendersSandInSeriesWithTheCouplingSpring) {
  // A device held 1 cm deep in a 2000 N/m surface through a 1000 N/m coupling settles at the
  // series stiffness: 2000 * 1000 / 3000 N/m times 1 cm.
  VirtualCoupling c(1000.0, 2.0, 0.02);
  const Vec3 device(0, 0, -0.01);
  c.reset(device, Vec3::Zero());
  Vec3 hand = Vec3::Zero();
  for (int i = 0; i < 5000; ++i) {
    const double depth = std::max(0.0, -c.tool_position().z());
    hand = c.step(device, Vec3::Zero(), Vec3(0, 0, 2000.0 * depth), kDt);
    ASSERT_TRUE(hand.allFinite());
  }
  EXPECT_NEAR(hand.z(), 2000.0 * 1000.0 / 3000.0 * 0.01, 1e-3);
}

// A stiff wall: flat sand at the device's stiffness limit, pressed in and out for 20 s while
// the simulation republishes patches (re-centred, so the lattice moves under the tool). The
// observer must end at or below zero (within a tolerance): the rendering created no energy.
struct WallRun {
  double energy_j = 0.0, energy_max_j = 0.0, force_max_n = 0.0;
  double step_max_n = 0.0;        // largest per-tick change
  double step_max_quiet_n = 0.0;  // the same over ticks where the passivity controller was idle
  bool finite = true;
};

WallRun press_the_wall(const RenderingOptions& rendering, const Material& material, double amplitude_m, double hz) {
  const DeviceLimits lim = limits(8.0, 2000.0);
  SharedPoseDevice device("wall", lim);
  PatchBuffer patches;
  const ForceParams params = ForceParams::from(material, test::disk(0.02));
  publish(patches, test::flat_patch(0.1, kCentre, params));
  ServoCore core(device, patches, 40.0, rendering, kDt);
  core.start();
  WallRun r;
  std::uint64_t version = 1;
  bool was_active = false;
  for (int i = 0; i < 20000; ++i) {
    const double t = i * kDt;
    // From 0.2 mm above the surface to 2 * amplitude - 0.2 mm deep and back, every cycle: in
    // contact nearly all the time, the wall entered and left again and again.
    const double depth = amplitude_m * (1.0 - std::cos(2.0 * std::numbers::pi * hz * t)) - 0.0002;
    device.set_pose(Vec3(kCentre.x(), kCentre.y(), 0.1 - depth), 0);
    if (i % 7 == 0) {
      const Vec2 centre = kCentre + Vec2(0.0003 * ((i / 7) % 5), 0.0);
      HeightPatch p = test::flat_patch(0.1, centre, params);
      p.version = ++version;
      publish(patches, p);
    }
    const ServoState s = core.step(t);
    r.finite &= s.force_n.allFinite();
    r.force_max_n = std::max(r.force_max_n, s.force_n.norm());
    r.step_max_n = std::max(r.step_max_n, s.force_step_n);
    if (!s.passivity_active && !was_active) r.step_max_quiet_n = std::max(r.step_max_quiet_n, s.force_step_n);
    was_active = s.passivity_active;
  }
  r.energy_j = core.passivity().energy_j();
  r.energy_max_j = core.passivity().energy_max_j();
  std::printf(
      "wall %.1f mm at %.0f Hz, drag %.0f: observer %.3g J (max %.3g J), force max %.2f N, step max %.3f N "
      "(%.3f N with the controller idle), controller active %llu ticks\n",
      2e3 * amplitude_m, hz, material.drag_n_s_per_m, r.energy_j, r.energy_max_j, r.force_max_n, r.step_max_n,
      r.step_max_quiet_n, static_cast<unsigned long long>(core.passivity().active_ticks()));
  return r;
}

TEST(HapticsServoRendering, StiffWallCreatesNoEnergyOverALongContact) {
  const RenderingOptions defaults;
  const double limit_n = defaults.max_force_rate_n_per_s * kDt;
  const double tolerance_j = 1e-6;
  // Sand as stiff as the device allows (its own drag and friction kept), and a pure spring (no
  // drag, no friction: the hardest case, whose sampled force alone creates energy). Slow and
  // fast presses, 1 and 4 mm deep; the fast one reaches the force-rate limit.
  for (const Material& material : {test::sand(1e5), test::sand(1e5, 0.0, 0.0)}) {
    for (auto [amplitude, hz] : {std::pair{0.0005, 1.0}, std::pair{0.002, 3.0}}) {
      const WallRun r = press_the_wall(defaults, material, amplitude, hz);
      EXPECT_TRUE(r.finite);
      EXPECT_LE(r.energy_j, tolerance_j) << amplitude << " m at " << hz << " Hz";
      EXPECT_LE(r.energy_max_j, tolerance_j);
      EXPECT_LE(r.force_max_n, 8.0);
      EXPECT_GT(r.force_max_n, 1.0);  // the wall still pushes
      // Continuity: within the rate limit, except where the controller had to act (never
      // with the sand's drag), and then by at most its bounded damping force.
      EXPECT_LE(r.step_max_quiet_n, limit_n + 1e-12);
      EXPECT_LE(r.step_max_n, limit_n + defaults.passivity_max_force_n + 1e-12);
      if (material.drag_n_s_per_m > 0.0) {
        EXPECT_LE(r.step_max_n, limit_n + 1e-12);
      }
    }
  }
  // The observer is what makes this meaningful: without the controller, the pure spring's
  // sampled force (it lags the motion by a period) and the rate limit create energy.
  RenderingOptions off = defaults;
  off.passivity = false;
  EXPECT_GT(press_the_wall(off, test::sand(1e5, 0.0, 0.0), 0.002, 3.0).energy_j, 1e-4);
  // With the virtual coupling (the option for stiff settings) as well.
  RenderingOptions coupled = defaults;
  coupled.coupling = true;
  const WallRun c = press_the_wall(coupled, test::sand(1e5, 0.0, 0.0), 0.002, 3.0);
  EXPECT_TRUE(c.finite);
  EXPECT_LE(c.energy_j, tolerance_j);
  EXPECT_LE(c.energy_max_j, tolerance_j);
  EXPECT_GT(c.force_max_n, 1.0);
}

TEST(HapticsServoRendering, ANewPatchChangesTheForceGraduallyAndTheRateLimitHolds) {
  const DeviceLimits lim = limits(8.0, 2000.0);
  SharedPoseDevice device("test", lim);
  PatchBuffer patches;
  const ForceParams params = ForceParams::from(test::sand(800.0, 0.0, 0.0), test::disk(0.02));
  publish(patches, test::flat_patch(0.1, kCentre, params));
  RenderingOptions rendering;
  rendering.blend_s = 0.05;
  rendering.max_force_rate_n_per_s = 80.0;
  ServoCore core(device, patches, 40.0, rendering, kDt);
  core.start();
  device.set_pose(Vec3(kCentre.x(), kCentre.y(), 0.1 - 0.005), 0);  // 5 mm deep: 4 N
  ServoState s;
  for (int i = 0; i < 200; ++i) s = core.step(i * kDt);  // the rate limit lets it rise in 50 ms
  EXPECT_NEAR(s.force_n.z(), 4.0, 1e-9);
  // The sand under the tool vanishes (a stamp dug it out): 4 N to 0, faded over 50 ms.
  HeightPatch dug = test::flat_patch(0.095, kCentre, params);
  dug.version = 2;
  publish(patches, dug);
  double previous = s.force_n.z();
  int ticks = 0;
  for (int i = 200; i < 400; ++i) {
    s = core.step(i * kDt);
    EXPECT_LE(std::abs(s.force_n.z() - previous), 4.0 / 50.0 + 1e-9);
    previous = s.force_n.z();
    ticks += s.force_n.z() > 1e-9;
  }
  EXPECT_LT(s.force_n.norm(), 1e-9);
  EXPECT_EQ(ticks, 50);  // bounded: gone after the blend time
  // The sand comes back: felt again, within the rate limit.
  HeightPatch back = test::flat_patch(0.1, kCentre, params);
  back.version = 3;
  publish(patches, back);
  for (int i = 400; i < 500; ++i) s = core.step(i * kDt);
  EXPECT_GT(s.force_n.z(), 3.0);
}

TEST(HapticsServoRendering, ANonFinitePatchSendsZeroAndDoesNotPoisonTheBlend) {
  SharedPoseDevice device("test", limits(8.0, 2000.0));
  PatchBuffer patches;
  const ForceParams params = ForceParams::from(test::sand(800.0), test::disk(0.02));
  publish(patches, test::flat_patch(0.1, kCentre, params));
  ServoCore core(device, patches, 40.0, RenderingOptions{}, kDt);
  core.start();
  device.set_pose(Vec3(kCentre.x(), kCentre.y(), 0.1 - 0.002), 0);
  ServoState s;
  for (int i = 0; i < 100; ++i) s = core.step(i * kDt);
  EXPECT_NEAR(s.force_n.z(), 1.6, 1e-9);
  HeightPatch broken = test::flat_patch(std::numeric_limits<double>::quiet_NaN(), kCentre, params);
  broken.heights.values[broken.heights.values.size() / 2] = 1e308;
  broken.version = 2;
  publish(patches, broken);
  s = core.step(0.1);
  EXPECT_TRUE(s.force_n.allFinite());
  EXPECT_LE(s.force_n.norm(), 8.0);
  HeightPatch good = test::flat_patch(0.1, kCentre, params);
  good.version = 3;
  publish(patches, good);
  for (int i = 101; i < 300; ++i) {
    s = core.step(i * kDt);
    ASSERT_TRUE(s.force_n.allFinite()) << i;
    ASSERT_TRUE(s.blend_offset_n.allFinite()) << i;
    EXPECT_LE(s.force_step_n, RenderingOptions{}.max_force_rate_n_per_s * kDt + 1e-12);
  }
  EXPECT_NEAR(s.force_n.z(), 1.6, 1e-9);  // the sand is felt again
}

TEST(HapticsSceneKeys, DefaultsAreTheDocumentedOnesAndBadValuesNameTheKey) {
  const std::string base = "domain.size_m = [0.5, 0.5]\nstroke.path_m = [[0.1, 0.1], [0.2, 0.2]]\n";
  const RenderingOptions d = parse_scene(base, "s.toml").haptics;
  EXPECT_DOUBLE_EQ(d.blend_s, 0.05);
  EXPECT_DOUBLE_EQ(d.max_force_rate_n_per_s, 2000.0);
  EXPECT_TRUE(d.passivity);
  EXPECT_FALSE(d.coupling);
  const RenderingOptions set =
      parse_scene(base, "s.toml",
                  {"haptics.blend_ms=20", "haptics.coupling=true", "haptics.coupling_stiffness_n_per_m=500",
                   "haptics.passivity_control=false"})
          .haptics;
  EXPECT_DOUBLE_EQ(set.blend_s, 0.02);
  EXPECT_TRUE(set.coupling);
  EXPECT_DOUBLE_EQ(set.coupling_stiffness_n_per_m, 500.0);
  EXPECT_FALSE(set.passivity);
  for (const std::string bad :
       {"haptics.blend_ms=-1", "haptics.max_force_rate_n_per_s=nan", "haptics.coupling_stiffness_n_per_m=0",
        "haptics.tool_mass_kg=-0.1", "haptics.passivity_control=3", "haptics.blend=5"}) {
    const std::string key = bad.substr(0, bad.find('='));
    try {
      parse_scene(base, "s.toml", {bad});
      ADD_FAILURE() << bad << " was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace sb::haptics
