#include "common/raster.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/bilinear.hpp"

namespace sb {

std::array<std::size_t, 2> Raster::shape_covering(const Aabb2& box, double spacing_m) {
  const Vec2 size = box.hi - box.lo;
  // The last sample lands on the box's far edge when the size is a whole number of steps.
  return {static_cast<std::size_t>(std::floor(size.x() / spacing_m + 1e-9)) + 1,
          static_cast<std::size_t>(std::floor(size.y() / spacing_m + 1e-9)) + 1};
}

Raster Raster::covering(const Aabb2& box, double spacing_m) {
  Raster r;
  r.origin_m = box.lo;
  r.spacing_m = spacing_m;
  const auto shape = shape_covering(box, spacing_m);
  r.nx = shape[0];
  r.ny = shape[1];
  r.values.assign(r.nx * r.ny, 0.0);
  return r;
}

double Raster::interpolate(const Vec2& p) const {
  const Vec2 g = (p - origin_m) / spacing_m;
  return bilinear(g.x(), g.y(), nx, ny, [&](std::size_t ix, std::size_t iy) { return at(ix, iy); });
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
