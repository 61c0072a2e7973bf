#pragma once
// RenderMesh: a SurfaceMesh made ready for drawing -- float positions relative to a centre,
// area-weighted vertex normals, triangles turned to face up, the unique edges (for the
// wireframe), the constrained edges, and skirt walls from the boundary down to z = 0.
// Preparing is O(V + T log T) (edges are sorted to find the boundary); it keeps 24 bytes
// per vertex and 12 per triangle (about 12 more with edges) and uses 48 per triangle while
// it runs.
#include <cstdint>
#include <vector>

#include "common/geometry.hpp"
#include "common/raster.hpp"
#include "common/terrain.hpp"

namespace sb {

struct RenderMesh {
  Vec3 centre{0.0, 0.0, 0.0};              // subtracted from every position
  std::vector<float> positions;            // x, y, z per vertex
  std::vector<float> normals;              // unit, z >= 0
  std::vector<std::uint32_t> triangles;    // 3 per triangle, counter-clockwise seen from above
  std::vector<std::uint32_t> edges;        // 2 per unique edge (empty unless asked for)
  std::vector<std::uint32_t> constrained;  // 2 per constrained edge
  std::vector<float> skirt_positions;      // 6 vertices (2 triangles) per boundary edge
  std::vector<float> skirt_normals;
};

// Throws std::invalid_argument when an index is out of range.
RenderMesh prepare_render_mesh(const SurfaceMesh& mesh, const Vec3& centre, bool with_edges);

// The raster's lattice as a mesh: two triangles per raster cell. O(points).
SurfaceMesh mesh_from_raster(const Raster& raster);

}  // namespace sb
