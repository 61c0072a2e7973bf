#pragma once
// Queries on any node-height storage `H` with `layout()` and `z(ix, iy)` (HeightGrid,
// SparseHeights): the bilinear interpolant's height at a point and its exact integral.
// Written once so that every storage answers bit for bit the same from the same heights.
#include <algorithm>
#include <cstddef>

#include "common/bilinear.hpp"
#include "grid/compensated_sum.hpp"
#include "grid/grid_layout.hpp"

namespace sb::grid {

// Bilinear interpolation of the node heights (common/bilinear.hpp), p clamped to the domain. O(1).
template <class H>
double bilinear_height(const H& h, const Vec2& p) {
  const GridLayout& layout = h.layout();
  return bilinear((p.x() - layout.origin.x()) / layout.dx, (p.y() - layout.origin.y()) / layout.dy, layout.nx,
                  layout.ny, [&h](std::size_t ix, std::size_t iy) { return h.z(ix, iy); });
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
