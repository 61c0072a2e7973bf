#include "harness/render/camera.hpp"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <numbers>

namespace sb {

Mat4 look_at(const Vec3& eye, const Vec3& target, const Vec3& up) {
  const Vec3 f = (target - eye).normalized();
  const Vec3 s = f.cross(up).normalized();
  const Vec3 u = s.cross(f);
  Mat4 m = Mat4::Identity();
  m.block<1, 3>(0, 0) = s.transpose();
  m.block<1, 3>(1, 0) = u.transpose();
  m.block<1, 3>(2, 0) = -f.transpose();
  m(0, 3) = -s.dot(eye);
  m(1, 3) = -u.dot(eye);
  m(2, 3) = f.dot(eye);
  return m;
}

Mat4 perspective(double fov_y_rad, double aspect, double near, double far) {
  const double t = 1.0 / std::tan(fov_y_rad / 2.0);
  Mat4 m = Mat4::Zero();
  m(0, 0) = t / aspect;
  m(1, 1) = t;
  m(2, 2) = (far + near) / (near - far);
  m(2, 3) = 2.0 * far * near / (near - far);
  m(3, 2) = -1.0;
  return m;
}

Mat4 ortho(double l, double r, double b, double t, double n, double f) {
  Mat4 m = Mat4::Identity();
  m(0, 0) = 2.0 / (r - l);
  m(1, 1) = 2.0 / (t - b);
  m(2, 2) = -2.0 / (f - n);
  m(0, 3) = -(r + l) / (r - l);
  m(1, 3) = -(t + b) / (t - b);
  m(2, 3) = -(f + n) / (f - n);
  return m;
}

Vec3 light_direction() {
  const double deg = std::numbers::pi / 180.0, az = 315.0 * deg, alt = 45.0 * deg;
  return {std::sin(az) * std::cos(alt), std::cos(az) * std::cos(alt), std::sin(alt)};
}

namespace {
Mat4 matrix(const Camera& c, double aspect, const Vec3& origin) {
  const double near = std::max(1e-3, c.distance_m * 0.01), far = c.distance_m * 20.0 + 2.0;
  return perspective(c.fov_y_deg * std::numbers::pi / 180.0, aspect, near, far) *
         look_at(c.eye() - origin, c.target - origin, Vec3::UnitZ());
}
}  // namespace

Vec3 Camera::eye() const {
  const double cp = std::cos(pitch_rad);
  return target + distance_m * Vec3(cp * std::cos(yaw_rad), cp * std::sin(yaw_rad), std::sin(pitch_rad));
}

Eigen::Matrix4f Camera::view_projection(double aspect, const Vec3& origin) const {
  return matrix(*this, aspect, origin).cast<float>();
}

Ray Camera::pixel_ray(double x, double y, int width, int height) const {
  const double aspect = static_cast<double>(std::max(width, 1)) / std::max(height, 1);
  const Eigen::Matrix4d inv = matrix(*this, aspect, Vec3::Zero()).inverse();
  const double nx = 2.0 * x / std::max(width, 1) - 1.0, ny = 1.0 - 2.0 * y / std::max(height, 1);
  Eigen::Vector4d a = inv * Eigen::Vector4d(nx, ny, -1.0, 1.0);
  Eigen::Vector4d b = inv * Eigen::Vector4d(nx, ny, 1.0, 1.0);
  const Vec3 pa = a.head<3>() / a.w(), pb = b.head<3>() / b.w();
  return {pa, (pb - pa).normalized()};
}

}  // namespace sb
