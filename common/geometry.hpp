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

// The smallest box holding both, and the overlap of two boxes (lo > hi when they do not meet).
inline Aabb2 united(const Aabb2& a, const Aabb2& b) { return {a.lo.cwiseMin(b.lo), a.hi.cwiseMax(b.hi)}; }
inline Aabb2 intersection(const Aabb2& a, const Aabb2& b) { return {a.lo.cwiseMax(b.lo), a.hi.cwiseMin(b.hi)}; }

// 2-D cross product (z of the 3-D cross product).
inline double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// Signed area: positive for counter-clockwise polygons.
double signed_area(std::span<const Vec2> polygon);
Aabb2 bounds(std::span<const Vec2> polygon);
// Even-odd rule; points exactly on the boundary may go either way.
bool point_in_polygon(std::span<const Vec2> polygon, const Vec2& p);
double distance_to_segment(const Vec2& p, const Vec2& a, const Vec2& b);
// The squared distance from p to the segment ab.
double squared_distance_to_segment(const Vec2& p, const Vec2& a, const Vec2& b);
double distance_to_boundary(std::span<const Vec2> polygon, const Vec2& p);
// True when no two non-adjacent edges intersect (O(n^2), for validating input polygons).
bool is_simple_polygon(std::span<const Vec2> polygon);
// Returns the polygon counter-clockwise (reversed if it was clockwise).
std::vector<Vec2> make_ccw(std::vector<Vec2> polygon);

// Convex and simple: no right turn, and the turns add up to one full turn (a pentagram turns
// left at every corner, but twice around).
bool is_convex_polygon(std::span<const Vec2> polygon);
// A counter-clockwise polygon's corners moved outwards by `gap` along the angle bisectors
// (a mitred offset; mitres at sharp corners are cut to 4 gaps). The result of a non-convex
// polygon may self-intersect when the gap exceeds its thickness: check is_simple_polygon.
std::vector<Vec2> offset_polygon(std::span<const Vec2> polygon, double gap);
// Sutherland-Hodgman clipping to the box; points on the box's sides are exactly on them.
// Empty when the polygon misses the box.
std::vector<Vec2> clip_to_box(std::span<const Vec2> polygon, const Aabb2& box);
// Drops points within `tolerance` of their predecessor (cyclically: the last one too when it
// is within `tolerance` of the first).
void drop_near_duplicates(std::vector<Vec2>& polygon, double tolerance);
// The shortest distance between segments ab and cd (0 when they cross).
double distance_between_segments(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d);
// Whether segment ab comes within `margin` of the closed polygon region (inside counts).
bool segment_near_polygon(const Vec2& a, const Vec2& b, std::span<const Vec2> polygon, double margin);
// Whether a and b both lie on one side of the box's boundary (exact comparisons: for points
// that were clipped or snapped onto it).
bool on_same_box_side(const Vec2& a, const Vec2& b, const Aabb2& box);
double perimeter(std::span<const Vec2> polygon);
// A convex polygon with at most `max_corners` of its corners, every (n / max_corners)-th of
// its n (a regular polygon stays regular when max_corners divides n), scaled about their mean
// to the original area (so a tool cut to fewer corners displaces the same volume). Polygons
// with no more corners are returned unchanged. max_corners >= 3.
std::vector<Vec2> fewer_corners(std::span<const Vec2> convex, std::size_t max_corners);
// The corner count to cut an n-cornered polygon to when `wanted` are enough: the smallest
// divisor of n that is at least `wanted` and at most `limit` (so the kept corners are evenly
// spaced), else min(wanted, limit); n when n <= wanted.
std::size_t corners_to_keep(std::size_t n, std::size_t wanted, std::size_t limit);

}  // namespace sb
