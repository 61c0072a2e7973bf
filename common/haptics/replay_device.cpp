#include "common/haptics/replay_device.hpp"

#include <stdexcept>

namespace sb::haptics {

ReplayDevice::ReplayDevice(Trajectory trajectory, const DeviceLimits& limits)
    : trajectory_(std::move(trajectory)), limits_(limits) {
  if (trajectory_.samples.empty()) throw std::invalid_argument("ReplayDevice: empty trajectory");
}

DeviceState ReplayDevice::read(double now_s) {
  const auto& s = trajectory_.samples;
  const double t = s.front().t_s + now_s;
  while (cursor_ + 1 < s.size() && s[cursor_ + 1].t_s <= t) ++cursor_;
  DeviceState out;
  out.valid = true;
  out.t_s = now_s;
  out.buttons = s[cursor_].buttons;
  if (cursor_ + 1 >= s.size()) {
    out.position_m = s.back().position_m;
    finished_.store(true, std::memory_order_relaxed);
  } else {
    const TrajectorySample& a = s[cursor_];
    const TrajectorySample& b = s[cursor_ + 1];
    const double span = b.t_s - a.t_s;
    const double u = span > 0.0 ? std::clamp((t - a.t_s) / span, 0.0, 1.0) : 0.0;
    out.position_m = a.position_m + u * (b.position_m - a.position_m);
  }
  out.position_m = limits_.workspace.clamp(out.position_m);
  return out;
}

void ReplayDevice::command_force(const ForceCommand& command) {
  const double f = command.force_n.norm();
  if (f > max_force_n_.load(std::memory_order_relaxed)) max_force_n_.store(f, std::memory_order_relaxed);
}

}  // namespace sb::haptics
