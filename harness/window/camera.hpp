#pragma once
// The interactive window's orbit camera: a target point, yaw, pitch and distance. Gives the
// view-projection matrix (relative to a fixed origin, so float precision suffices) and the
// world ray under a pixel. O(1) per call.
#include <Eigen/Core>

#include "common/geometry.hpp"

namespace sb {

struct Ray {
  Vec3 origin{0.0, 0.0, 0.0};
  Vec3 direction{0.0, 0.0, 1.0};  // unit
};

struct Camera {
  Vec3 target{0.0, 0.0, 0.0};
  double yaw_rad = -2.356;  // looking along +x +y
  double pitch_rad = 0.75;  // above the horizon
  double distance_m = 0.4;
  double fov_y_deg = 40.0;

  Vec3 eye() const;
  // Projection * view, for points given relative to `origin`.
  Eigen::Matrix4f view_projection(double aspect, const Vec3& origin) const;
  // The ray through window pixel (x, y), origin at the top left.
  Ray pixel_ray(double x, double y, int width, int height) const;
};

}  // namespace sb
