#pragma once
// Raster: heights on a regular lattice of sample points, the common ground on which
// back-ends are compared. Row-major, rows along y: value(ix, iy) at origin + (ix, iy) * spacing.
#include <array>
#include <cstddef>
#include <vector>

#include "common/geometry.hpp"

namespace sb {

// The most samples a scene's raster may have (output.raster_m); run files are held to it too.
inline constexpr double kMaxRasterSamples = 1e8;

struct Raster {
  Vec2 origin_m{0.0, 0.0};
  double spacing_m = 0.0;
  std::size_t nx = 0, ny = 0;
  std::vector<double> values;

  static Raster covering(const Aabb2& box, double spacing_m);
  // {nx, ny} of covering(box, spacing_m), without allocating it.
  static std::array<std::size_t, 2> shape_covering(const Aabb2& box, double spacing_m);
  Vec2 point(std::size_t ix, std::size_t iy) const {
    return origin_m + Vec2(static_cast<double>(ix), static_cast<double>(iy)) * spacing_m;
  }
  double& at(std::size_t ix, std::size_t iy) { return values[iy * nx + ix]; }
  double at(std::size_t ix, std::size_t iy) const { return values[iy * nx + ix]; }
  // Bilinear interpolation, clamped to the raster's extent.
  double interpolate(const Vec2& p) const;
};

struct RasterDifference {
  double rmse_m = 0.0;
  double max_abs_m = 0.0;
  double mean_m = 0.0;  // mean of (a - b)
};
// Compares two rasters on the same lattice.
RasterDifference compare_rasters(const Raster& a, const Raster& b);

}  // namespace sb
