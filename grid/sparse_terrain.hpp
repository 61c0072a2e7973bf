#pragma once
// SparseGridTerrain<Real>: the regular height grid with sparse storage -- the dense grid's
// model (GridTerrain: nodes covering the domain, bilinear surface, trapezoid volume, the
// same stamp and the same erosion kernel, instantiated for this storage) whose heights live
// in an OpenVDB tree that stores only the 8 x 8 node blocks differing from a uniform
// height (sparse_heights.hpp). Same schedule, same heights as the dense grid, bit for bit.
//
// Memory (bytes per node):
//   a block with a leaf (any node differs from its block's tile): sizeof(Real) + 0.625
//                                       (double 8.6, float 4.6)
//   an untouched or uniform block:      0.14 (table pointer and state byte, 9 bytes / 64)
//   active set, every node:             1 bit of membership + bit_width(idle_passes - 1)
//                                       bits of idle count (default: 0.25), 4 bytes per row
//   fixed: the tree object 1.2 KB, a 544-byte internal node per 32 x 128 nodes that hold a
//   leaf or tile, 64 * sizeof(Real) per distinct tile height, and the erosion tables the
//   dense grid has too (up to 25 node classes, 14 KB).
// So its memory follows the disturbed area in whole blocks: a local stroke on a flat bed needs
// a fraction of the dense grid's bytes, a terrain where every node differs about as many
// (tests/unit/sparse_terrain_test.cpp bounds the ratios; results/sparse.md has this run's).
//
// Each stamp and erode reports its exact volume change (volume_change_m3: the stamp's own
// sums and the rounding carry, as on the dense grid), so the runner never integrates it per
// step. The dense erosion pass runs the dense grid's code on a RowWindow (row_window.hpp), a
// contiguous copy of the rows it touches that slides from row to row, so it classes rows and
// visits nodes in the same vector lanes, with the same heights as the dense grid's, bit for bit.
// Costs: those of GridTerrain (grid_terrain.hpp), each height read or write O(1) through
// the block table (a multiply-high for the row, a few shifts, two loads; a write one branch
// more), a write to a uniform block O(64) once to create its leaf; when erosion settles
// (the active set empties), O(64) per block written since the last settle to prune uniform
// blocks back to tiles. tests/bench/sparse_bench.cpp measures its step and settling times
// against the dense grid's. OpenVDB's headers stay in sparse_heights.cpp (they are slow and
// memory-hungry to compile).
#include <functional>
#include <memory>

#include "common/height_field.hpp"
#include "common/scene.hpp"
#include "common/terrain.hpp"
#include "grid/grid_terrain_base.hpp"
#include "grid/sparse_heights.hpp"
#include "grid/sparse_idle_counts.hpp"

namespace sb::grid {

// The operations both grids share are GridTerrainBase's (grid_terrain_base.hpp); this class
// adds the sparse storage's name, check() and the pruning after settling.
template <class Real>
class SparseGridTerrain final : public GridTerrainBase<SparseHeights<Real>, SparseActiveSet> {
 public:
  // neighbours: 4 or 8; idle_passes: idle visits before a node leaves the active set.
  SparseGridTerrain(const GridLayout& layout, const std::function<double(const Vec2&)>& initial, int neighbours,
                    int idle_passes)
      : GridTerrainBase<SparseHeights<Real>, SparseActiveSet>(layout, initial, neighbours, idle_passes) {}

  std::string_view name() const override { return "sparse"; }
  // The shared erosion, then, once settled, uniform blocks back to tiles.
  ErosionReport erode(const ErosionRule& rule, const ErosionBudget& budget) override;
  IntegrityReport check() const override;
};

extern template class GridTerrainBase<SparseHeights<float>, SparseActiveSet>;
extern template class GridTerrainBase<SparseHeights<double>, SparseActiveSet>;
extern template class SparseGridTerrain<float>;
extern template class SparseGridTerrain<double>;

// The sparse grid of the scene's [grid] section (cell size, storage, neighbours), idle
// passes from [erosion]: the dense grid's keys, so both run at the same resolution.
std::unique_ptr<Terrain> make_sparse_terrain(const Scene& scene, const HeightField& initial);

}  // namespace sb::grid
