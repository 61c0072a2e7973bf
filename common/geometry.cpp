#include "common/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sb {

double signed_area(std::span<const Vec2> polygon) {
  double twice = 0.0;
  const std::size_t n = polygon.size();
  for (std::size_t i = 0; i < n; ++i) twice += cross2(polygon[i], polygon[(i + 1) % n]);
  return 0.5 * twice;
}

Aabb2 bounds(std::span<const Vec2> polygon) {
  Aabb2 box{Vec2::Constant(std::numeric_limits<double>::infinity()),
            Vec2::Constant(-std::numeric_limits<double>::infinity())};
  for (const Vec2& p : polygon) {
    box.lo = box.lo.cwiseMin(p);
    box.hi = box.hi.cwiseMax(p);
  }
  return box;
}

bool point_in_polygon(std::span<const Vec2> polygon, const Vec2& p) {
  bool inside = false;
  const std::size_t n = polygon.size();
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
    const Vec2& a = polygon[i];
    const Vec2& b = polygon[j];
    if ((a.y() > p.y()) != (b.y() > p.y())) {
      const double x = a.x() + (p.y() - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
      if (p.x() < x) inside = !inside;
    }
  }
  return inside;
}

double distance_to_segment(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

double distance_to_boundary(std::span<const Vec2> polygon, const Vec2& p) {
  double best = std::numeric_limits<double>::infinity();
  const std::size_t n = polygon.size();
  for (std::size_t i = 0; i < n; ++i) {
    best = std::min(best, distance_to_segment(p, polygon[i], polygon[(i + 1) % n]));
  }
  return best;
}

namespace {
int orientation(const Vec2& a, const Vec2& b, const Vec2& c) {
  const double v = cross2(b - a, c - a);
  return (v > 0.0) - (v < 0.0);
}
bool on_segment(const Vec2& a, const Vec2& b, const Vec2& p) {
  return std::min(a.x(), b.x()) <= p.x() && p.x() <= std::max(a.x(), b.x()) && std::min(a.y(), b.y()) <= p.y() &&
         p.y() <= std::max(a.y(), b.y());
}
bool segments_intersect(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const int o1 = orientation(a, b, c), o2 = orientation(a, b, d);
  const int o3 = orientation(c, d, a), o4 = orientation(c, d, b);
  if (o1 != o2 && o3 != o4) return true;
  return (o1 == 0 && on_segment(a, b, c)) || (o2 == 0 && on_segment(a, b, d)) || (o3 == 0 && on_segment(c, d, a)) ||
         (o4 == 0 && on_segment(c, d, b));
}
}  // namespace

bool is_simple_polygon(std::span<const Vec2> polygon) {
  const std::size_t n = polygon.size();
  if (n < 3) return false;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      const bool adjacent = j == i + 1 || (i == 0 && j == n - 1);
      if (adjacent) continue;
      if (segments_intersect(polygon[i], polygon[(i + 1) % n], polygon[j], polygon[(j + 1) % n])) return false;
    }
  }
  return std::abs(signed_area(polygon)) > 0.0;
}

std::vector<Vec2> make_ccw(std::vector<Vec2> polygon) {
  if (signed_area(polygon) < 0.0) std::reverse(polygon.begin(), polygon.end());
  return polygon;
}

}  // namespace sb
