#pragma once
// The one camera and light of every picture, offscreen or in the window: look-at,
// perspective and orthographic matrices (Eigen, double precision, OpenGL conventions),
// the window's orbit camera, and the light with its ambient and diffuse weights. O(1) per call.
#include <Eigen/Core>

#include "common/geometry.hpp"

namespace sb {

using Mat4 = Eigen::Matrix4d;

// View matrix: eye looking at target, `up` towards the top of the picture.
Mat4 look_at(const Vec3& eye, const Vec3& target, const Vec3& up);
// Projections onto OpenGL clip space; fov_y_rad is the full vertical field of view.
Mat4 perspective(double fov_y_rad, double aspect, double near, double far);
Mat4 ortho(double left, double right, double bottom, double top, double near, double far);

// The light: from the north-west, 45 degrees above the horizon (GIS hillshade convention);
// shade = ambient + diffuse * max(0, n . light). Exposed so tests can compare with a raster.
Vec3 light_direction();
inline constexpr double kAmbient = 0.30;
inline constexpr double kDiffuse = 0.75;

struct Ray {
  Vec3 origin{0.0, 0.0, 0.0};
  Vec3 direction{0.0, 0.0, 1.0};  // unit
};

// The interactive window's orbit camera: a target point, yaw, pitch and distance. Gives the
// view-projection matrix (relative to a fixed origin, so float precision suffices) and the
// world ray under a pixel.
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
