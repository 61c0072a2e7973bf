#include "common/haptics/servo_core.hpp"

#include <cmath>
#include <numbers>

namespace sb::haptics {

ServoCore::ServoCore(HapticDevice& device, PatchBuffer& patches, double velocity_cutoff_hz)
    : device_(device), patches_(patches), limits_(device.limits()), cutoff_hz_(velocity_cutoff_hz) {}

ServoState ServoCore::step(double now_s) {
  ServoState s;
  s.tick = tick_++;
  s.t_s = now_s;
  s.device = device_.read(now_s);
  patches_.update();
  const HeightPatch& patch = patches_.front();
  s.patch_version = patch.version;

  if (s.device.valid && s.device.position_m.allFinite()) {
    if (have_prev_ && now_s > prev_t_s_) {
      const double dt = now_s - prev_t_s_;
      const Vec3 raw = (s.device.position_m - prev_position_) / dt;
      const double alpha = 1.0 - std::exp(-2.0 * std::numbers::pi * cutoff_hz_ * dt);
      velocity_ += alpha * (raw - velocity_);
    }
    have_prev_ = true;
    prev_position_ = s.device.position_m;
    prev_t_s_ = now_s;
    s.velocity_m_s = velocity_;
    s.model = compute_force(patch, s.device.position_m, velocity_, limits_.max_stiffness_n_per_m);
  } else {
    have_prev_ = false;
    velocity_.setZero();
  }

  const LimitedForce safe = limit_force(s.model.force_n, limits_.max_force_n);
  s.force_n = safe.force_n;
  s.clamped = safe.clamped;
  s.nonfinite = safe.nonfinite;
  ForceCommand cmd;
  cmd.force_n = s.force_n;
  cmd.t_s = now_s;
  cmd.in_contact = s.model.in_contact;
  cmd.clamped = safe.clamped;
  cmd.stale = !s.device.valid;
  device_.command_force(cmd);
  return s;
}

}  // namespace sb::haptics
