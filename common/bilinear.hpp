#pragma once
// Bilinear interpolation on a lattice of nx x ny nodes (rasters, heightmap images, grid
// heights): the one implementation. (gx, gy) are lattice coordinates, clamped to
// [0, nx - 1] x [0, ny - 1]; at(ix, iy) gives a node's value. Inline because the grid calls
// it from its hot loops. O(1).
#include <algorithm>
#include <cstddef>

namespace sb {

template <typename At>
double bilinear(double gx, double gy, std::size_t nx, std::size_t ny, const At& at) {
  gx = std::clamp(gx, 0.0, static_cast<double>(nx - 1));
  gy = std::clamp(gy, 0.0, static_cast<double>(ny - 1));
  const std::size_t ix = std::min(static_cast<std::size_t>(gx), nx > 1 ? nx - 2 : 0);
  const std::size_t iy = std::min(static_cast<std::size_t>(gy), ny > 1 ? ny - 2 : 0);
  const std::size_t ix1 = std::min(ix + 1, nx - 1), iy1 = std::min(iy + 1, ny - 1);
  const double tx = gx - static_cast<double>(ix), ty = gy - static_cast<double>(iy);
  return (1.0 - ty) * ((1.0 - tx) * at(ix, iy) + tx * at(ix1, iy)) +
         ty * ((1.0 - tx) * at(ix, iy1) + tx * at(ix1, iy1));
}

}  // namespace sb
