#pragma once
// Level of detail for drawing a height lattice (the grids) with a number of triangles bounded
// by a constant, not by the domain: nested square patches around a focus (the tool), in the
// manner of geometry clipmaps (Losasso and Hoppe 2004). Patch i has kLodCells x kLodCells cells
// of 2^i lattice cells each, so the finest (i = 0) is the lattice at full resolution around the
// tool, and the coarsest covers the whole domain. A patch leaves out the cells the next finer
// patch covers (its hole), so every point of the domain is drawn once. Each patch's corner lies
// on the lines of the next coarser patch's vertices (a multiple of its stride), so a finer
// patch's border runs along coarser edges; the vertex shader puts the finer border's vertices
// on those edges (linear between the coarser vertices) and the surface has no cracks.
//
// A lattice of at most kFullCells cells in all is drawn whole, in one patch of its own size: the
// shipped scenes (smaller) look exactly as a full mesh (same vertices, same diagonals). The bound
// is on the cells, not on a side, so that no lattice drawn whole costs more triangles than a
// levelled one of a large domain (a patch of kLodCells^2 cells and 3/4 of one per coarser level):
// a small lattice at a fine cell is never the slower one to draw.
//
// Pure arithmetic, O(levels); the window draws each patch from one shared index buffer.
#include <cstddef>
#include <utility>
#include <vector>

namespace sb {

inline constexpr std::size_t kLodCells = 64;          // cells per side of a patch when levelled
inline constexpr std::size_t kFullCells = 160 * 160;  // lattices of at most this many cells are drawn whole

struct LatticePatch {
  std::size_t x0 = 0, y0 = 0;  // node of vertex (0, 0)
  std::size_t stride = 1;      // lattice cells per patch cell; vertex (i, j) at node min(x0 + i stride, nx - 1), ...
  std::size_t coarse = 0;      // the next coarser patch's stride (0: none, the coarsest)
  std::size_t hx0 = 0, hx1 = 0, hy0 = 0;  // cells left out: [hx0, hx1) x [hy0, hy1) (none when hx0 == hx1)
  std::size_t hy1 = 0;
};

// Patch cells per side (x, y) for a lattice of nx x ny nodes: the lattice's own cells when it
// is drawn whole, kLodCells otherwise.
inline std::pair<std::size_t, std::size_t> lattice_patch_cells(std::size_t nx, std::size_t ny) {
  if ((nx - 1) * (ny - 1) <= kFullCells) return {nx - 1, ny - 1};
  return {kLodCells, kLodCells};
}

// The patches for a lattice of nx x ny nodes (at least 2 each) around node (fx, fy), finest
// first.
std::vector<LatticePatch> lattice_patches(std::size_t nx, std::size_t ny, std::size_t fx, std::size_t fy);

}  // namespace sb
