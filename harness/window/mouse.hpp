#pragma once
// The mouse standing in for a haptic device: the cursor's ray meets the scene's initial
// surface for x and y (the initial surface, not the deforming one, so the tool does not sink
// into its own trench); the depth below that surface comes from the wheel or the keys. The
// pose goes to a SharedPoseDevice that the servo reads. O(ray march) per frame.
#include <optional>

#include "common/haptics/shared_pose_device.hpp"
#include "common/height_field.hpp"
#include "harness/render/camera.hpp"

namespace sb {

class MouseTool {
 public:
  MouseTool(haptics::SharedPoseDevice& device, const HeightField& initial);

  // ray: under the cursor, or none while the cursor is over the panel (the tool stays).
  void update(const std::optional<Ray>& ray, bool primary_button);
  void adjust_depth(double delta_m);
  double depth_m() const { return depth_m_; }  // below the initial surface; negative: above
  const Vec3& position() const { return position_; }

 private:
  haptics::SharedPoseDevice& device_;
  const HeightField& initial_;
  Vec2 xy_;
  double depth_m_ = -0.005;
  Vec3 position_{0.0, 0.0, 0.0};
};

// First hit of a ray with a height field z = f(x, y) inside its domain: a march plus
// bisection. None when the ray misses.
std::optional<Vec2> intersect_height_field(const Ray& ray, const HeightField& field);

}  // namespace sb
