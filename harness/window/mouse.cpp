#include "harness/window/mouse.hpp"

#include <cmath>

namespace sb {

std::optional<Vec2> intersect_height_field(const Ray& ray, const HeightField& field) {
  const Aabb2 box = field.domain().box();
  const double reach = 4.0 * (box.hi - box.lo).norm() + (ray.origin.head<2>() - box.lo).norm();
  const int steps = 1024;
  auto below = [&](double t) {
    const Vec3 p = ray.origin + t * ray.direction;
    return p.z() <= field(p.head<2>());
  };
  double prev = 0.0;
  for (int i = 1; i <= steps; ++i) {
    const double t = reach * i / steps;
    const Vec3 p = ray.origin + t * ray.direction;
    if (!box.contains(p.head<2>())) {
      prev = t;
      continue;
    }
    if (below(t)) {
      double lo = prev, hi = t;
      for (int k = 0; k < 40; ++k) {
        const double mid = 0.5 * (lo + hi);
        (below(mid) ? hi : lo) = mid;
      }
      const Vec2 xy = (ray.origin + hi * ray.direction).head<2>();
      return box.contains(xy) ? std::optional<Vec2>(xy) : std::nullopt;
    }
    prev = t;
  }
  return std::nullopt;
}

MouseTool::MouseTool(haptics::SharedPoseDevice& device, const HeightField& initial)
    : device_(device), initial_(initial) {
  const Aabb2 box = initial.domain().box();
  xy_ = 0.5 * (box.lo + box.hi);
  position_ = Vec3(xy_.x(), xy_.y(), initial_(xy_) - depth_m_);
}

void MouseTool::update(const std::optional<Ray>& ray, bool primary_button) {
  if (ray) {
    if (const auto hit = intersect_height_field(*ray, initial_)) xy_ = *hit;
  }
  position_ = Vec3(xy_.x(), xy_.y(), initial_(xy_) - depth_m_);
  device_.set_pose(position_, primary_button ? 1u : 0u);
}

void MouseTool::adjust_depth(double delta_m) { depth_m_ = std::clamp(depth_m_ + delta_m, -0.05, 0.1); }

}  // namespace sb
