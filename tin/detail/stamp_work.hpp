#pragma once
// Private to tin/stamp.cpp: one stamp's working state, passed from step to step (the paper's
// steps 1a-1f, TinTerrain::stamp). Plain data; the steps are TinTerrain members.
#include <algorithm>
#include <utility>
#include <vector>

#include "common/geometry.hpp"
#include "common/tool.hpp"
#include "tin/detail/tin_impl.hpp"

namespace sb::tin::detail {

struct ContourPoint {
  Vec2 p;
  double z;
};

struct StampWork {
  // The stamp as applied: its footprint counter-clockwise, without near-duplicate corners,
  // and a many-sided convex one cut to the corners the mesh resolves (same area).
  ToolStamp tool;
  // Whether the footprint is cut into the mesh (steps 1a-1e). One narrower than the mesh
  // resolves (TinTerrain::resolves) lowers the vertices it covers instead, as a grid's nodes.
  bool cut = true;
  double tiny = 0.0;                         // a length below rounding at the domain's scale
  double margin = 0.0;                       // what snapping may move a point by, and then some
  double gap = 0.0;                          // between the footprint I and the outer contour O
  std::vector<Vec2> outer;                   // O, unclipped
  std::vector<Vec2> outer_clip, inner_clip;  // O and I clipped to the domain (I empty: off it)
  Aabb2 footprint_bounds;
  // Around the pose: points nearer than `inside_radius` are in the footprint, points farther
  // than `reach_radius` beyond the rim band (cheap tests before the polygon's O(corners) ones).
  double inside_radius = 0.0, reach_radius = 0.0;

  // 1a: the points to insert, with their heights from the terrain.
  std::vector<ContourPoint> o_pts, i_pts, interior_pts, rim_pts;

  // What changes in the mesh.
  Aabb2 reach;   // O's box grown by the clearance: old constraints and vertices near O
  Aabb2 region;  // every face the stamp may change lies in it (for the volume capture)
  std::vector<std::pair<VertexHandle, VertexHandle>> dropped;  // old constraints near O
  std::vector<VertexHandle> o_verts, i_verts;                  // the contours' vertices, in order
  std::vector<const void*> own;                                // the stamp's own vertices, sorted
  std::vector<VertexHandle> fresh;                             // inserted by this stamp
  std::vector<VertexHandle> inside;                            // in the footprint
  std::vector<VertexHandle> changed;                           // heights changed (lowered or raised)
  std::vector<Vec2> picked_up;  // where the carried pile was taken, before the retriangulation
  double lowered_volume = 0.0;  // taken out by 1d

  // footprint_bounds, inside_radius and reach_radius from the footprint and the rim. O(corners).
  void bound_footprint() {
    footprint_bounds = bounds(tool.footprint).expanded(2.0 * tiny);
    const Vec2 centre = tool.pose.xy;
    if (tool.contains(centre)) inside_radius = std::max(0.0, distance_to_boundary(tool.footprint, centre) - 2.0 * tiny);
    for (const Vec2& p : tool.footprint) reach_radius = std::max(reach_radius, (p - centre).norm());
    reach_radius += std::max(tool.rim.width_m, 0.0) + 2.0 * tiny;
  }
  // Strictly inside, off the boundary (the inscribed circle's test, O(1)).
  bool deep_inside(const Vec2& p) const { return (p - tool.pose.xy).squaredNorm() < inside_radius * inside_radius; }
  bool in_footprint(const Vec2& p) const {
    return deep_inside(p) ||
           (footprint_bounds.contains(p) && (tool.contains(p) || distance_to_boundary(tool.footprint, p) <= tiny));
  }
  // The deposit's weight: 0 inside the footprint (the inner contour lies on its boundary,
  // which point-in-polygon may put either side, so it is excluded explicitly).
  double rim_weight(const Vec2& p) const {
    const double d2 = (p - tool.pose.xy).squaredNorm();
    if (d2 < inside_radius * inside_radius || d2 > reach_radius * reach_radius) return 0.0;
    // in_footprint and ToolStamp::rim_weight with one distance to the boundary between them.
    if (tool.contains(p)) return 0.0;
    const double d = distance_to_boundary(tool.footprint, p);
    return footprint_bounds.contains(p) && d <= tiny ? 0.0 : tool.rim_weight_outside(p, d);
  }
  // A tool deeper than the bed stops at its floor, z = 0: there is no sand below to push away.
  double bottom(const Vec2& p) const { return std::max(tool.bottom_z(p), 0.0); }
  bool is_own(VertexHandle v) const { return std::binary_search(own.begin(), own.end(), &*v); }
};

}  // namespace sb::tin::detail
