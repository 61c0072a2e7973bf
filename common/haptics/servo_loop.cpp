#include "common/haptics/servo_loop.hpp"

#include <algorithm>
#include <cmath>

#include "common/haptics/precise_wait.hpp"

namespace sb::haptics {

using std::chrono::duration;
using std::chrono::nanoseconds;

ServoLoop::ServoLoop(HapticDevice& device, PatchBuffer& patches, const ServoOptions& options)
    : core_(device, patches, options.velocity_cutoff_hz, options.rendering, 1.0 / options.rate_hz),
      options_(options),
      samples_(options.record_capacity),
      onset_lag_(1.0 / options.rate_hz) {}

ServoLoop::~ServoLoop() { stop(); }

void ServoLoop::start() {
  if (thread_.joinable()) return;
  stop_.store(false);
  thread_ = std::thread([this] { run(); });
}

void ServoLoop::stop() {
  if (!thread_.joinable()) return;
  stop_.store(true);
  thread_.join();
}

ServoStats ServoLoop::stats() const {
  ServoStats s = stats_;
  s.tick_us_p50 = tick_us_.percentile(0.5);
  s.tick_us_p99 = tick_us_.percentile(0.99);
  s.tick_us_max = tick_us_.max();
  s.late_us_p50 = late_us_.percentile(0.5);
  s.late_us_p99 = late_us_.percentile(0.99);
  s.late_us_max = late_us_.max();
  s.force_limit_n = core_.limits().max_force_n;
  s.force_step_n_p99 = force_step_n_.percentile(0.99);
  s.force_step_n_p999 = force_step_n_.percentile(0.999);
  s.force_step_n_max = force_step_n_.max();
  s.force_error_n_p50 = force_error_n_.percentile(0.5);
  s.force_error_n_p99 = force_error_n_.percentile(0.99);
  s.force_error_n_max = force_error_n_.max();
  s.force_error_unblended_n_p50 = force_error_unblended_n_.percentile(0.5);
  s.force_error_unblended_n_p99 = force_error_unblended_n_.percentile(0.99);
  s.force_error_unblended_n_max = force_error_unblended_n_.max();
  s.onsets = onset_lag_.onsets();
  s.onset_lag_ms_max = 1e3 * onset_lag_.lag_max_s();
  s.onset_held_force_n = onset_lag_.held_force_n();
  return s;
}

void ServoLoop::run() {
  stats_ = ServoStats{};
  force_step_n_ = TickHistogram(0.001, 20.0);
  force_error_n_ = TickHistogram(0.001, 20.0);
  force_error_unblended_n_ = TickHistogram(0.001, 20.0);
  onset_lag_ = OnsetLag(1.0 / options_.rate_hz);
  stats_.realtime = options_.realtime && request_realtime();
  const auto period = std::chrono::duration_cast<nanoseconds>(duration<double>(1.0 / options_.rate_hz));
  const auto spin = std::chrono::duration_cast<nanoseconds>(duration<double, std::micro>(options_.spin_us));
  const auto t0 = ServoClock::now();
  core_.start();
  auto deadline = t0;  // scheduled start of the next tick
  auto first_start = t0, last_start = t0;
  auto rate_window_start = t0;
  std::uint64_t rate_window_ticks = 0;
  double servo_hz = 0.0;

  while (!stop_.load(std::memory_order_relaxed)) {
    wait_until(deadline, spin);
    const auto start = ServoClock::now();
    ServoState s = core_.step(duration<double>(start - t0).count());
    const bool record = recording_.load(std::memory_order_relaxed);
    if (record) {
      ServoSample r;
      r.t_s = s.t_s;
      r.position_m = s.device.position_m;
      r.buttons = s.device.buttons;
      r.valid = s.device.valid;
      r.force_n = s.force_n;
      r.penetration_m = s.model.penetration_m;
      r.model_force_n = s.model_force_n;
      r.contact_fraction = s.model.contact_fraction;
      r.model_velocity_m_s = s.tool_velocity_m_s;
      if (!samples_.push(r)) ++stats_.samples_dropped;
    }

    // Bookkeeping (counted in the tick's duration: it is part of the loop's work).
    if (stats_.ticks == 0) first_start = start;
    last_start = start;
    ++stats_.ticks;
    const double force = s.force_n.norm();
    stats_.force_max_n = std::max(stats_.force_max_n, force);
    stats_.forces_clamped += s.clamped;
    stats_.forces_nonfinite += s.nonfinite;
    stats_.ticks_in_contact += s.model.in_contact;
    stats_.ticks_without_pose += !s.device.valid;
    stats_.ticks_outside_patch += s.model.outside_patch;
    force_step_n_.add(s.force_step_n);
    if (s.device.valid) {
      const double limit = core_.limits().max_force_n;
      const Vec3 model = limit_force(s.model_force_n, limit).force_n;
      force_error_n_.add((s.force_n - model).norm());
      force_error_unblended_n_.add((s.force_n - limit_force(s.model.force_n, limit).force_n).norm());
      onset_lag_.add(model.norm(), s.force_n.norm());
    }
    stats_.patch_switches += s.patch_switched;
    stats_.ticks_rate_limited += s.rate_limited;
    stats_.pose_jumps += s.pose_jump;
    late_us_.add(duration<double, std::micro>(start - deadline).count());
    if (++rate_window_ticks, start - rate_window_start >= std::chrono::seconds(1)) {
      servo_hz = static_cast<double>(rate_window_ticks - 1) / duration<double>(start - rate_window_start).count();
      rate_window_start = start;
      rate_window_ticks = 1;
    }
    s.missed_deadlines = stats_.missed_deadlines;
    s.force_max_n = stats_.force_max_n;
    s.servo_hz = servo_hz;
    s.tick_us_max = tick_us_.max();
    const auto end_before_publish = ServoClock::now();
    s.tick_us = duration<double, std::micro>(end_before_publish - start).count();
    to_simulation_.back() = s;
    to_simulation_.publish();
    to_display_.back() = s;
    to_display_.publish();

    const auto end = ServoClock::now();
    tick_us_.add(duration<double, std::micro>(end - start).count());
    deadline += period;
    if (end > deadline) {
      // The force went out after the next period began: a missed deadline. Periods that
      // passed entirely (the thread was not running) are skipped, not run back to back, and
      // count as missed too; so the rate is that of periods actually served.
      const auto skipped = (end - deadline) / period;
      stats_.missed_deadlines += 1 + static_cast<std::uint64_t>(skipped);
      deadline += skipped * period;
    }
  }
  onset_lag_.finish();
  stats_.duration_s = duration<double>(last_start - first_start).count();
  const PassivityController& pc = core_.passivity();
  stats_.passivity_energy_j = pc.energy_j();
  stats_.passivity_energy_max_j = pc.energy_max_j();
  stats_.passivity_dissipated_j = pc.dissipated_j();
  stats_.passivity_ticks_active = pc.active_ticks();
  stats_.passivity_ticks_bounded = pc.bounded_ticks();
  stats_.passivity_energy_bound_j = pc.energy_bound_j();
  stats_.servo_hz =
      stats_.ticks > 1 && stats_.duration_s > 0.0 ? static_cast<double>(stats_.ticks - 1) / stats_.duration_s : 0.0;
}

}  // namespace sb::haptics
