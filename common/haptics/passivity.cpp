#include "common/haptics/passivity.hpp"

#include <algorithm>
#include <cmath>

namespace sb::haptics {

void PassivityController::observe(const Vec3& position) {
  if (have_position_) {
    energy_j_ += last_force_.dot(position - last_position_);
    energy_max_j_ = std::max(energy_max_j_, energy_j_);
  }
  have_position_ = true;
  last_position_ = position;
}

Vec3 PassivityController::control(const Vec3& force, const Vec3& velocity, double dt) {
  return bound(damp(force, velocity, dt));
}

Vec3 PassivityController::damp(const Vec3& force, const Vec3& velocity, double dt) {
  active_now_ = false;
  const double predicted = energy_j_ + force.dot(velocity) * dt;
  const double v2 = velocity.squaredNorm();
  if (predicted <= 0.0 || !(v2 * dt > 0.0) || max_force_n_ <= 0.0) return force;
  // alpha v with alpha = predicted / (|v|^2 dt); its size is predicted / (|v| dt).
  const double speed = std::sqrt(v2);
  const double size = std::min(predicted / (speed * dt), max_force_n_);
  active_now_ = true;
  ++active_;
  dissipated_j_ += size * speed * dt;
  return force - (size / speed) * velocity;
}

// The worst the next period can do: the force the device will send, times the longest step.
Vec3 PassivityController::bound(const Vec3& force) {
  bounded_now_ = false;
  if (max_step_m_ <= 0.0) return force;
  const double size = force.norm();
  const double allowed = std::max(0.0, energy_bound_j() - energy_j_) / max_step_m_;
  if (!(std::min(size, max_sent_n_) > allowed)) return force;
  bounded_now_ = true;
  ++bounded_;
  return force * (allowed / size);
}

}  // namespace sb::haptics
