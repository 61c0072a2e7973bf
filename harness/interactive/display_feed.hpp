#pragma once
// DisplayFeed: the surface the window draws, handed from the simulation thread to the window
// thread at a cost that follows what changed, not the size of the terrain.
//
// A back-end with a height lattice (the grids, Terrain::lattice) is fed by tiles: the feed keeps
// a float copy of every node's height (minus a reference height, so floats keep sub-micrometre
// steps at any elevation); publish() asks the terrain which node rectangles changed since the
// last call (Terrain::changes_since), copies only those into the copy and marks their tiles
// pending; the window's take() copies the pending tiles out and clears them. A tile changed
// twice before the window takes it is sent once. A mesh (the TIN) is fed by tiles of its domain
// (kMeshTiles per side): publish() asks which boxes changed (changes_since's regions), reads the
// faces of every tile they meet again (Terrain::surface_faces: those whose centroid lies in the
// tile) and marks those tiles pending; take() hands their faces over. Without tiles (or from a
// back-end that tracks nothing) a mesh is fed whole: a new mesh() each time it changed.
//
// Stamp-to-frame latency: publish() carries the times of the stamps applied since the last
// call; take() hands them to the window, which measures from them to the swap that shows them.
//
// Costs: publish O(tiles) to find the changed ones (O(1) per tile for the grids' versions) plus
// O(changed nodes) copied, or O(faces of the changed mesh tiles) read, under the feed's own
// mutex (the servo never takes it) except the faces' reading; take O(pending nodes or faces).
// Memory: 4 bytes per lattice node in the copy, as much again in the window's texture; 36 bytes
// per mesh face in the copy (three float corners), as much again in the window's buffers.
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "common/domain_tiles.hpp"
#include "common/terrain.hpp"

namespace sb {

struct DisplayMesh {
  std::uint64_t version = 0;
  SurfaceMesh mesh;
};

// What the window takes from a lattice feed: rectangles and their heights, one after the
// other, row-major (rect k's node (x, y) at heights[offset_k + (y - y0) * width + (x - x0)]).
struct LatticeUpdate {
  std::vector<NodeRect> rects;
  std::vector<float> heights;
  std::vector<double> stamp_times_s;  // steady-clock seconds of the stamps these changes show
  void clear() {
    rects.clear();
    heights.clear();
    stamp_times_s.clear();
  }
};

// What the window takes from a mesh fed by tiles: each changed tile's faces, whole, one tile
// after the other (tile tiles[k]'s corners are xyz[offsets[k] .. offsets[k + 1]), three floats a
// corner, nine a face, relative to the feed's origin()).
struct MeshTileUpdate {
  std::vector<std::uint32_t> tiles;
  std::vector<std::size_t> offsets{0};
  std::vector<float> xyz;
  std::vector<double> stamp_times_s;
  void clear() {
    tiles.clear();
    offsets.assign(1, 0);
    xyz.clear();
    stamp_times_s.clear();
  }
};

class DisplayFeed {
 public:
  static constexpr std::size_t kMeshTiles = 32;  // a mesh's tiles per side of its domain

  // Back-ends are fed by tiles (unless `tiles` is false), a lattice's or the domain's; a mesh
  // whose back-end does not track its changes whole. z_ref: subtracted from the heights (the
  // window adds it back); `domain`: the scene's, whose centre and z_ref are origin().
  DisplayFeed(Terrain& terrain, double z_ref, const Aabb2& domain, bool tiles = true);

  const std::optional<HeightLattice>& lattice() const { return lattice_; }
  double z_ref() const { return z_ref_; }
  Vec3 origin() const { return origin_; }
  // A mesh fed by tiles: how many (the window draws them one by one); 0: fed whole.
  std::size_t mesh_tiles() const { return mesh_tiles_.size(); }

  // Simulation thread: what changed since the last call (everything on the first), and the
  // steady-clock times of the stamps applied since. `changed`: whether the terrain changed at
  // all (a mesh is rebuilt only then). Returns whether anything was published.
  bool publish(Terrain& terrain, bool changed, std::vector<double>& stamp_times_s);

  // Window thread: the stamp times published since the last call and, for a lattice, the
  // pending tiles (false: none). Mesh: the newest mesh (take() first: the mesh read after it
  // shows at least the stamps it returned).
  bool take(LatticeUpdate& out);
  // Window thread, a mesh fed by tiles: the stamp times and the pending tiles (false: none).
  bool take(MeshTileUpdate& out);
  std::shared_ptr<const DisplayMesh> mesh() const;

 private:
  bool publish_mesh_tiles(Terrain& terrain, std::vector<double>& stamp_times_s);
  Aabb2 mesh_tile_box(std::size_t tile) const;  // border tiles reach beyond the domain

  std::optional<HeightLattice> lattice_;
  double z_ref_;
  Vec3 origin_;
  DomainTiles mesh_grid_;           // a mesh's tiles (used when mesh_tiles_ is not empty)
  std::uint64_t version_ = 0;       // the terrain's change version last read (simulation thread)
  std::uint64_t mesh_version_ = 0;  // meshes published
  bool first_ = true;

  mutable std::mutex mutex_;
  std::vector<float> heights_;         // lattice copy, row-major
  std::size_t tile_cols_ = 0;          // pending tiles, kTile nodes square
  std::vector<std::uint8_t> pending_;  // per tile
  std::vector<std::uint32_t> pending_list_;
  std::vector<double> stamp_times_s_;
  std::shared_ptr<const DisplayMesh> mesh_;
  std::vector<std::vector<float>> mesh_tiles_;  // per mesh tile: its faces' corners (MeshTileUpdate)
  std::vector<Vec3> faces_scratch_;             // simulation thread
};

}  // namespace sb
