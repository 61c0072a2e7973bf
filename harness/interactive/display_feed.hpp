#pragma once
// DisplayFeed: the surface the window draws, handed from the simulation thread to the window
// thread at a cost that follows what changed, not the size of the terrain.
//
// A back-end with a height lattice (the grids, Terrain::lattice) is fed by tiles: the feed keeps
// a float copy of every node's height (minus a reference height, so floats keep sub-micrometre
// steps at any elevation); publish() asks the terrain which node rectangles changed since the
// last call (Terrain::changes_since), copies only those into the copy and marks their tiles
// pending; the window's take() copies the pending tiles out and clears them. A tile changed
// twice before the window takes it is sent once. Any other back-end (the TIN) is fed whole: a
// new mesh() each time it changed, which the window uploads whole.
//
// Stamp-to-frame latency: publish() carries the times of the stamps applied since the last
// call; take() hands them to the window, which measures from them to the swap that shows them.
//
// Costs: publish O(tiles) to find the changed ones (O(1) per tile for the grids' versions) plus
// O(changed nodes) copied, under the feed's own mutex (the servo never takes it); take O(pending
// nodes). Memory: 4 bytes per lattice node in the copy, as much again in the window's texture.
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

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

class DisplayFeed {
 public:
  // Lattice back-ends are fed by tiles (unless `tiles` is false), others by meshes. z_ref:
  // subtracted from the lattice's heights (the window adds it back).
  DisplayFeed(const Terrain& terrain, double z_ref, bool tiles = true);

  const std::optional<HeightLattice>& lattice() const { return lattice_; }
  double z_ref() const { return z_ref_; }

  // Simulation thread: what changed since the last call (everything on the first), and the
  // steady-clock times of the stamps applied since. `changed`: whether the terrain changed at
  // all (a mesh is rebuilt only then). Returns whether anything was published.
  bool publish(Terrain& terrain, bool changed, std::vector<double>& stamp_times_s);

  // Window thread: the stamp times published since the last call and, for a lattice, the
  // pending tiles (false: none). Mesh: the newest mesh (take() first: the mesh read after it
  // shows at least the stamps it returned).
  bool take(LatticeUpdate& out);
  std::shared_ptr<const DisplayMesh> mesh() const;

 private:
  std::optional<HeightLattice> lattice_;
  double z_ref_;
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
};

}  // namespace sb
