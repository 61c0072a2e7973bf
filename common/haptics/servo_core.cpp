#include "common/haptics/servo_core.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace sb::haptics {

ServoCore::ServoCore(HapticDevice& device, PatchBuffer& patches, double velocity_cutoff_hz,
                     const RenderingOptions& rendering, double period_s)
    : device_(device),
      patches_(patches),
      limits_(device.limits()),
      cutoff_hz_(velocity_cutoff_hz),
      rendering_(rendering),
      period_s_(period_s),
      blend_(rendering.blend_s),
      passivity_(rendering.passivity_max_force_n, limits_.max_speed_m_s * period_s, limits_.max_force_n),
      coupling_(rendering.coupling_stiffness_n_per_m, rendering.coupling_damping_n_s_per_m, rendering.tool_mass_kg) {}

ServoState ServoCore::step(double now_s) {
  ServoState s;
  s.tick = tick_++;
  s.t_s = now_s;
  s.device = device_.read(now_s);

  Vec3 force = Vec3::Zero();
  if (s.device.valid && s.device.position_m.allFinite()) {
    double dt = 0.0;
    if (have_prev_ &&
        (s.device.position_m - prev_position_).norm() > limits_.max_speed_m_s * std::max(0.0, now_s - prev_t_s_)) {
      s.pose_jump = true;
      restart_rendering();
      have_prev_ = false;
    }
    if (have_prev_ && now_s > prev_t_s_) {
      dt = now_s - prev_t_s_;
      const Vec3 raw = (s.device.position_m - prev_position_) / dt;
      const double alpha = 1.0 - std::exp(-2.0 * std::numbers::pi * cutoff_hz_ * dt);
      velocity_ += alpha * (raw - velocity_);
    }
    have_prev_ = true;
    prev_position_ = s.device.position_m;
    prev_t_s_ = now_s;
    s.velocity_m_s = velocity_;
    force = render(s, dt);
  } else {
    // No pose: no force at once (not faded), and every rendering state starts afresh.
    have_prev_ = false;
    patches_.update();
    restart_rendering();
  }
  s.patch_version = patches_.front().version;

  const LimitedForce safe = limit_force(force, limits_.max_force_n);
  s.force_n = safe.force_n;
  s.clamped = safe.clamped;
  s.nonfinite = safe.nonfinite;
  s.force_step_n = (s.force_n - last_force_).norm();
  last_force_ = s.force_n;
  passivity_.sent(s.force_n);
  s.passivity_energy_j = passivity_.energy_j();
  ForceCommand cmd;
  cmd.force_n = s.force_n;
  cmd.t_s = now_s;
  cmd.in_contact = s.model.in_contact;
  cmd.clamped = safe.clamped;
  cmd.stale = !s.device.valid;
  device_.command_force(cmd);
  return s;
}

void ServoCore::restart_rendering() {
  velocity_.setZero();
  blend_.reset();
  coupling_.invalidate();
  passivity_.lose_pose();
  last_rendered_.setZero();
}

// The rendering pipeline of rendering.hpp for a tick with a valid pose; dt: time since the
// previous valid tick (0 on the first).
Vec3 ServoCore::render(ServoState& s, double dt) {
  const Vec3& device_x = s.device.position_m;
  const double fade_dt = std::min(dt, period_s_);  // a late tick fades no further than one period
  const bool coupled = rendering_.coupling;
  if (coupled && !coupling_.valid()) coupling_.reset(device_x, velocity_);
  const Vec3 x = coupled ? coupling_.tool_position() : device_x;
  const Vec3 v = coupled ? coupling_.tool_velocity() : velocity_;
  s.tool_position_m = x;
  s.tool_velocity_m_s = v;

  // The model on the patch the servo holds, and when a newer one is waiting, on that one too:
  // the difference at the same pose is the jump the blend fades out.
  const double k_max = limits_.max_stiffness_n_per_m;
  s.model = compute_force(patches_.front(), x, v, k_max);
  if (patches_.pending()) {
    const bool had_patch = patches_.front().valid;
    const Vec3 old_force = s.model.force_n;
    patches_.update();
    s.patch_switched = true;
    s.model = compute_force(patches_.front(), x, v, k_max);
    if (had_patch && old_force.allFinite() && s.model.force_n.allFinite()) blend_.jump(old_force, s.model.force_n);
  }
  s.blend_offset_n = blend_.offset();
  const Vec3 sand = s.model.force_n + blend_.offset();
  s.model_force_n = sand;
  blend_.advance(fade_dt);
  if (!sand.allFinite()) {  // sent as zero (and counted) by limit_force
    blend_.reset();
    coupling_.invalidate();
    last_rendered_.setZero();
    return Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  }

  Vec3 f = coupled ? coupling_.step(device_x, velocity_, sand, dt) : sand;
  const double max_step = rendering_.max_force_rate_n_per_s * period_s_;
  if (max_step > 0.0) {
    const Vec3 change = f - last_rendered_;
    const double size = change.norm();
    if (size > max_step) {
      f = last_rendered_ + change * (max_step / size);
      s.rate_limited = true;
    }
  }
  last_rendered_ = f;
  // Passivity comes last and is not rate-limited: the controller must be able to dissipate
  // at once what the sampling, the blend and the limit above created. It acts only when the
  // observer would otherwise go positive (never on the replayed stroke: the sand's drag and
  // friction keep the observer far below zero).
  passivity_.observe(device_x);
  if (rendering_.passivity) {
    f = passivity_.control(f, velocity_, period_s_);
    s.passivity_active = passivity_.active_now();
    s.passivity_bounded = passivity_.bounded_now();
  }
  return f;
}

}  // namespace sb::haptics
