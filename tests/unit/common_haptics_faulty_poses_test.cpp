// A misbehaving pose stream (a UDP bridge that floods, drops, reorders or corrupts packets)
// against the servo's rendering: the passivity observer's energy stays within its bound
// (common/haptics/passivity.hpp) whatever the poses do, and pose steps faster than the
// device's max_speed_m_s restart the rendering instead of counting as motion.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <numbers>
#include <utility>
#include <vector>

#include "common/haptics/passivity.hpp"
#include "common/haptics/servo_core.hpp"
#include "common_haptics_test_support.hpp"

namespace sb::haptics {
namespace {

const Vec2 kCentre(0.3, 0.3);
constexpr double kDt = 0.001;
constexpr double kSurface = 0.1;  // the flat sand's height, m

// Poses from a function of the tick: nullopt-like `valid = false` for a lost pose.
class ScriptedDevice final : public HapticDevice {
 public:
  ScriptedDevice(const DeviceLimits& limits, std::function<DeviceState(long tick)> pose)
      : limits_(limits), pose_(std::move(pose)) {}
  std::string name() const override { return "scripted"; }
  DeviceLimits limits() const override { return limits_; }
  DeviceState read(double now_s) override {
    DeviceState s = pose_(tick_++);
    s.t_s = now_s;
    s.position_m = limits_.workspace.clamp(s.position_m);
    return s;
  }
  void command_force(const ForceCommand&) override {}

