#include "common/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

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

double squared_distance_to_segment(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double len2 = ab.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - a).dot(ab) / len2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).squaredNorm();
}

double distance_to_segment(const Vec2& p, const Vec2& a, const Vec2& b) {
  return std::sqrt(squared_distance_to_segment(p, a, b));
}

double distance_to_boundary(std::span<const Vec2> polygon, const Vec2& p) {
  // One square root for the nearest side: the root is monotone and correctly rounded, so this
  // equals the least of the sides' distances exactly.
  double best = std::numeric_limits<double>::infinity();
  const std::size_t n = polygon.size();
  for (std::size_t i = 0, j = n - 1; i < n; j = i++)
    best = std::min(best, squared_distance_to_segment(p, polygon[j], polygon[i]));
  return std::sqrt(best);
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

bool is_convex_polygon(std::span<const Vec2> polygon) {
  const std::size_t n = polygon.size();
  if (n < 3) return false;
  double turning = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 a = polygon[(i + 1) % n] - polygon[i], b = polygon[(i + 2) % n] - polygon[(i + 1) % n];
    if (cross2(a, b) < 0.0) return false;
    turning += std::atan2(cross2(a, b), a.dot(b));
  }
  return std::abs(turning - 2.0 * std::numbers::pi) < 1e-6;
}

std::vector<Vec2> offset_polygon(std::span<const Vec2> polygon, double gap) {
  const std::size_t n = polygon.size();
  std::vector<Vec2> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2& prev = polygon[(i + n - 1) % n];
    const Vec2& cur = polygon[i];
    const Vec2& next = polygon[(i + 1) % n];
    const Vec2 e0 = cur - prev, e1 = next - cur;
    const double l0 = e0.norm(), l1 = e1.norm();
    const Vec2 n0 = l0 > 0.0 ? Vec2(Vec2(e0.y(), -e0.x()) / l0) : Vec2(Vec2::Zero());
    const Vec2 n1 = l1 > 0.0 ? Vec2(Vec2(e1.y(), -e1.x()) / l1) : Vec2(Vec2::Zero());
    const double denom = 1.0 + n0.dot(n1);
    Vec2 shift = denom > 1e-6 ? Vec2((n0 + n1) * gap / denom) : Vec2((n0 + n1).normalized() * gap);
    if (shift.norm() > 4.0 * gap) shift *= 4.0 * gap / shift.norm();
    out[i] = cur + shift;
  }
  return out;
}

std::vector<Vec2> clip_to_box(std::span<const Vec2> polygon, const Aabb2& box) {
  std::vector<Vec2> cur(polygon.begin(), polygon.end()), next;
  for (int side = 0; side < 4 && !cur.empty(); ++side) {
    const int axis = side / 2;
    const bool low = side % 2 == 0;
    const double bound = low ? box.lo[axis] : box.hi[axis];
    auto inside = [&](const Vec2& p) { return low ? p[axis] >= bound : p[axis] <= bound; };
    next.clear();
    const std::size_t n = cur.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Vec2& a = cur[i];
      const Vec2& b = cur[(i + 1) % n];
      const bool ia = inside(a), ib = inside(b);
      if (ia) next.push_back(a);
      if (ia != ib) {
        const double t = (bound - a[axis]) / (b[axis] - a[axis]);
        Vec2 x = a + t * (b - a);
        x[axis] = bound;
        x[1 - axis] = std::clamp(x[1 - axis], box.lo[1 - axis], box.hi[1 - axis]);
        next.push_back(x);
      }
    }
    cur.swap(next);
  }
  return cur;
}

void drop_near_duplicates(std::vector<Vec2>& polygon, double tolerance) {
  std::vector<Vec2> out;
  for (const Vec2& p : polygon)
    if (out.empty() || (p - out.back()).norm() > tolerance) out.push_back(p);
  while (out.size() > 1 && (out.front() - out.back()).norm() <= tolerance) out.pop_back();
  polygon.swap(out);
}

double distance_between_segments(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const double o1 = cross2(b - a, c - a), o2 = cross2(b - a, d - a);
  const double o3 = cross2(d - c, a - c), o4 = cross2(d - c, b - c);
  if (((o1 > 0) != (o2 > 0)) && ((o3 > 0) != (o4 > 0)) && o1 != 0 && o2 != 0 && o3 != 0 && o4 != 0) return 0.0;
  return std::min({distance_to_segment(a, c, d), distance_to_segment(b, c, d), distance_to_segment(c, a, b),
                   distance_to_segment(d, a, b)});
}

bool segment_near_polygon(const Vec2& a, const Vec2& b, std::span<const Vec2> polygon, double margin) {
  if (point_in_polygon(polygon, a) || point_in_polygon(polygon, b)) return true;
  const std::size_t n = polygon.size();
  for (std::size_t i = 0; i < n; ++i)
    if (distance_between_segments(a, b, polygon[i], polygon[(i + 1) % n]) <= margin) return true;
  return false;
}

bool on_same_box_side(const Vec2& a, const Vec2& b, const Aabb2& box) {
  return (a.x() == box.lo.x() && b.x() == box.lo.x()) || (a.x() == box.hi.x() && b.x() == box.hi.x()) ||
         (a.y() == box.lo.y() && b.y() == box.lo.y()) || (a.y() == box.hi.y() && b.y() == box.hi.y());
}

double perimeter(std::span<const Vec2> polygon) {
  double length = 0.0;
  const std::size_t n = polygon.size();
  for (std::size_t i = 0; i < n; ++i) length += (polygon[(i + 1) % n] - polygon[i]).norm();
  return length;
}

std::vector<Vec2> fewer_corners(std::span<const Vec2> convex, std::size_t max_corners) {
  const std::size_t n = convex.size();
  if (n <= max_corners || max_corners < 3) return {convex.begin(), convex.end()};
  std::vector<Vec2> fewer;
  fewer.reserve(max_corners);
  for (std::size_t k = 0; k < max_corners; ++k) fewer.push_back(convex[k * n / max_corners]);
  // A subset of a convex polygon's corners is convex and lies inside it: grow it about the
  // centroid back to the original area.
  const double before = std::abs(signed_area(convex)), after = std::abs(signed_area(fewer));
  if (!(after > 0.0)) return fewer;
  Vec2 centroid = Vec2::Zero();
  for (const Vec2& p : fewer) centroid += p;
  centroid /= static_cast<double>(fewer.size());
  const double scale = std::sqrt(before / after);
  for (Vec2& p : fewer) p = centroid + scale * (p - centroid);
  return fewer;
}

std::size_t corners_to_keep(std::size_t n, std::size_t wanted, std::size_t limit) {
  if (n <= wanted) return n;
  for (std::size_t k = wanted; k <= limit && k <= n; ++k)
    if (n % k == 0) return k;
  return std::min(wanted, limit);
}

}  // namespace sb
