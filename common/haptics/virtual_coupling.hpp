#pragma once
// Virtual coupling (Adams and Hannaford 1999): the force model pushes a simulated tool of mass
// m, which a spring-damper (k_c, b_c) ties to the device; the hand feels only the coupling,
//   f_hand = k_c (x_tool - x_device) + b_c (v_tool - v_device),
// so the stiffness it renders never exceeds k_c however stiff the sand (in series: k k_c /
// (k + k_c)). The tool is integrated with the coupling implicit (unconditionally stable in
// k_c and b_c) and the sand's force explicit; that part is stable while the sand's stiffness
// times dt^2 stays well below m (2000 N/m at 1 kHz against 0.02 kg: 0.1). O(1) per tick.
#include "common/geometry.hpp"

namespace sb::haptics {

class VirtualCoupling {
 public:
  VirtualCoupling(double stiffness_n_per_m, double damping_n_s_per_m, double mass_kg)
      : k_(stiffness_n_per_m), b_(damping_n_s_per_m), m_(mass_kg) {}

  // Puts the tool on the device, at rest relative to it.
  void reset(const Vec3& device_position, const Vec3& device_velocity) {
    x_ = device_position;
    v_ = device_velocity;
    valid_ = true;
  }
  bool valid() const { return valid_; }
  void invalidate() { valid_ = false; }
  const Vec3& tool_position() const { return x_; }
  const Vec3& tool_velocity() const { return v_; }

  // Advances the tool by dt under `sand_force` (evaluated at the tool) and the coupling to
  // the device's new pose; returns the force on the hand.
  Vec3 step(const Vec3& device_position, const Vec3& device_velocity, const Vec3& sand_force, double dt) {
    const Vec3 pull = k_ * (device_position - x_) + b_ * device_velocity;
    v_ = (m_ * v_ + dt * (sand_force + pull)) / (m_ + dt * b_ + dt * dt * k_);
    x_ += dt * v_;
    return k_ * (x_ - device_position) + b_ * (v_ - device_velocity);
  }

 private:
  double k_, b_, m_;
  Vec3 x_{0.0, 0.0, 0.0}, v_{0.0, 0.0, 0.0};
  bool valid_ = false;
};

}  // namespace sb::haptics
