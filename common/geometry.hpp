#pragma once
// Small 2-D/3-D geometry on Eigen: polygons (closed, counter-clockwise, no repeated last
// point), bounding boxes, distances. Every function is O(polygon size) unless stated.
#include <Eigen/Core>
#include <span>
#include <vector>

namespace sb {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;

struct Aabb2 {
  Vec2 lo{0.0, 0.0};
  Vec2 hi{0.0, 0.0};
  bool contains(const Vec2& p) const {
    return p.x() >= lo.x() && p.x() <= hi.x() && p.y() >= lo.y() && p.y() <= hi.y();
  }
  Aabb2 expanded(double margin) const { return {lo - Vec2(margin, margin), hi + Vec2(margin, margin)}; }
};

// 2-D cross product (z of the 3-D cross product).
inline double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// Signed area: positive for counter-clockwise polygons.
double signed_area(std::span<const Vec2> polygon);
Aabb2 bounds(std::span<const Vec2> polygon);
// Even-odd rule; points exactly on the boundary may go either way.
bool point_in_polygon(std::span<const Vec2> polygon, const Vec2& p);
double distance_to_segment(const Vec2& p, const Vec2& a, const Vec2& b);
double distance_to_boundary(std::span<const Vec2> polygon, const Vec2& p);
// True when no two non-adjacent edges intersect (O(n^2), for validating input polygons).
bool is_simple_polygon(std::span<const Vec2> polygon);
// Returns the polygon counter-clockwise (reversed if it was clockwise).
std::vector<Vec2> make_ccw(std::vector<Vec2> polygon);

}  // namespace sb
