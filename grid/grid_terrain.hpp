#pragma once
// GridTerrain<Real>: a dense regular height grid (Sumner et al. 1999; Onoue & Nishita 2003;
// Benes et al. 2006), the related-work baseline the TIN is compared with.
//
// Heights live on nx * ny nodes covering the domain exactly (GridLayout); the surface is
// their bilinear interpolant. Each node stands for the area A_k = dx dy, halved on each
// border axis, so volume() = sum A_k z_k is the interpolant's exact integral. Tool stamps
// cut the footprint to the tool bottom and put exactly that volume on the rim band
// (grid_stamp.hpp); erosion applies sb::erosion_transfers over an active set with an
// 8- or 4-neighbour stencil (erosion_kernel.hpp, active_set.hpp).
//
// Memory per node: sizeof(Real) for the height + 2 for the active-set state (idle count,
// and 1 bit of membership), i.e.
//   double: 10 bytes/node,  float: 6 bytes/node,
// plus, once erosion has run, its node-class tables (at most 25 classes, < 16 kB), and
// during a dense pass a scratch of 8 bytes per node of a row and 1 bit per node of the rows
// it visits. A 512 x 512 grid is 2.6 MB
// in double, 1.6 MB in float.
// Volume drift after 1000 stamps with erosion (a disk tool over flat sand, measured in
// tests/unit/grid_volume_test.cpp): double 0, float 1.4e-16 relative -- both at the
// resolution of the volume sum itself. Float writes carry their rounding error on
// (height_grid.hpp), which makes the sum of stored heights exact in units of one ulp;
// without the carry float drifts by 8.4e-8 over the same stroke.
//
// Cost of each operation (n = nx * ny, w = nodes in a stamp's influence window,
// v = footprint vertices, a = active nodes):
//   construction                O(n) evaluations of the initial surface
//   height(p)                   O(1)
//   sample(raster)              O(raster points)
//   stamp                       O(w), plus O(v) per node near the footprint's boundary
//                               or in the rim band; pour O((radius / cell)^2) (stamp_kernel.hpp)
//   erode                       O(passes * a * stencil) on the active set, or per dense
//                               pass O(nodes between the first and last member of each
//                               row), the stable ones classed with vector arithmetic;
//                               never the whole grid unless every row is active
//                               (erosion_kernel.hpp: node-class tables, built once per rule);
//                               settling budgets add the cascade's O(box around the active
//                               set) per call (multires_settle.hpp)
//   simplify                    O(1), nothing to simplify on a grid (reports a zero change)
//   volume, max_slope_deg,
//   mesh, check                 O(n)
//   stream_mesh                 O(n) time, O(nx) memory (the run file's writer)
//   stats                       O(1)
// Each stamp and erode reports its exact volume change (volume_change_m3: the stamp's own
// sums, and the rounding carry), so the runner never integrates the grid per step.
// Node updates per second and the time per call of each pass are measured by
// tests/bench/grid_bench.cpp (`make bench`; BM_ReferenceSweep is the plain scalar sweep of the
// same rule, the baseline of the vector pass); results/settling.md has the stroke and settling
// times against resolution of the last reproduction. On a stroke's states most visited nodes
// transfer, so the vector classing saves only the visits of stable nodes.
// Settling (relax_at_end) with fine passes alone is diffusive near the critical angle: the
// passes to settle grow about as (L / h)^2 with the cell h, and neither a larger transfer
// fraction nor another sweep order changes that exponent, they only make each pass cheaper.
// Settling budgets (32 passes or more, 1024 active nodes or more) therefore start with a
// coarse-to-fine cascade (multires_settle.hpp) that moves the sand over long distances on
// coarse copies of the grid before the fine passes finish: O(box around the active set) per
// call, plus the coarse levels' visits.
// See README, "The three back-ends at a glance".
#include <functional>
#include <memory>

#include "common/height_field.hpp"
#include "common/scene.hpp"
#include "common/terrain.hpp"
#include "grid/active_set.hpp"
#include "grid/grid_terrain_base.hpp"
#include "grid/height_grid.hpp"

namespace sb::grid {

// The operations both grids share are GridTerrainBase's (grid_terrain_base.hpp); this class
// adds the dense storage's name and check().
template <class Real>
class GridTerrain final : public GridTerrainBase<HeightGrid<Real>, ActiveSet> {
 public:
  // neighbours: 4 or 8; idle_passes: idle visits before a node leaves the active set.
  GridTerrain(const GridLayout& layout, const std::function<double(const Vec2&)>& initial, int neighbours,
              int idle_passes)
      : GridTerrainBase<HeightGrid<Real>, ActiveSet>(layout, initial, neighbours, idle_passes) {}

  std::string_view name() const override { return "grid"; }
  IntegrityReport check() const override;
};

extern template class GridTerrainBase<HeightGrid<float>, ActiveSet>;
extern template class GridTerrainBase<HeightGrid<double>, ActiveSet>;
extern template class GridTerrain<float>;
extern template class GridTerrain<double>;

// The grid of the scene's [grid] section: cell size, storage, neighbours; idle passes from
// [erosion].
std::unique_ptr<Terrain> make_grid_terrain(const Scene& scene, const HeightField& initial);

}  // namespace sb::grid
