#pragma once
// ServoCore: one servo tick without the clock -- read the device, estimate its velocity, take
// the newest height patch, compute the force, make it safe (finite, within the device's
// force limit) and command it. ServoLoop calls it at 1 kHz; tests and benchmarks call it
// directly. A tick costs two virtual calls, one atomic exchange and the force model.
#include <cstdint>

#include "common/haptics/device.hpp"
#include "common/haptics/force_model.hpp"
#include "common/haptics/height_patch.hpp"

namespace sb::haptics {

// What one tick produced; the servo publishes it to the simulation and the display.
struct ServoState {
  std::uint64_t tick = 0;
  double t_s = 0.0;
  DeviceState device;
  Vec3 velocity_m_s{0.0, 0.0, 0.0};
  Vec3 force_n{0.0, 0.0, 0.0};  // as commanded
  ForceOutput model;            // the model's view (its force before limiting)
  bool clamped = false;
  bool nonfinite = false;  // the model's force was not finite; zero was sent
  std::uint64_t patch_version = 0;
  // Running counters of the loop (filled by ServoLoop).
  std::uint64_t missed_deadlines = 0;
  double tick_us = 0.0, tick_us_max = 0.0, servo_hz = 0.0, force_max_n = 0.0;
};

class ServoCore {
 public:
  // velocity_cutoff_hz: first-order low-pass on the differentiated position.
  ServoCore(HapticDevice& device, PatchBuffer& patches, double velocity_cutoff_hz = 40.0);

  void start() { device_.start(); }
  ServoState step(double now_s);
  const DeviceLimits& limits() const { return limits_; }
  HapticDevice& device() { return device_; }

 private:
  HapticDevice& device_;
  PatchBuffer& patches_;
  DeviceLimits limits_;
  double cutoff_hz_;
  std::uint64_t tick_ = 0;
  bool have_prev_ = false;
  Vec3 prev_position_{0.0, 0.0, 0.0};
  double prev_t_s_ = 0.0;
  Vec3 velocity_{0.0, 0.0, 0.0};
};

}  // namespace sb::haptics
