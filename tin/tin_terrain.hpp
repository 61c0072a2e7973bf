#pragma once
// TinTerrain: Purchart's TIN ("Interactive manipulation of sand on a TIN terrain model for
// virtual reality", Sections 3-4) on CGAL's constrained Delaunay triangulation in 2.5D
// (Projection_traits_xy_3 over the exact-predicates kernel), behind the Terrain interface.
// CGAL stays inside tin/*.cpp; this header is all a caller sees.
//
// Model: vertices (x, y, z), triangles, constrained edges tagged with the generation of the
// stamp that made them, the erosion list L_e and the simplification list L_r.
// Memory (x86-64, from the containers' capacities; tests/unit/tin_memory_test.cpp checks it
// against allocator accounting, to the byte): a vertex is 56 B (point 24, face handle 8,
// lists, flags and cached area 24), a triangle 56 B; about 2 triangles per vertex, so
// 168 B per vertex plus container slack (168.6 MB for 10^6 vertices). A constrained edge
// adds a 32 B hash node and an 8 B bucket; a vertex in L_r 8 B; a vertex in L_e 16 B plus its
// cached ring, 8 B per neighbour (about 50 B), in a pool whose garbage (rings of vertices that
// left L_e or whose star changed) is compacted once it is an eighth of the pool, and freed
// with L_e when erosion has settled: while a stroke erodes, about 100 B per active vertex more
// than without the cache (pile.toml: peak 142 kB against 106 kB, final 102 kB against 106 kB).
// Costs (n vertices; a walk is O(sqrt(n)) from a far hint but O(1) from the last located
// face, which is where queries and stamps come from; k = vertices and faces within the
// tool's reach, independent of n):
//   construction      flat: O(1), 4 corners and 2 triangles; dunes and heightmaps: greedy
//                     insertion of the worst sample until tin.tolerance_m, O(m log m) for m
//                     samples (0.1 s for the dunes scene); from points: O(n log n), spatially
//                     sorted insertion (about 2 s for 10^6 points)
//   height(p)         one walk from the last located face: O(1) for nearby queries
//   stamp             O(k): contours inserted, old constraints dropped, constraints enforced,
//                     vertices removed, the rim refined (about 0.4 ms for a 1.5 cm disk); a
//                     convex footprint keeps one corner per refine_m_ of perimeter (8 to 64,
//                     evenly spaced, same area), so tool.sides = 4096 costs what 16 sides do;
//                     one narrower than refine_m / 4 is not cut in: O(vertices it covers)
//   erode             O(|L_e| * degree) per pass, about 0.2 us per vertex visit; an edge
//                     split is O(1). A visit reads its vertex's ring from L_e's cache (the
//                     neighbours in CGAL's circulator order, walked again only after the star
//                     changed; check() compares it with the star), heights and cached areas
//                     fresh; no allocation per visit (scratch and pool grow amortized).
//                     A settling budget (no tool) first drops the last stamp's constraints
//                     and thins its contours, O(its contours). Settling budgets (the
//                     runner's, >= 32 passes) with >= 512 active
//                     vertices first run a coarse-to-fine cascade over the region around L_e
//                     (settle_cascade.hpp: clusters of refinement-length cells, none with
//                     erosion.cascade = false, then the fine rule over plain arrays),
//                     O(region x degree) plus its visits
//   simplify          detect O(|L_r| * degree); removal O(degree) per vertex; with
//                     tin.coarsen, once per rest after activity: detect O(n * degree), each
//                     removal's capture located from the vertex itself, O(1)
//   one step          stamp + 4 erosion passes + simplify: 0.6 to 0.7 ms CPU at every n from
//                     10^3 to 10^6, on tin.initial_points TINs with their border points too,
//                     log-log slope -0.006 (tests/bench/tin_step_bench.cpp; 0.73 ms on the
//                     heightmap scene's TIN), where the paper measured O(n^1.5)
//   display tracking (off until changes_since is first called): each edit marks the cells of a
//                     64 x 64 division of the domain under the faces it changed, O(its star or
//                     region); a height write lists its vertex, O(1); changes_since marks the
//                     listed vertices' stars, O(listed x degree), and reports O(4096 cells);
//                     surface_faces(box): O(faces overlapping the box) after a walk to it
//   volume, mesh, check, max_slope_deg: O(n); sample: O(faces + raster points), rasterising the
//                     faces (~225 instructions a point), or a short walk per point (~1000) where
//                     the raster has fewer than a quarter as many points as the TIN has faces
//                     (tin/sample.cpp)
// Volume: stamps, erosion and simplification conserve volume except where the Delaunay
// triangulation changes under a non-planar surface (flips after insertions and edge splits,
// removals of not quite planar vertices, dropped constraints). tin.conserve_volume (the
// default) measures each such change over the faces it touched and gives it back there (to
// the rim deposit, the split vertex, the hole's vertices in proportion to the removed vertex's
// area each took over): exact to rounding, at the cost of one
// local face traversal per split and per removal. Either way each phase reports its volume
// change (volume_change_m3: A dz per height written, plus each retriangulation's measured
// change), O(1) per edit, so the runner integrates the surface only at a run's start and end.
// Point location walks from the last located face; its guard uses the data structure's O(1)
// face count (CGAL's number_of_faces() circulates the hull: O(sqrt(n)) with border points).
// Stale constraints (of stamps before the current one) are dropped at each stamp, and with
// tin.conserve_volume the top of each pair of their contour vertices closer than refine_m / 3
// goes (O and I lie a contour gap apart, far below the mesh's resolution, and two such small
// areas throttled every transfer across the old wall). A tool deeper than the bed stops at z = 0. Erosion re-activates
// the giver's neighbours and the receivers; under the gradient rule also the receivers' neighbours, whose fan gradients
// read the receiver's height (re-activating only the giver's ring visits less, but leaves the pile's flank further from
// critical); tan_settle is its settling criterion. A stamp re-activates the vertices whose
// heights it changed with their neighbours, and of the rest of the retriangulated region only vertices next to a face
// steeper than critical. Not thread-safe: height() and sample() move their walk hint (a walk of their own: what an
// edit builds never depends on the queries made before it, tests/unit/tin_reproducible_test.cpp).
#include <memory>
#include <vector>

#include "common/height_field.hpp"
#include "common/scene.hpp"
#include "common/terrain.hpp"

namespace sb::tin {

// The scene's initial surface as a TIN: 2 triangles for a flat terrain, greedy insertion
// to tin.tolerance_m for dunes, cones and heightmaps (or tin.initial_points' lattice), whose
// vertices then take the terrain's L2 projection: the terrain's volume, the least mean-square
// error on that mesh (tin/project.cpp). Throws InputError for bad scene values.
std::unique_ptr<Terrain> make_tin_terrain(const Scene& scene, const HeightField& initial);

// A TIN of the given points (inside the scene's domain; duplicates merged) plus the domain's
// corners, which take the height of the nearest point. For benchmarks and tests that need a
// TIN of a given size. Throws InputError for points outside the domain or non-finite values.
std::unique_ptr<Terrain> make_tin_terrain_from_points(const Scene& scene, const std::vector<Vec3>& points);

// The edge lengths a scene's TIN refines to: erosion splits edges longer than refine_m that
// sand flows across, curvature refinement goes down to fine_m (= refine_m when it is off).
// What the TIN itself uses; the resource pre-flight estimates vertex counts from them. O(1).
struct Refinement {
  double refine_m = 0.0;
  double fine_m = 0.0;
};
Refinement refinement_of(const Scene& scene);

}  // namespace sb::tin
