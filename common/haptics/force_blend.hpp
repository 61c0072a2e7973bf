#pragma once
// ForceBlend: the servo's continuity across height patches (Mark et al. 1996: a local
// representation updated at the simulation's rate, interpolated at the servo's). When a new
// patch arrives, the force model's output at the tool's unchanged position jumps by
// (old patch's force - new patch's force); the blend carries that difference as an offset
// added to the new patch's force and fades it linearly to zero over blend_s. A patch arriving
// mid-blend adds its jump to what is left and restarts the fade, so the offset never exceeds
// the sum of the recent jumps and each tick changes the force by at most |offset| / ticks
// left. O(1) per tick, no allocation.
#include "common/geometry.hpp"

namespace sb::haptics {

class ForceBlend {
 public:
  explicit ForceBlend(double blend_s = 0.0) : blend_s_(blend_s) {}

  // A new patch: the model's force jumped from `old_force` to `new_force` at the same pose.
  void jump(const Vec3& old_force, const Vec3& new_force) {
    if (blend_s_ <= 0.0) return;
    offset_ += old_force - new_force;
    remaining_s_ = blend_s_;
  }
  // Advances the fade by dt (call once per tick, after adding offset()).
  void advance(double dt) {
    if (remaining_s_ <= dt * (1.0 + 1e-9)) {  // the last tick of the fade, despite rounding
      offset_.setZero();
      remaining_s_ = 0.0;
    } else {
      offset_ *= 1.0 - dt / remaining_s_;
      remaining_s_ -= dt;
    }
  }
  void reset() {
    offset_.setZero();
    remaining_s_ = 0.0;
  }
  const Vec3& offset() const { return offset_; }
  bool active() const { return remaining_s_ > 0.0; }

 private:
  double blend_s_;
  Vec3 offset_{0.0, 0.0, 0.0};
  double remaining_s_ = 0.0;
};

}  // namespace sb::haptics
