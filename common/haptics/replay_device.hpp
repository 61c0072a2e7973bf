#pragma once
// ReplayDevice: plays a recorded trajectory as if a hand moved the device. Positions are
// interpolated linearly in time (buttons: the last sample at or before t); after the end the
// last pose is held. Time 0 is the servo loop's start, which plays the first sample. read() is
// O(1) amortised (a cursor that only moves forward).
#include <atomic>

#include "common/haptics/device.hpp"
#include "common/haptics/trajectory.hpp"

namespace sb::haptics {

class ReplayDevice final : public HapticDevice {
 public:
  ReplayDevice(Trajectory trajectory, const DeviceLimits& limits);

  std::string name() const override { return "replay"; }
  DeviceLimits limits() const override { return limits_; }
  void start() override { cursor_ = 0; }
  DeviceState read(double now_s) override;
  void command_force(const ForceCommand& command) override;

  // Readable from any thread.
  bool finished() const { return finished_.load(std::memory_order_relaxed); }
  double max_commanded_force_n() const { return max_force_n_.load(std::memory_order_relaxed); }
  double duration_s() const { return trajectory_.duration_s(); }

 private:
  Trajectory trajectory_;
  DeviceLimits limits_;
  std::size_t cursor_ = 0;  // servo thread only
  std::atomic<bool> finished_{false};
  std::atomic<double> max_force_n_{0.0};
};

}  // namespace sb::haptics
