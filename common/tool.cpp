#include "common/tool.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <utility>

namespace sb {

namespace {
constexpr std::pair<ToolShape, std::string_view> kShapeNames[] = {{ToolShape::Disk, "disk"},
                                                                  {ToolShape::Box, "box"},
                                                                  {ToolShape::Ellipse, "ellipse"},
                                                                  {ToolShape::Polygon, "polygon"},
                                                                  {ToolShape::Pour, "pour"}};
constexpr std::pair<BottomProfile, std::string_view> kProfileNames[] = {{BottomProfile::Flat, "flat"},
                                                                        {BottomProfile::SphereCap, "sphere_cap"}};
constexpr std::pair<Displacement, std::string_view> kDisplacementNames[] = {
    {Displacement::Rim, "rim"}, {Displacement::Bulldoze, "bulldoze"}, {Displacement::Carry, "carry"}};

template <typename Enum, std::size_t N>
std::string name_of(const std::pair<Enum, std::string_view> (&table)[N], Enum e) {
  for (const auto& [value, name] : table)
    if (value == e) return std::string(name);
  return "?";
}

template <typename Enum, std::size_t N>
std::optional<Enum> value_of(const std::pair<Enum, std::string_view> (&table)[N], std::string_view name) {
  for (const auto& [value, n] : table)
    if (n == name) return value;
  return std::nullopt;
}

std::string number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}
}  // namespace

std::string to_string(ToolShape s) { return name_of(kShapeNames, s); }
std::string to_string(BottomProfile p) { return name_of(kProfileNames, p); }
std::optional<ToolShape> tool_shape_from(std::string_view name) { return value_of(kShapeNames, name); }
std::string to_string(Displacement d) { return name_of(kDisplacementNames, d); }
std::optional<BottomProfile> bottom_profile_from(std::string_view name) { return value_of(kProfileNames, name); }
std::optional<Displacement> displacement_from(std::string_view name) { return value_of(kDisplacementNames, name); }

std::optional<std::string> ToolSpec::problem() const {
  auto positive = [](const char* key, double v) -> std::optional<std::string> {
    if (v > 0.0) return std::nullopt;
    return std::string(key) + " = " + number(v) + " must be > 0";
  };
  std::optional<std::string> p;
  if (shape == ToolShape::Disk || shape == ToolShape::Pour) p = positive("tool.radius_m", radius_m);
  if (!p && (shape == ToolShape::Box || shape == ToolShape::Ellipse))
    p = positive("tool.size_m", half_size_m.minCoeff());
  if (!p && (shape == ToolShape::Disk || shape == ToolShape::Ellipse) && (sides < 3 || sides > 4096))
    p = "tool.sides = " + std::to_string(sides) + " must be in [3, 4096]";
  if (!p && shape == ToolShape::Polygon && (polygon_m.size() < 3 || !is_simple_polygon(polygon_m)))
    p = "tool.polygon_m must be a simple polygon of at least 3 points";
  if (!p && shape == ToolShape::Pour) p = positive("tool.volume_m3", pour_volume_m3);
  if (!p && shape != ToolShape::Pour && profile == BottomProfile::SphereCap)
    p = positive("tool.sphere_radius_m", sphere_radius_m);
  if (!p && !(rim.width_m >= 0.0)) p = "tool.rim_width_m = " + number(rim.width_m) + " must be >= 0";
  if (!p && !(rim.forward_bias >= 0.0 && rim.forward_bias <= 1.0))
    p = "tool.rim_forward_bias = " + number(rim.forward_bias) + " must be in [0, 1]";
  if (!p && !(rim.carry_shed_fraction >= 0.0 && rim.carry_shed_fraction <= 1.0))
    p = "tool.carry_shed_fraction = " + number(rim.carry_shed_fraction) + " must be in [0, 1]";
  if (!p && !(rim.face_friction >= 0.0)) p = "tool.face_friction = " + number(rim.face_friction) + " must be >= 0";
  return p;
}

std::size_t ToolSpec::footprint_corners() const {
  switch (shape) {
    case ToolShape::Box:
      return 4;
    case ToolShape::Polygon:
      return polygon_m.size();
    case ToolShape::Pour:
      return 1;
    case ToolShape::Disk:
    case ToolShape::Ellipse:
      break;
  }
  return static_cast<std::size_t>(std::max(sides, 0));
}

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
  return rim_weight_outside(p, distance_to_boundary(footprint, p));
}

double ToolStamp::rim_weight_outside(const Vec2& p, double d) const {
  if (rim.width_m <= 0.0 || d >= rim.width_m) return 0.0;
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
    const Vec2 offset = s.footprint.back() - pose.xy;
    s.half_width_m = std::max(s.half_width_m, std::abs(offset.x() * motion_dir.y() - offset.y() * motion_dir.x()));
    const double along = offset.dot(motion_dir);
    s.rear_m = s.footprint.size() == 1 ? along : std::min(s.rear_m, along);
    s.front_m = s.footprint.size() == 1 ? along : std::max(s.front_m, along);
  }
  return s;
}

}  // namespace sb
