#pragma once
// Bilinear interpolation on a lattice of nx x ny nodes (rasters, heightmap images, grid
// heights): the one implementation. (gx, gy) are lattice coordinates, clamped to
// [0, nx - 1] x [0, ny - 1]; at(ix, iy) gives a node's value. Inline because the grid calls
// it from its hot loops. O(1).
#include <algorithm>
#include <cstddef>

namespace sb {

// The lattice cell holding (gx, gy): its corners (ix, iy) and (ix1, iy1) and the fractions
// (tx, ty) across it. Shared by interpolation (bilinear) and by its adjoint, handing a value to
// the four corners with the same weights (the grid's pour, grid/stamp_kernel.hpp).
struct BilinearCell {
  std::size_t ix, iy, ix1, iy1;
  double tx, ty;
};

inline BilinearCell bilinear_cell(double gx, double gy, std::size_t nx, std::size_t ny) {
  gx = std::clamp(gx, 0.0, static_cast<double>(nx - 1));
  gy = std::clamp(gy, 0.0, static_cast<double>(ny - 1));
  const std::size_t ix = std::min(static_cast<std::size_t>(gx), nx > 1 ? nx - 2 : 0);
  const std::size_t iy = std::min(static_cast<std::size_t>(gy), ny > 1 ? ny - 2 : 0);
  return {ix,
          iy,
          std::min(ix + 1, nx - 1),
          std::min(iy + 1, ny - 1),
          gx - static_cast<double>(ix),
          gy - static_cast<double>(iy)};
}

template <typename At>
double bilinear(double gx, double gy, std::size_t nx, std::size_t ny, const At& at) {
  const BilinearCell c = bilinear_cell(gx, gy, nx, ny);
  return (1.0 - c.ty) * ((1.0 - c.tx) * at(c.ix, c.iy) + c.tx * at(c.ix1, c.iy)) +
         c.ty * ((1.0 - c.tx) * at(c.ix, c.iy1) + c.tx * at(c.ix1, c.iy1));
}

}  // namespace sb
