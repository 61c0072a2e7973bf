#include "grid/grid_erosion.hpp"

#include <array>
#include <span>

namespace sb::grid {

namespace {

// Central differences (one-sided on the border): the gradient rule's input. O(1).
template <class Real>
SurfaceGradient grid_gradient(const HeightGrid<Real>& grid, const GridLayout& layout, std::size_t ix, std::size_t iy) {
  const std::size_t x0 = ix > 0 ? ix - 1 : ix, x1 = ix + 1 < layout.nx ? ix + 1 : ix;
  const std::size_t y0 = iy > 0 ? iy - 1 : iy, y1 = iy + 1 < layout.ny ? iy + 1 : iy;
  return {(grid.z(layout.index(x1, iy)) - grid.z(layout.index(x0, iy))) / (static_cast<double>(x1 - x0) * layout.dx),
          (grid.z(layout.index(ix, y1)) - grid.z(layout.index(ix, y0))) / (static_cast<double>(y1 - y0) * layout.dy)};
}

}  // namespace

template <class Real>
ErosionReport erode_grid(HeightGrid<Real>& grid, ActiveSet& active, const Stencil& stencil, const ErosionRule& rule,
                         const ErosionBudget& budget) {
  const GridLayout& layout = grid.layout();
  ErosionReport report;
  CompensatedSum moved;
  std::array<ErosionNeighbour, 8> nbrs;
  std::array<std::uint32_t, 8> nbr_node;
  std::array<double, 8> sent;

  while (report.passes < budget.max_passes && !active.empty() && report.updates < budget.max_updates) {
    const std::span<const std::uint32_t> visiting = active.begin_pass();
    ++report.passes;
    for (std::size_t v = 0; v < visiting.size(); ++v) {
      if (report.updates >= budget.max_updates) {
        for (std::size_t rest = v; rest < visiting.size(); ++rest) active.keep(visiting[rest]);
        break;
      }
      ++report.updates;
      const std::uint32_t k = visiting[v];
      const auto [ix, iy] = layout.split(k);
      std::size_t n = 0;
      stencil.for_each(layout, ix, iy, [&](std::size_t jx, std::size_t jy, int slot) {
        const std::uint32_t j = layout.index(jx, jy);
        nbrs[n] = {grid.z(j), stencil.distance_m[slot], layout.area(jx, jy), stencil.ox[slot] * layout.dx,
                   stencil.oy[slot] * layout.dy};
        nbr_node[n] = j;
        ++n;
      });
      const double z_i = grid.z(k);
      const double area_i = layout.area(ix, iy);
      const SurfaceGradient gradient = rule.needs_gradient() ? grid_gradient(grid, layout, ix, iy) : SurfaceGradient{};
      const double total =
          erosion_transfers(z_i, area_i, gradient, std::span(nbrs.data(), n), rule, std::span(sent.data(), n));
      if (total <= 0.0) {
        active.idle(k);
        continue;
      }
      // The centre loses exactly what the neighbours gain (sum of the parts, not `total`,
      // which may differ from it in the last bit).
      CompensatedSum given;
      for (std::size_t m = 0; m < n; ++m) {
        if (sent[m] <= 0.0) continue;
        grid.set(nbr_node[m], nbrs[m].z + sent[m] / nbrs[m].area, nbrs[m].area);
        given.add(sent[m]);
        ++report.transfers;
      }
      grid.set(k, z_i - given.value() / area_i, area_i);
      moved.add(given.value());
      active.activate(k);
      for (std::size_t m = 0; m < n; ++m) active.activate(nbr_node[m]);
    }
  }
  report.active = active.size();
  report.volume_moved_m3 = moved.value();
  return report;
}

template ErosionReport erode_grid<float>(HeightGrid<float>&, ActiveSet&, const Stencil&, const ErosionRule&,
                                         const ErosionBudget&);
template ErosionReport erode_grid<double>(HeightGrid<double>&, ActiveSet&, const Stencil&, const ErosionRule&,
                                          const ErosionBudget&);

}  // namespace sb::grid
