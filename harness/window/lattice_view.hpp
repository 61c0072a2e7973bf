#pragma once
// LatticeSurface: a height lattice (the grids) drawn from a texture of its heights. The heights
// live in one R32F texture, node (ix, iy) at texel (ix, iy), brought up to date with a
// sub-image upload per changed tile (DisplayFeed); the geometry is one static index buffer of
// a patch of cells, drawn once per level of detail (lattice_lod.hpp) by a vertex shader that
// places each vertex on its node and reads its height from the texture. So an update costs the
// tiles that changed, and a frame the patches' triangles, however large the lattice.
//
// The fragment shader is the mesh's (gl_program.hpp): the same facets, colours and light.
// Memory on the GL side: 4 bytes per node, plus 24 bytes per patch cell of indices.
#include <vector>

#include "common/terrain.hpp"
#include "harness/interactive/display_feed.hpp"
#include "harness/window/lattice_lod.hpp"

namespace sb {

class LatticeSurface {
 public:
  // origin: subtracted from every position (the view's); z_ref: the feed's reference height,
  // added to the texture's values. Throws std::runtime_error when the lattice exceeds the
  // GL's largest texture.
  LatticeSurface(const HeightLattice& lattice, const Vec3& origin, double z_ref);
  ~LatticeSurface();
  LatticeSurface(const LatticeSurface&) = delete;
  LatticeSurface& operator=(const LatticeSurface&) = delete;

  void upload(const LatticeUpdate& u);
  // The patches around `focus` (world metres), with the program's view_projection and colour
  // uniforms already set by the caller; `tint_location` is not touched.
  void draw(const Vec2& focus);
  unsigned program() const { return program_; }
  std::size_t triangles_drawn() const { return triangles_; }

 private:
  void draw_cells(std::size_t first_cell, std::size_t cells);

  HeightLattice lattice_;
  Vec3 origin_;
  double z_ref_;
  std::size_t cells_x_ = 0, cells_y_ = 0;
  unsigned program_ = 0, texture_ = 0, vao_ = 0, ebo_ = 0;
  std::size_t triangles_ = 0;
  std::vector<int> counts_;
  std::vector<const void*> offsets_;
};

}  // namespace sb
