#pragma once
// TinTerrain: Purchart's TIN ("Interactive manipulation of sand on a TIN terrain model for
// virtual reality", Sections 3-4) on CGAL's constrained Delaunay triangulation in 2.5D
// (Projection_traits_xy_3 over the exact-predicates kernel), behind the Terrain interface.
// CGAL stays inside tin/*.cpp; this header is all a caller sees.
//
// Model: vertices (x, y, z), triangles, constrained edges tagged with the generation of the
// stamp that made them, the erosion list L_e and the simplification list L_r.
// Memory (x86-64, from the containers' capacities, checked against allocator accounting):
//   vertex 48 B (point 24, face handle 8, list slots and flags 16), triangle 56 B; about
//   2 triangles per vertex, so ~165 B per vertex with container slack; a constrained edge
//   adds ~40 B (hash node) and an active vertex 8 B per list.
// Costs (n vertices; k = vertices the tool touches; a walk is O(sqrt(n)) from a far hint but
// O(1) from the last located face, which is where queries and stamps come from):
//   construction      flat: O(1) (4 corners, 2 triangles); dunes/heightmap: greedy
//                     insertion of the worst sample until tin.tolerance_m, O(m log m) for m
//                     samples; from points: O(n log n) (spatially sorted insertion)
//   height(p)         one walk from the last located face, O(1) for nearby queries
//   stamp             O(k + faces whose circumcircle meets the tool's reach), independent
//                     of n: contour insertion, constraint enforcement, vertex removal
//   erode             O(|L_e| * degree^2) per pass; edge splits O(1) each
//   simplify          detect O(|L_r| * degree), removal O(degree) per vertex (Devillers)
//   volume, mesh, check, max_slope_deg, sample: O(n) (sample: O(raster + n^0.5))
// Not thread-safe: height() and sample() move the walk hint.
#include <memory>
#include <vector>

#include "common/height_field.hpp"
#include "common/scene.hpp"
#include "common/terrain.hpp"

namespace sb::tin {

// The scene's initial surface as a TIN: 2 triangles for a flat terrain, greedy insertion
// to tin.tolerance_m for dunes and heightmaps. Throws InputError for bad scene values.
std::unique_ptr<Terrain> make_tin_terrain(const Scene& scene, const HeightField& initial);

// A TIN of the given points (inside the scene's domain; duplicates merged) plus the domain's
// corners, which take the height of the nearest point. For benchmarks and tests that need a
// TIN of a given size. Throws InputError for points outside the domain or non-finite values.
std::unique_ptr<Terrain> make_tin_terrain_from_points(const Scene& scene, const std::vector<Vec3>& points);

}  // namespace sb::tin
