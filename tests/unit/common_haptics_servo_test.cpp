// The servo: one tick (ServoCore) and the 1 kHz loop (ServoLoop) with a simulation-like
// publisher running beside it. Rates and timings are reported by the app, never asserted.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <thread>

#include "common/haptics/replay_device.hpp"
#include "common/haptics/servo_loop.hpp"
#include "common/haptics/shared_pose_device.hpp"
#include "common_haptics_test_support.hpp"

namespace sb::haptics {
namespace {

const Vec2 kCentre(0.3, 0.3);

DeviceLimits limits(double max_force_n = 4.0, double max_stiffness = 2000.0) {
  return test::limits(max_force_n, max_stiffness);
}

using test::publish;

TEST(HapticsServoCore, CommandsTheModelsForceWithinTheDeviceLimit) {
  SharedPoseDevice device("test", limits(4.0));
  PatchBuffer patches;
  const ForceParams params = ForceParams::from(test::sand(800.0), test::disk(0.02));
  publish(patches, test::flat_patch(0.1, kCentre, params));
  ServoCore core(device, patches, 40.0, test::raw_rendering());
  core.start();

  ServoState s = core.step(0.0);  // no pose yet: nothing
  EXPECT_FALSE(s.device.valid);
  EXPECT_EQ(s.force_n, Vec3::Zero());

  device.set_pose(Vec3(kCentre.x(), kCentre.y(), 0.1 - 0.002), 0);
  s = core.step(0.001);
  EXPECT_TRUE(s.model.in_contact);
  EXPECT_NEAR(s.force_n.z(), 800.0 * 0.002, 1e-9);
  EXPECT_FALSE(s.clamped);
  EXPECT_EQ(s.patch_version, 1u);

  device.set_pose(Vec3(kCentre.x(), kCentre.y(), 0.1 - 0.02), 0);  // 16 N asked, 4 N allowed
  s = core.step(0.002);
  EXPECT_TRUE(s.clamped);
  EXPECT_LE(s.force_n.norm(), 4.0);
  EXPECT_NEAR(s.force_n.norm(), 4.0, 1e-9);
  EXPECT_GT(s.model.force_n.norm(), 4.0);
  EXPECT_LE(device.max_commanded_force_n(), 4.0);
}

TEST(HapticsServoCore, EstimatesVelocityFromPositions) {
  SharedPoseDevice device("test", limits());
  PatchBuffer patches;
  publish(patches, test::flat_patch(0.0, kCentre, ForceParams::from(test::sand(), test::disk(0.02))));
  ServoCore core(device, patches, 40.0);
  core.start();
  const Vec3 v(0.05, -0.02, 0.01);
  ServoState s;
  for (int i = 0; i < 400; ++i) {
    const double t = i * 0.001;
    device.set_pose(Vec3(0.3, 0.3, 0.1) + t * v, 0);
    s = core.step(t);
  }
  EXPECT_TRUE(s.velocity_m_s.isApprox(v, 1e-6)) << s.velocity_m_s.transpose();
}

// The state holds everything the model's force was computed from: with the scene's
// parameters, k d z^ - b c v - mu k d v_xy / |v_xy| of the recorded penetration d, contact
// fraction c and velocity v is the model's force (what a calibration against other forces
// fits, experiments/haptic_calibration.py). A tool half a contact depth into the sand, so c < 1.
TEST(HapticsServoCore, StateHoldsWhatTheModelsForceWasComputedFrom) {
  SharedPoseDevice device("test", limits(100.0));
  PatchBuffer patches;
  const double k = 900.0, b = 7.0, mu = 0.3;
  publish(patches, test::flat_patch(0.1, kCentre, ForceParams::from(test::sand(k, b, mu), test::disk(0.02))));
  ServoCore core(device, patches, 40.0, test::raw_rendering());
  core.start();
  const Vec3 v(0.05, -0.02, -0.002);
  ServoState s;
  for (int i = 0; i < 300; ++i) {
    const double t = i * 0.001;
    device.set_pose(Vec3(kCentre.x(), kCentre.y(), 0.1 - 0.5 * kContactDepth_m) + t * v, 0);
    s = core.step(t);
  }
  ASSERT_TRUE(s.model.in_contact);
  EXPECT_FALSE(s.model.outside_patch);
  EXPECT_GT(s.model.contact_fraction, 0.1);
  EXPECT_LT(s.model.contact_fraction, 0.99);
  EXPECT_EQ(s.tool_velocity_m_s, s.velocity_m_s);  // no coupling: the device's own velocity
  const double d = s.model.penetration_m, c = s.model.contact_fraction;
  const Vec3& u = s.tool_velocity_m_s;
  const Vec2 along = u.head<2>() / std::max(u.head<2>().norm(), kFrictionVelocityEps);
  const Vec3 expected(-b * c * u.x() - mu * k * d * along.x(), -b * c * u.y() - mu * k * d * along.y(),
                      k * d - b * c * u.z());
  EXPECT_LT((s.model.force_n - expected).norm(), 1e-12 * expected.norm()) << s.model.force_n.transpose();
  EXPECT_EQ(s.model_force_n, s.model.force_n);  // no blend
}

// The loop with a replay device pressing into the sand and a second thread publishing
// patches all the while, as the simulation does. Every force must be finite and within the
// limit; the statistics must be coherent. The test waits for events (the replay played
// through, states read), with a generous deadline, never for a fixed time.
TEST(HapticsServoLoop, RunsBesideAPublisherAndKeepsForcesWithinLimits) {
  Trajectory t;
  for (int i = 0; i <= 100; ++i) {
    const double u = i / 100.0;
    t.samples.push_back({0.4 * u, Vec3(kCentre.x() + 0.02 * u, kCentre.y(), 0.105 - 0.03 * u), 0});
  }
  ReplayDevice device(t, limits(3.0, 1000.0));
  PatchBuffer patches;
  reserve_patches(patches, 49);
  const ForceParams params = ForceParams::from(test::sand(5000.0), test::disk(0.02));
  const HeightPatch flat = test::flat_patch(0.1, kCentre, params);
  publish(patches, flat);

  ServoOptions options;
  options.realtime = false;  // a test must not take the machine's real-time priority
  ServoLoop loop(device, patches, options);
  loop.set_recording(true);
  std::atomic<bool> stop{false};
  std::uint64_t published = 0;
  std::thread simulation([&] {
    HeightPatch p = flat;
    while (!stop.load()) {
      p.version = ++published + 1;
      publish(patches, p);
      std::this_thread::sleep_for(std::chrono::microseconds(300));
    }
  });
  loop.start();
  // Read what the servo publishes for the simulation, as it would, until the replay has
  // played through and held its last pose for 100 more ticks.
  std::uint64_t states = 0, last_tick = 0, finished_at = 0;
  bool finite = true;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < deadline) {
    if (loop.to_simulation().update()) {
      ++states;
      finite &= loop.to_simulation().front().force_n.allFinite();
      last_tick = loop.to_simulation().front().tick;
      if (device.finished() && finished_at == 0) finished_at = last_tick;
      if (finished_at > 0 && last_tick > finished_at + 100) break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  loop.stop();
  stop.store(true);
  simulation.join();

  const ServoStats s = loop.stats();
  ASSERT_GT(finished_at, 0u) << "the replay did not play through within 60 s";
  EXPECT_GT(s.ticks, finished_at + 100);
  EXPECT_GT(states, 0u);
  EXPECT_TRUE(finite);
  EXPECT_EQ(s.forces_nonfinite, 0u);
  EXPECT_LE(s.force_max_n, 3.0);
  EXPECT_LE(device.max_commanded_force_n(), 3.0);
  EXPECT_GT(s.force_max_n, 0.0);  // the replay pressed 2.5 cm into the sand
  EXPECT_GT(s.forces_clamped, 0u);
  EXPECT_GT(s.ticks_in_contact, 0u);
  EXPECT_EQ(s.force_limit_n, 3.0);
  EXPECT_GT(s.servo_hz, 0.0);
  EXPECT_GT(s.duration_s, 0.0);
  // Recording: every tick queued, in time order.
  ServoSample r;
  std::uint64_t samples = 0;
  double last_t = -1.0;
  bool ordered = true;
  bool contact_recorded = true;
  while (loop.samples().pop(r)) {
    // In sand the contact fraction is recorded with the penetration; out of it both are 0.
    contact_recorded &= (r.penetration_m > 0.0) == (r.contact_fraction > 0.0) && r.contact_fraction <= 1.0;
    ordered &= r.t_s > last_t;
    last_t = r.t_s;
    ++samples;
  }
  EXPECT_TRUE(ordered);
  EXPECT_TRUE(contact_recorded);
  EXPECT_EQ(samples + s.samples_dropped, s.ticks);
}

TEST(HapticsServoLoop, StopIsIdempotentAndStartsAgain) {
  SharedPoseDevice device("test", limits());
  PatchBuffer patches;
  ServoOptions options;
  options.realtime = false;
  ServoLoop loop(device, patches, options);
  loop.stop();
  loop.start();
  EXPECT_TRUE(loop.running());
  // Until the first tick is published (a generous deadline, not a fixed time).
  bool ticked = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (!ticked && std::chrono::steady_clock::now() < deadline) {
    ticked = loop.to_display().update();
    if (!ticked) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_TRUE(ticked);
  loop.stop();
  loop.stop();
  EXPECT_FALSE(loop.running());
  EXPECT_GT(loop.stats().ticks, 0u);
  EXPECT_EQ(loop.stats().ticks_without_pose, loop.stats().ticks);
  EXPECT_EQ(loop.stats().force_max_n, 0.0);
}

}  // namespace
}  // namespace sb::haptics
