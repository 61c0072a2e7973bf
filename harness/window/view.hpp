#pragma once
// The interactive window's 3-D drawing, plain OpenGL 3.3 core through libepoxy: the terrain
// (flat-shaded facets, coloured by height, optional wireframe) and coloured line overlays (the
// tool, the force arrow). The terrain is a mesh (uploading one is O(vertices + triangles)), a
// mesh by tiles (mesh_tiles_view.hpp: uploads per changed tile) or, for a height lattice, a
// LatticeSurface (lattice_view.hpp: uploads per changed tile, triangles bounded by its levels of
// detail around the tool); all share one fragment shader.
#include <cstdint>
#include <memory>
#include <vector>

#include "common/terrain.hpp"
#include "harness/render/camera.hpp"
#include "harness/window/lattice_view.hpp"
#include "harness/window/mesh_tiles_view.hpp"

namespace sb {

struct LineVertex {
  float x, y, z;  // world metres
  float r, g, b;
};

class TerrainView {
 public:
  // origin: subtracted from every position (the domain's centre); z range for the colours.
  TerrainView(const Vec3& origin, double z_lo, double z_hi);
  ~TerrainView();
  TerrainView(const TerrainView&) = delete;
  TerrainView& operator=(const TerrainView&) = delete;

  void upload_mesh(const SurfaceMesh& mesh);
  // From now on the terrain is this lattice, drawn from its heights (DisplayFeed's z_ref).
  void use_lattice(const HeightLattice& lattice, double z_ref);
  void upload_lattice(const LatticeUpdate& update);
  // From now on the terrain is a mesh by tiles (DisplayFeed::mesh_tiles, positions relative to
  // the feed's origin).
  void use_mesh_tiles(std::size_t tiles, const Vec3& feed_origin);
  void upload_mesh_tiles(const MeshTileUpdate& update);
  // Clears and draws the terrain and the lines for a width x height framebuffer; a lattice is
  // drawn at full resolution around `focus` (world x, y: the tool).
  void draw(const Camera& camera, int width, int height, bool wireframe, const std::vector<LineVertex>& lines,
            const Vec2& focus);
  // The framebuffer's back buffer as RGB rows, top row first.
  std::vector<std::uint8_t> read_pixels(int width, int height) const;

 private:
  Vec3 origin_;
  double z_lo_, z_hi_;
  unsigned surface_program_ = 0, line_program_ = 0;
  unsigned mesh_vao_ = 0, mesh_vbo_ = 0, mesh_ebo_ = 0;
  unsigned line_vao_ = 0, line_vbo_ = 0;
  int mesh_indices_ = 0;
  std::unique_ptr<LatticeSurface> lattice_;
  std::unique_ptr<MeshTileSurface> mesh_tiles_;
};

}  // namespace sb
