#pragma once
// The interactive window's 3-D drawing, plain OpenGL 3.3 core through libepoxy: the terrain mesh (flat-shaded
// facets, coloured by height, optional wireframe) and coloured line overlays (the tool, the
// force arrow). Uploading a mesh is O(vertices + triangles); drawing is one call per layer.
#include <cstdint>
#include <vector>

#include "common/terrain.hpp"
#include "harness/render/camera.hpp"

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
  // Clears and draws the terrain and the lines for a width x height framebuffer.
  void draw(const Camera& camera, int width, int height, bool wireframe, const std::vector<LineVertex>& lines);
  // The framebuffer's back buffer as RGB rows, top row first.
  std::vector<std::uint8_t> read_pixels(int width, int height) const;

 private:
  Vec3 origin_;
  double z_lo_, z_hi_;
  unsigned surface_program_ = 0, line_program_ = 0;
  unsigned mesh_vao_ = 0, mesh_vbo_ = 0, mesh_ebo_ = 0;
  unsigned line_vao_ = 0, line_vbo_ = 0;
  int mesh_indices_ = 0;
};

}  // namespace sb
