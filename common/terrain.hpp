#pragma once
// The Terrain interface: one virtual call per operation (a stamp, an erosion step, a batch
// of queries); hot loops stay inside the back-ends. Every implementation documents, in its
// header, bytes per element and the cost of each operation.
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "common/erosion.hpp"
#include "common/geometry.hpp"
#include "common/raster.hpp"
#include "common/tool.hpp"

namespace sb {

// Volume changes a back-end reports for one phase (volume_change_m3): exact bookkeeping of
// its own writes, so the runner need not integrate the surface after every phase. NaN means
// "not tracked": the runner measures volume() instead.
inline constexpr double kVolumeChangeUnknown = std::numeric_limits<double>::quiet_NaN();

struct StampReport {
  double volume_change_m3 = kVolumeChangeUnknown;  // volume() after minus before
  double volume_removed_m3 = 0.0;                  // cut out of the footprint
  double volume_deposited_m3 = 0.0;                // put on the rim (equals removed) or poured
  std::size_t elements_touched = 0;                // cells or triangles the tool touched
  std::size_t vertices_inserted = 0;
  std::size_t vertices_removed = 0;
};

struct ErosionBudget {
  int max_passes = 4;                                                 // passes over the active set in this call
  std::size_t max_updates = std::numeric_limits<std::size_t>::max();  // element visits
  // The sand is left to come to rest (no tool this step: the runner's settling, an idle
  // interactive step). A back-end may spend work here that only pays at rest; the TIN refines
  // creases then when tin.curvature_when = "settling", and counts its last stamp as passed
  // (constraints dropped, contours thinned).
  bool settling = false;
  // Settling budgets may start with a back-end's coarse-to-fine cascade (erosion.cascade): the
  // grid's multires_settle, the TIN's clusters. false: the fine rule's own passes only.
  bool cascade = true;
};

struct ErosionReport {
  double volume_change_m3 = kVolumeChangeUnknown;  // volume() after minus before (rounding only)
  int passes = 0;
  std::size_t updates = 0;    // element visits (an element and its neighbours examined)
  std::size_t transfers = 0;  // neighbour transfers made
  std::size_t active = 0;     // active set size after the call (0: settled)
  double volume_moved_m3 = 0.0;
};

struct SimplifyParams {
  double alpha_flat_deg = 0.4;
};

struct SimplifyReport {
  double volume_change_m3 = kVolumeChangeUnknown;  // volume() after minus before
  std::size_t candidates = 0;                      // vertices examined (the paper's L_r)
  std::size_t removed = 0;
  double detect_s = 0.0;  // redundant-vertex detection time
  double remove_s = 0.0;  // vertex removal time
};

struct ModelStats {
  std::size_t vertices = 0;
  std::size_t triangles = 0;
  std::size_t constrained_edges = 0;
  std::size_t cells = 0;
  std::size_t bytes = 0;         // the model's own data, from its containers' capacities
  std::uint64_t walk_steps = 0;  // point-location steps since construction (TIN)
  std::size_t active = 0;        // erosion active set (L_e) size
};

// Triangles of a back-end's surface, for rendering and export.
struct SurfaceMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<std::array<std::uint32_t, 2>> constrained_edges;
};

// Receives a surface mesh piece by piece (Terrain::stream_mesh): the counts first, then the
// vertices in order, then the triangles, then the constrained edges, each in one or more calls.
class MeshSink {
 public:
  virtual ~MeshSink() = default;
  virtual void begin(std::size_t vertices, std::size_t triangles, std::size_t constrained_edges) = 0;
  virtual void vertices(std::span<const Vec3> v) = 0;
  virtual void triangles(std::span<const std::array<std::uint32_t, 3>> t) = 0;
  virtual void constrained_edges(std::span<const std::array<std::uint32_t, 2>> e) = 0;
};

// Hands a whole mesh to a sink in one piece each.
inline void stream_mesh(const SurfaceMesh& m, MeshSink& sink) {
  sink.begin(m.vertices.size(), m.triangles.size(), m.constrained_edges.size());
  sink.vertices(m.vertices);
  sink.triangles(m.triangles);
  sink.constrained_edges(m.constrained_edges);
}

