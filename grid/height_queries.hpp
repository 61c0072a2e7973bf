#pragma once
// Queries on any node-height storage `H` with `layout()` and `z(ix, iy)` (HeightGrid,
// SparseHeights): the bilinear interpolant's height at a point and its exact integral.
// Written once so that every storage answers bit for bit the same from the same heights.
#include <algorithm>
#include <cstddef>

#include "grid/compensated_sum.hpp"
#include "grid/grid_layout.hpp"

namespace sb::grid {

// Bilinear interpolation of the node heights, p clamped to the domain. O(1).
template <class H>
double bilinear_height(const H& h, const Vec2& p) {
  const GridLayout& layout = h.layout();
  const double gx = std::clamp((p.x() - layout.origin.x()) / layout.dx, 0.0, static_cast<double>(layout.nx - 1));
  const double gy = std::clamp((p.y() - layout.origin.y()) / layout.dy, 0.0, static_cast<double>(layout.ny - 1));
  const std::size_t ix = std::min(static_cast<std::size_t>(gx), layout.nx - 2);
  const std::size_t iy = std::min(static_cast<std::size_t>(gy), layout.ny - 2);
  const double tx = gx - static_cast<double>(ix), ty = gy - static_cast<double>(iy);
  const double z00 = h.z(ix, iy), z10 = h.z(ix + 1, iy), z01 = h.z(ix, iy + 1), z11 = h.z(ix + 1, iy + 1);
  return (1.0 - ty) * ((1.0 - tx) * z00 + tx * z10) + ty * ((1.0 - tx) * z01 + tx * z11);
}

// The exact integral of the bilinear interpolant over the domain: sum of A_k z_k with the
// trapezoid weights, row by row, summed with compensation. O(nodes).
template <class H>
double trapezoid_volume(const H& h) {
  const GridLayout& layout = h.layout();
  CompensatedSum total;
  for (std::size_t iy = 0; iy < layout.ny; ++iy) {
    CompensatedSum row;
    for (std::size_t ix = 0; ix < layout.nx; ++ix) row.add(layout.weight_x(ix) * h.z(ix, iy));
    total.add(layout.weight_y(iy) * row.value());
  }
  return total.value();
}

}  // namespace sb::grid
