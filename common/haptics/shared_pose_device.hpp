#pragma once
// SharedPoseDevice: a device whose pose another thread sets -- the mouse in the interactive
// app, or a test. set_pose() (one writer thread) and read() (the servo) hand the pose over
// through a TripleBuffer: neither waits. The forces commanded are only remembered (for
// display); a mouse cannot push back.
#include <atomic>

#include "common/haptics/device.hpp"
#include "common/haptics/triple_buffer.hpp"

namespace sb::haptics {

class SharedPoseDevice final : public HapticDevice {
 public:
  SharedPoseDevice(std::string name, const DeviceLimits& limits) : name_(std::move(name)), limits_(limits) {}

  std::string name() const override { return name_; }
  DeviceLimits limits() const override { return limits_; }
  DeviceState read(double now_s) override {
    poses_.update();
    DeviceState s = poses_.front();
    s.t_s = now_s;
    s.position_m = limits_.workspace.clamp(s.position_m);
    return s;
  }
  void command_force(const ForceCommand& command) override {
    const double f = command.force_n.norm();
    if (f > max_force_n_.load(std::memory_order_relaxed)) max_force_n_.store(f, std::memory_order_relaxed);
  }

  // Writer thread: the new pose (valid is set).
  void set_pose(const Vec3& position_m, std::uint32_t buttons) {
    DeviceState& s = poses_.back();
    s.position_m = position_m;
    s.buttons = buttons;
    s.valid = true;
    poses_.publish();
  }
  double max_commanded_force_n() const { return max_force_n_.load(std::memory_order_relaxed); }

 private:
  std::string name_;
  DeviceLimits limits_;
  TripleBuffer<DeviceState> poses_;
  std::atomic<double> max_force_n_{0.0};
};

}  // namespace sb::haptics
