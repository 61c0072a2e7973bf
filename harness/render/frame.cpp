#include "harness/render/frame.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "harness/render/colour.hpp"

namespace sb {

namespace {
Aabb2 extent(const Raster& r) {
  const double w = static_cast<double>(r.nx > 0 ? r.nx - 1 : 0) * r.spacing_m;
  const double h = static_cast<double>(r.ny > 0 ? r.ny - 1 : 0) * r.spacing_m;
  return {r.origin_m, r.origin_m + Vec2(w, h)};
}

// The largest deviation at raster point i: change of any surface, or difference to the first.
double deviation(const std::vector<FrameSurface>& s, std::size_t i) {
  double d = 0.0;
  for (const FrameSurface& f : s) {
    if (f.initial) d = std::max(d, std::abs(f.final->values[i] - f.initial->values[i]));
    d = std::max(d, std::abs(f.final->values[i] - s.front().final->values[i]));
  }
  return d;
}
}  // namespace

RenderFrame make_frame(const std::vector<FrameSurface>& surfaces, FrameRegion region) {
  if (surfaces.empty() || !surfaces.front().final) throw std::invalid_argument("make_frame: no surfaces");
  const Raster& ref = *surfaces.front().final;
  if (ref.nx < 2 || ref.ny < 2) throw std::invalid_argument("make_frame: raster smaller than 2 x 2");
  for (const FrameSurface& s : surfaces) {
    if (!s.final || s.final->nx != ref.nx || s.final->ny != ref.ny ||
        (s.initial && (s.initial->nx != ref.nx || s.initial->ny != ref.ny)))
      throw std::invalid_argument("make_frame: surfaces are not on one lattice");
  }
  RenderFrame f;
  f.domain = extent(ref);
  f.region = f.domain;

  if (region == FrameRegion::Changed) {
    double largest = 0.0;
    for (std::size_t i = 0; i < ref.values.size(); ++i) largest = std::max(largest, deviation(surfaces, i));
    const double threshold = std::max(1e-7, 0.05 * largest);
    std::size_t x0 = ref.nx, y0 = ref.ny, x1 = 0, y1 = 0;
    for (std::size_t iy = 0; iy < ref.ny; ++iy)
      for (std::size_t ix = 0; ix < ref.nx; ++ix)
        if (deviation(surfaces, iy * ref.nx + ix) > threshold) {
          x0 = std::min(x0, ix), x1 = std::max(x1, ix);
          y0 = std::min(y0, iy), y1 = std::max(y1, iy);
        }
    if (x0 <= x1 && largest > 1e-7) {
      Aabb2 box{ref.point(x0, y0), ref.point(x1, y1)};
      const Vec2 size = box.hi - box.lo;
      const double margin = std::max(size.maxCoeff() / 5.0, 8.0 * ref.spacing_m);
      box = box.expanded(margin);
      f.region = {box.lo.cwiseMax(f.domain.lo), box.hi.cwiseMin(f.domain.hi)};
    }
  }

  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (std::size_t iy = 0; iy < ref.ny; ++iy)
    for (std::size_t ix = 0; ix < ref.nx; ++ix) {
      if (!f.region.contains(ref.point(ix, iy))) continue;
      for (const FrameSurface& s : surfaces) {
        lo = std::min(lo, s.final->at(ix, iy));
        hi = std::max(hi, s.final->at(ix, iy));
      }
    }
  if (!(lo <= hi)) lo = hi = ref.values.front();
  // A flat surface still gets a small height range, so colours and contours stay defined.
  const double pad = std::max(0.0, 1e-3 - (hi - lo)) / 2.0;
  f.z_min_m = lo - pad;
  f.z_max_m = hi + pad;
  f.contour_step_m = nice_step(f.z_max_m - f.z_min_m, 15);
  return f;
}

}  // namespace sb