// Display change tracking (Terrain::lattice, changes_since, lattice_heights, surface_faces): a
// back-end tells what changed since a version it gave, so that a display keeping a copy reads
// only that. One whose surface is a lattice of heights (the grids) names node rectangles; a
// mesh (the TIN) names boxes of its domain, and the display reads the faces in them again.

// Nodes [x0, x1) x [y0, y1) of a lattice.
struct NodeRect {
  std::size_t x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

// Node (ix, iy) lies at origin + (ix dx, iy dy).
struct HeightLattice {
  Vec2 origin{0.0, 0.0};
  double dx = 1.0, dy = 1.0;
  std::size_t nx = 0, ny = 0;
};

struct SurfaceChanges {
  std::uint64_t version = 0;    // ask from this next time
  bool tracked = false;         // false: not tracked, anything may have changed
  std::vector<NodeRect> rects;  // tracked lattice: every node changed since lies in one (none: nothing changed)
  // Tracked mesh: the centroid (in xy) of every face added or removed since (a face whose
  // vertices moved counts as both) lies in one of these boxes (none: nothing changed).
  std::vector<Aabb2> regions;
};

// Whether the xy centroid of triangle abc lies in [box.lo, box.hi) (surface_faces' rule).
inline bool centroid_in(const Aabb2& box, const Vec3& a, const Vec3& b, const Vec3& c) {
  const double x = (a.x() + b.x() + c.x()) / 3.0, y = (a.y() + b.y() + c.y()) / 3.0;
  return x >= box.lo.x() && x < box.hi.x() && y >= box.lo.y() && y < box.hi.y();
}

struct IntegrityReport {
  std::vector<std::string> problems;
  bool ok() const { return problems.empty(); }
};

class Terrain {
 public:
  virtual ~Terrain() = default;
  virtual std::string_view name() const = 0;  // "tin", "grid", "sparse"
  virtual double height(const Vec2& p) const = 0;
  virtual StampReport stamp(const ToolStamp& s) = 0;
  virtual ErosionReport erode(const ErosionRule& rule, const ErosionBudget& budget) = 0;
  virtual SimplifyReport simplify(const SimplifyParams& params) = 0;
  virtual double volume() const = 0;  // exact integral of the surface above z = 0
  virtual ModelStats stats() const = 0;
  virtual SurfaceMesh mesh() const = 0;
  // mesh(), piece by piece, for writers that must not hold a copy of a large model. The
  // default builds mesh() and hands it over whole.
  virtual void stream_mesh(MeshSink& sink) const { sb::stream_mesh(mesh(), sink); }
  virtual void sample(Raster& out) const = 0;  // heights at every raster point
  virtual IntegrityReport check() const = 0;
  // Steepest slope between neighbours (the graph erosion uses), in degrees. O(model).
  virtual double max_slope_deg() const = 0;

  // The surface's height lattice, if it is one (the grids; not the TIN).
  virtual std::optional<HeightLattice> lattice() const { return std::nullopt; }
  // What changed since `version`, a value an earlier call returned (0: the first call, which
  // reports everything and may start the tracking). Default: not tracked.
  virtual SurfaceChanges changes_since(std::uint64_t /*version*/) { return {}; }
  // Lattice back-ends: the heights of the nodes of `r` minus z_ref, node (x, y) at
  // out[(y - r.y0) * stride + (x - r.x0)]. O(nodes of r).
  virtual void lattice_heights(const NodeRect& /*r*/, double /*z_ref*/, float* /*out*/, std::size_t /*stride*/) const {}
  // The faces of mesh() whose centroid (in xy) lies in [box.lo, box.hi), three corners each,
  // appended to `out` (boxes that tile the plane share out every face once). Default: mesh()
  // filtered, O(n); the TIN: O(faces overlapping the box) after a walk to it.
  virtual void surface_faces(const Aabb2& box, std::vector<Vec3>& out) const;
};

}  // namespace sb
