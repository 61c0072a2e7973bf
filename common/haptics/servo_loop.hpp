#pragma once
// ServoLoop: the 1 kHz haptic thread. Each period it runs one ServoCore tick and publishes the
// result to the simulation and to the display (one TripleBuffer each), optionally queues a
// sample for recording, and measures itself: tick durations, lateness of its wake-ups,
// achieved rate and missed deadlines (a tick whose force went out after the next period
// began, plus every period skipped because the thread did not run; late periods are never
// run back to back). It never waits on the simulation -- no mutex, no allocation on its
// path -- and waits for its deadlines by sleeping until shortly before them, then spinning.
#include <atomic>
#include <cstdint>
#include <thread>

#include "common/haptics/onset_lag.hpp"
#include "common/haptics/servo_core.hpp"
#include "common/haptics/spsc_ring.hpp"
#include "common/haptics/tick_histogram.hpp"
#include "common/haptics/triple_buffer.hpp"

namespace sb::haptics {

struct ServoOptions {
  double rate_hz = 1000.0;
  double spin_us = 150.0;  // spin this long before each deadline
  bool realtime = true;    // ask for SCHED_FIFO (silently not, when refused)
  double velocity_cutoff_hz = 40.0;
  std::size_t record_capacity = 1u << 17;  // samples queued for the recorder (131 s at 1 kHz)
  RenderingOptions rendering;              // blend, rate limit, passivity, coupling
};

// One tick as recorded: the device trajectory plus the force sent.
struct ServoSample {
  double t_s = 0.0;
  Vec3 position_m{0.0, 0.0, 0.0};
  std::uint32_t buttons = 0;
  bool valid = false;
  Vec3 force_n{0.0, 0.0, 0.0};
  double penetration_m = 0.0;
  Vec3 model_force_n{0.0, 0.0, 0.0};  // ServoState::model_force_n
  // The rest of what the model's force on the newest patch was computed from (with
  // penetration_m and the scene's parameters): its contact fraction and velocity.
  double contact_fraction = 0.0;
  Vec3 model_velocity_m_s{0.0, 0.0, 0.0};  // ServoState::tool_velocity_m_s
};

// The haptic statistics of README "Interactive mode and haptics" (servo_hz, tick_us.*, missed_deadlines, force_max_n)
// and a few more.
struct ServoStats {
  std::uint64_t ticks = 0;
  double duration_s = 0.0;                                         // first to last tick start
  double servo_hz = 0.0;                                           // (ticks - 1) / duration_s
  double tick_us_p50 = 0.0, tick_us_p99 = 0.0, tick_us_max = 0.0;  // work per tick
  double late_us_p50 = 0.0, late_us_p99 = 0.0, late_us_max = 0.0;  // wake-up after deadline
  std::uint64_t missed_deadlines = 0;
  double force_max_n = 0.0;    // largest force commanded
  double force_limit_n = 0.0;  // the device's limit
  std::uint64_t forces_clamped = 0, forces_nonfinite = 0;
  std::uint64_t ticks_in_contact = 0, ticks_without_pose = 0, ticks_outside_patch = 0;
  std::uint64_t samples_dropped = 0;  // recording queue full
  bool realtime = false;              // SCHED_FIFO granted
  // Continuity: |force(n) - force(n-1)| over all ticks (1 mN bins), and what shaped it.
  double force_step_n_p99 = 0.0, force_step_n_p999 = 0.0, force_step_n_max = 0.0;
  std::uint64_t patch_switches = 0, ticks_rate_limited = 0;
  std::uint64_t pose_jumps = 0;  // poses that moved faster than the device's max_speed_m_s (servo_core.hpp)
  // Fidelity: |force sent - the model's force at the same pose| over the ticks with a pose
  // (1 mN bins), against the model with the patch blend (ServoState::model_force_n) and
  // without it (the model on the newest patch alone); both model forces are first passed
  // through the device's force limit, which no rendering can exceed.
  double force_error_n_p50 = 0.0, force_error_n_p99 = 0.0, force_error_n_max = 0.0;
  double force_error_unblended_n_p50 = 0.0, force_error_unblended_n_p99 = 0.0, force_error_unblended_n_max = 0.0;
  // Contact onsets (onset_lag.hpp): how many, the largest lag of the force sent behind the
  // model's in reaching 90 % of the held force, and the last onset's held force.
  std::uint64_t onsets = 0;
  double onset_lag_ms_max = 0.0, onset_held_force_n = 0.0;
  // Passivity (passivity.hpp): the observer's energy at the end and at most (J, > 0: energy
  // was created), the damping the controller added, the energy bound and the ticks it acted.
  double passivity_energy_j = 0.0, passivity_energy_max_j = 0.0, passivity_dissipated_j = 0.0;
  double passivity_energy_bound_j = 0.0;
  std::uint64_t passivity_ticks_active = 0, passivity_ticks_bounded = 0;
};

class ServoLoop {
 public:
  ServoLoop(HapticDevice& device, PatchBuffer& patches, const ServoOptions& options = {});
  ~ServoLoop();
  ServoLoop(const ServoLoop&) = delete;
  ServoLoop& operator=(const ServoLoop&) = delete;

  void start();
  void stop();  // joins; idempotent
  bool running() const { return thread_.joinable(); }

  // One reader each.
  TripleBuffer<ServoState>& to_simulation() { return to_simulation_; }
  TripleBuffer<ServoState>& to_display() { return to_display_; }
  // Consumer: one thread. Filled only while recording is on.
  SpscRing<ServoSample>& samples() { return samples_; }
  void set_recording(bool on) { recording_.store(on, std::memory_order_relaxed); }

  // Complete after stop(); while running, only the counters visible in ServoState are kept.
  ServoStats stats() const;
  const DeviceLimits& limits() const { return core_.limits(); }

 private:
  void run();

  ServoCore core_;
  ServoOptions options_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> recording_{false};
  TripleBuffer<ServoState> to_simulation_, to_display_;
  SpscRing<ServoSample> samples_;
  // Servo thread only until joined.
  TickHistogram tick_us_, late_us_;
  TickHistogram force_step_n_{0.001, 20.0};
  TickHistogram force_error_n_{0.001, 20.0}, force_error_unblended_n_{0.001, 20.0};
  OnsetLag onset_lag_;
  ServoStats stats_;
};

}  // namespace sb::haptics
