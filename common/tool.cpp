#include "common/tool.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace sb {

std::string to_string(ToolShape s) {
  switch (s) {
    case ToolShape::Disk:
      return "disk";
    case ToolShape::Box:
      return "box";
    case ToolShape::Ellipse:
      return "ellipse";
    case ToolShape::Polygon:
      return "polygon";
    case ToolShape::Pour:
      return "pour";
  }
  return "?";
}

std::string to_string(BottomProfile p) { return p == BottomProfile::Flat ? "flat" : "sphere_cap"; }

std::vector<Vec2> ToolSpec::footprint_local() const {
  std::vector<Vec2> poly;
  auto ngon = [&](double ax, double ay) {
    for (int k = 0; k < sides; ++k) {
      const double t = 2.0 * std::numbers::pi * k / sides;
      poly.emplace_back(ax * std::cos(t), ay * std::sin(t));
    }
  };
  switch (shape) {
    case ToolShape::Disk:
      ngon(radius_m, radius_m);
      break;
    case ToolShape::Ellipse:
      ngon(half_size_m.x(), half_size_m.y());
      break;
    case ToolShape::Box: {
      const double hx = half_size_m.x(), hy = half_size_m.y();
      poly = {{-hx, -hy}, {hx, -hy}, {hx, hy}, {-hx, hy}};
      break;
    }
    case ToolShape::Polygon:
      poly = make_ccw(polygon_m);
      break;
    case ToolShape::Pour:
      break;
  }
  return poly;
}

double ToolStamp::bottom_z(const Vec2& p) const {
  if (profile == BottomProfile::Flat) return pose.bottom_z;
  const double r2 = (p - pose.xy).squaredNorm();
  const double R = sphere_radius_m;
  // Sphere cap: lowest point at the pose; beyond the sphere's silhouette the bottom is
  // vertical, so clamp to its equator height.
  return pose.bottom_z + R - std::sqrt(std::max(0.0, R * R - r2));
}

double ToolStamp::rim_weight(const Vec2& p) const {
  if (footprint.empty() || rim.width_m <= 0.0) return 0.0;
  if (contains(p)) return 0.0;
  const double d = distance_to_boundary(footprint, p);
  if (d >= rim.width_m) return 0.0;
  const double taper = 1.0 - d / rim.width_m;
  double directional = 1.0;
  const Vec2 offset = p - pose.xy;
  const double len = offset.norm();
  if (len > 0.0 && motion_dir.squaredNorm() > 0.0) {
    const double c = offset.dot(motion_dir) / len;
    directional = (1.0 + rim.forward_bias * c) / (1.0 + rim.forward_bias);
  }
  return std::max(0.0, directional) * taper;
}

Aabb2 ToolStamp::influence_bounds() const {
  if (footprint.empty()) {
    return Aabb2{pose.xy, pose.xy}.expanded(pour_radius_m);
  }
  return bounds(footprint).expanded(rim.width_m);
}

ToolStamp make_stamp(const ToolSpec& spec, const ToolPose& pose, const Vec2& motion_dir, std::uint32_t generation) {
  ToolStamp s;
  s.generation = generation;
  s.pose = pose;
  s.motion_dir = motion_dir;
  s.profile = spec.profile;
  s.sphere_radius_m = spec.sphere_radius_m;
  s.rim = spec.rim;
  if (spec.shape == ToolShape::Pour) {
    s.pour_volume_m3 = spec.pour_volume_m3;
    s.pour_radius_m = spec.radius_m;
    return s;
  }
  const double c = std::cos(pose.heading_rad), sn = std::sin(pose.heading_rad);
  for (const Vec2& q : spec.footprint_local()) {
    s.footprint.emplace_back(pose.xy.x() + c * q.x() - sn * q.y(), pose.xy.y() + sn * q.x() + c * q.y());
  }
  return s;
}

}  // namespace sb
