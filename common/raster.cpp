#include "common/raster.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sb {

Raster Raster::covering(const Aabb2& box, double spacing_m) {
  Raster r;
  r.origin_m = box.lo;
  r.spacing_m = spacing_m;
  const Vec2 size = box.hi - box.lo;
  // The last sample lands on the box's far edge when the size is a whole number of steps.
  r.nx = static_cast<std::size_t>(std::floor(size.x() / spacing_m + 1e-9)) + 1;
  r.ny = static_cast<std::size_t>(std::floor(size.y() / spacing_m + 1e-9)) + 1;
  r.values.assign(r.nx * r.ny, 0.0);
  return r;
}

double Raster::interpolate(const Vec2& p) const {
  const Vec2 g = (p - origin_m) / spacing_m;
  const double gx = std::clamp(g.x(), 0.0, static_cast<double>(nx - 1));
  const double gy = std::clamp(g.y(), 0.0, static_cast<double>(ny - 1));
  const auto ix = std::min(static_cast<std::size_t>(gx), nx > 1 ? nx - 2 : 0);
  const auto iy = std::min(static_cast<std::size_t>(gy), ny > 1 ? ny - 2 : 0);
  const double tx = nx > 1 ? gx - ix : 0.0, ty = ny > 1 ? gy - iy : 0.0;
  const std::size_t ix1 = std::min(ix + 1, nx - 1), iy1 = std::min(iy + 1, ny - 1);
  return (1 - tx) * (1 - ty) * at(ix, iy) + tx * (1 - ty) * at(ix1, iy) + (1 - tx) * ty * at(ix, iy1) +
         tx * ty * at(ix1, iy1);
}

RasterDifference compare_rasters(const Raster& a, const Raster& b) {
  if (a.nx != b.nx || a.ny != b.ny) throw std::invalid_argument("compare_rasters: lattices differ");
  RasterDifference d;
  double sum2 = 0.0, sum = 0.0;
  for (std::size_t i = 0; i < a.values.size(); ++i) {
    const double e = a.values[i] - b.values[i];
    sum2 += e * e;
    sum += e;
    d.max_abs_m = std::max(d.max_abs_m, std::abs(e));
  }
  const auto n = static_cast<double>(std::max<std::size_t>(1, a.values.size()));
  d.rmse_m = std::sqrt(sum2 / n);
  d.mean_m = sum / n;
  return d;
}

}  // namespace sb
