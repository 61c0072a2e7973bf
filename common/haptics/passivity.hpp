#pragma once
// Time-domain passivity observer and controller (Hannaford and Ryu 2002) at the device port.
//
// Observer: E = sum over ticks of f(n-1) . (x(n) - x(n-1)), the work the device's force did on
// the hand -- exact for a force held constant over each period (zero-order hold) and any
// motion. A passive rendering never makes E positive: the sand may give back at most what
// the hand put in. Sampling, patch blending and rate limiting can each return a little more
// (a sampled spring already does: its force lags the motion), so
// Controller: before a force f goes out, the work it would do over the next period is
// predicted from the device velocity v; if E + f . v dt > 0, a damping force -alpha v with
// alpha = (E + f . v dt) / (|v|^2 dt) is added (at most max_force_n), which dissipates the
// excess. The observer then books the force actually sent. O(1) per tick.
//
// The controller's prediction assumes the motion of the next period continues the present
// velocity. Poses that do not (a device stream that drops, reorders or corrupts packets, and
// steps back and forth within the physical speed limit) can defeat it, tick after tick, and
// E would then grow without end. Hence the energy bound: the hand moves at most max_step_m in
// one period and the device sends at most max_sent_n, so a force f adds at most
// min(|f|, max_sent_n) max_step_m to E; before a force goes out it is scaled down so that this
// keeps E within energy_bound_j() = max_sent_n max_step_m, one period of the largest force at
// the fastest motion. While E <= 0 (whenever the controller above did its job) the bound never
// acts; it acts only on what the controller could not dissipate, and E <= energy_bound_j()
// whatever the poses do (for ticks on time: a late tick can add |f| times the extra distance
// the hand covered). Pose steps beyond the physical speed are not motion: ServoCore restarts
// the observer at the new pose (lose_pose) instead of booking them.
#include <cstdint>

#include "common/geometry.hpp"

namespace sb::haptics {

class PassivityController {
 public:
  // max_force_n: the largest damping force. max_step_m: the farthest the hand can move in one
  // period (0: no energy bound); max_sent_n: the device's force limit, which the servo applies
  // to what this returns.
  explicit PassivityController(double max_force_n = 1.0, double max_step_m = 0.0, double max_sent_n = 0.0)
      : max_force_n_(max_force_n), max_step_m_(max_step_m), max_sent_n_(max_sent_n) {}

  // The device moved to `position`: books the work of the force sent last tick.
  void observe(const Vec3& position);
  // The force to send instead of `force` (damping added when needed, then scaled to the
  // energy bound); v: device velocity.
  Vec3 control(const Vec3& force, const Vec3& velocity, double dt);
  // The force actually sent this tick (after rate limiting and the device's force limit).
  void sent(const Vec3& force) { last_force_ = force; }
  // No pose: nothing is booked until the next valid position (E is kept).
  void lose_pose() {
    have_position_ = false;
    last_force_.setZero();
  }

  double energy_j() const { return energy_j_; }          // E, J (> 0: energy was created)
  double energy_max_j() const { return energy_max_j_; }  // largest E seen
  double energy_bound_j() const { return max_sent_n_ * max_step_m_; }
  double dissipated_j() const { return dissipated_j_; }   // predicted work of the added damping
  std::uint64_t active_ticks() const { return active_; }  // ticks that added damping
  bool active_now() const { return active_now_; }
  std::uint64_t bounded_ticks() const { return bounded_; }  // ticks the energy bound scaled down
  bool bounded_now() const { return bounded_now_; }

 private:
  Vec3 damp(const Vec3& force, const Vec3& velocity, double dt);
  Vec3 bound(const Vec3& force);

  double max_force_n_;
  double max_step_m_;
  double max_sent_n_;
  bool have_position_ = false;
  Vec3 last_position_{0.0, 0.0, 0.0};
  Vec3 last_force_{0.0, 0.0, 0.0};
  double energy_j_ = 0.0, energy_max_j_ = 0.0, dissipated_j_ = 0.0;
  std::uint64_t active_ = 0, bounded_ = 0;
  bool active_now_ = false, bounded_now_ = false;
};

}  // namespace sb::haptics
