#pragma once
// MeshTileSurface: a mesh (the TIN) drawn from tiles of its domain, one vertex buffer per tile
// holding the tile's faces as separate triangles (DisplayFeed's MeshTileUpdate). An update
// replaces the buffers of the tiles that changed, so it costs their faces, not the mesh's.
// Drawn with the view's surface program (the whole mesh's): the same facets, colours and light.
// Memory on the GL side: 36 bytes per face, plus a buffer and a vertex array per tile.
#include <cstddef>
#include <vector>

#include "common/geometry.hpp"
#include "harness/interactive/display_feed.hpp"

namespace sb {

class MeshTileSurface {
 public:
  // `tiles`: the feed's mesh_tiles(); offset: the feed's origin minus the view's, added to
  // every corner.
  MeshTileSurface(std::size_t tiles, const Vec3& offset);
  ~MeshTileSurface();
  MeshTileSurface(const MeshTileSurface&) = delete;
  MeshTileSurface& operator=(const MeshTileSurface&) = delete;

  void upload(const MeshTileUpdate& u);
  void draw() const;  // with the caller's program and uniforms

 private:
  Vec3 offset_;
  std::vector<unsigned> vaos_, vbos_;
  std::vector<int> vertices_;  // per tile
  std::vector<float> shifted_;
};

}  // namespace sb