 private:
  DeviceLimits limits_;
  std::function<DeviceState(long)> pose_;
  long tick_ = 0;
};

// A fixed-seed generator (the same numbers on every platform): uniform in [0, 1).
struct Lcg {
  std::uint64_t state = 0x9e3779b97f4a7c15ull;
  double next() {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<double>(state >> 11) * 0x1.0p-53;
  }
};

DeviceState at(double x, double y, double z) {
  DeviceState s;
  s.valid = true;
  s.position_m = Vec3(x, y, z);
  return s;
}

struct FaultyRun {
  double energy_j = 0.0, energy_max_j = 0.0, energy_bound_j = 0.0, force_max_n = 0.0;
  std::uint64_t jumps = 0, bounded = 0;
  bool finite = true;
};

// 20 s at 1 kHz of `pose` on flat sand as stiff as the device allows (a pure spring by
// default: no drag or friction to dissipate anything), republished every 7 ticks as the
// simulation does.
FaultyRun run(const std::function<DeviceState(long)>& pose, const DeviceLimits& lim,
              const Material& material = test::sand(1e5, 0.0, 0.0)) {
  ScriptedDevice device(lim, pose);
  PatchBuffer patches;
  const ForceParams params = ForceParams::from(material, test::disk(0.02));
  test::publish(patches, test::flat_patch(kSurface, kCentre, params));
  ServoCore core(device, patches, 40.0, RenderingOptions{}, kDt);
  core.start();
  FaultyRun r;
  std::uint64_t version = 1;
  for (long i = 0; i < 20000; ++i) {
    if (i % 7 == 0) {
      HeightPatch p = test::flat_patch(kSurface, kCentre + Vec2(0.0003 * ((i / 7) % 5), 0.0), params);
      p.version = ++version;
      test::publish(patches, p);
    }
    const ServoState s = core.step(static_cast<double>(i) * kDt);
    r.finite &= s.force_n.allFinite();
    r.force_max_n = std::max(r.force_max_n, s.force_n.norm());
    r.jumps += s.pose_jump;
    r.bounded += s.passivity_bounded;
  }
  r.energy_j = core.passivity().energy_j();
  r.energy_max_j = core.passivity().energy_max_j();
  r.energy_bound_j = core.passivity().energy_bound_j();
  return r;
}

// The pose streams. Teleports: every tick anywhere in a box around the tool's place, from
// 6 mm deep to 2 cm above the sand.
DeviceState teleport(Lcg& g) {
  const double x = kCentre.x() + 0.02 * (g.next() - 0.5), y = kCentre.y() + 0.02 * (g.next() - 0.5);
  return at(x, y, kSurface - 0.006 + 0.026 * g.next());
}

// The worst a stream within the speed limit can do to the controller: in and out of the sand
// by just less than the longest physical step, every tick (its velocity estimate, a low-pass,
// never sees the motion it has to damp).
DeviceState ratchet(long tick, double step_m) {
  return at(kCentre.x(), kCentre.y(), kSurface - (tick % 2 == 0 ? step_m : 0.0));
}

// A smooth press (1 to 3 mm deep at 2 Hz) as a lossy, reordering bridge delivers it: each
// pose is late by 0 to 4 ticks (so poses arrive out of order and the device shows an older
// one), one in 50 is dropped as lost for 3 ticks, one in 200 is corrupt (a random place).
DeviceState lossy_press(long tick, Lcg& g) {
  auto press = [](long k) {
    const double t = static_cast<double>(k) * kDt;
    return at(kCentre.x(), kCentre.y(), kSurface - 0.002 + 0.001 * std::cos(2.0 * std::numbers::pi * 2.0 * t));
  };
  const double u = g.next();
  if (u < 0.02) {
    DeviceState lost;
    lost.valid = false;
    return lost;
  }
  if (u < 0.025) return teleport(g);
  return press(std::max(0L, tick - static_cast<long>(5.0 * g.next())));
}

TEST(HapticsFaultyPoses, TheObserversEnergyStaysWithinItsBoundWhateverThePosesDo) {
  const DeviceLimits lim = test::limits(8.0, 2000.0);
  const double bound_j = lim.max_force_n * lim.max_speed_m_s * kDt;  // one tick at 8 N and 2 m/s
  const double step_m = 0.95 * lim.max_speed_m_s * kDt;
  Lcg g;
  const std::vector<std::pair<const char*, std::function<DeviceState(long)>>> streams = {
      {"teleports", [&](long) { return teleport(g); }},
      {"ratchet", [&](long t) { return ratchet(t, step_m); }},
      {"lossy press", [&](long t) { return lossy_press(t, g); }},
      {"mixed", [&](long t) { return t % 3 == 0   ? teleport(g)
                                     : t % 3 == 1 ? ratchet(t, step_m)
                                                  : lossy_press(t, g); }},
  };
  for (const auto& [name, pose] : streams) {
    for (const Material& material : {test::sand(1e5, 0.0, 0.0), test::sand()}) {
      const FaultyRun r = run(pose, lim, material);
      std::printf(
          "%s (drag %.0f): observer %.4g J, max %.4g J (bound %.4g J), force max %.2f N, %llu pose jumps, "
          "%llu ticks bounded\n",
          name, material.drag_n_s_per_m, r.energy_j, r.energy_max_j, r.energy_bound_j, r.force_max_n,
          static_cast<unsigned long long>(r.jumps), static_cast<unsigned long long>(r.bounded));
      EXPECT_TRUE(r.finite) << name;
      EXPECT_NEAR(r.energy_bound_j, bound_j, 1e-15);
      EXPECT_LE(r.energy_max_j, bound_j + 1e-12) << name;
      EXPECT_LE(r.force_max_n, 8.0 + 1e-12) << name;
    }
  }
}

TEST(HapticsFaultyPoses, WithoutTheSpeedLimitAndTheBoundTheSameStreamsCreateEnergy) {
  // What the bound and the jump detection are for: with neither (a device that claims any
  // speed is possible), teleports and the ratchet defeat the damping controller.
  DeviceLimits lim = test::limits(8.0, 2000.0);
  const double step_m = 0.95 * lim.max_speed_m_s * kDt;
  lim.max_speed_m_s = std::numeric_limits<double>::infinity();
  Lcg g;
  const FaultyRun teleports = run([&](long) { return teleport(g); }, lim);
  const FaultyRun ratchets = run([&](long t) { return ratchet(t, step_m); }, lim);
  std::printf("unbounded: teleports %.4g J, ratchet %.4g J\n", teleports.energy_j, ratchets.energy_j);
  EXPECT_EQ(teleports.jumps, 0u);
  EXPECT_GT(teleports.energy_j, 1.0);
  EXPECT_GT(ratchets.energy_j, 1.0);
}

TEST(HapticsFaultyPoses, SmoothMotionIsNeverAJumpAndNeverBounded) {
  // The stiff wall pressed at up to 4 mm and 3 Hz (as common_haptics_rendering_test), with
  // the sand's drag and friction: the rendering acts as before the bound existed.
  const DeviceLimits lim = test::limits(8.0, 2000.0);
  const FaultyRun r = run(
      [](long tick) {
        const double t = static_cast<double>(tick) * kDt;
        const double depth = 0.002 * (1.0 - std::cos(2.0 * std::numbers::pi * 3.0 * t)) - 0.0002;
        return at(kCentre.x(), kCentre.y(), kSurface - depth);
      },
      lim, test::sand(1e5));
  EXPECT_EQ(r.jumps, 0u);
  EXPECT_EQ(r.bounded, 0u);
  EXPECT_LE(r.energy_max_j, 1e-6);
  EXPECT_GT(r.force_max_n, 1.0);
}

TEST(HapticsFaultyPoses, ABoundedControllerScalesTheForceToWhatTheBoundLeaves) {
  // 1 mm per period at most, 8 N sent at most: the bound is 8 mJ. At E = 4 mJ a 6 N force may
  // add at most 4 mJ more: it goes out as 4 N.
  PassivityController pc(1.0, 0.001, 8.0);
  EXPECT_DOUBLE_EQ(pc.energy_bound_j(), 0.008);
  pc.observe(Vec3::Zero());
  pc.sent(Vec3(0, 0, 4.0));
  pc.observe(Vec3(0, 0, 0.001));  // E = 4 mJ
  ASSERT_NEAR(pc.energy_j(), 0.004, 1e-15);
  const Vec3 f = pc.control(Vec3(0, 0, -6.0), Vec3::Zero(), kDt);
  EXPECT_TRUE(pc.bounded_now());
  EXPECT_NEAR(f.z(), -4.0, 1e-12);
  // At E <= 0 even the largest force goes out as it is.
  PassivityController fresh(1.0, 0.001, 8.0);
  fresh.observe(Vec3::Zero());
  EXPECT_EQ(fresh.control(Vec3(0, 0, 8.0), Vec3::Zero(), kDt), Vec3(0, 0, 8.0));
  EXPECT_FALSE(fresh.bounded_now());
  // No step bound: no energy bound.
  PassivityController unbounded(1.0);
  unbounded.observe(Vec3::Zero());
  unbounded.sent(Vec3(0, 0, 4.0));
  unbounded.observe(Vec3(0, 0, 1.0));
  EXPECT_EQ(unbounded.control(Vec3(0, 0, -6.0), Vec3::Zero(), kDt), Vec3(0, 0, -6.0));
}

}  // namespace
}  // namespace sb::haptics
