#pragma once
// RenderFrame: what a picture shows -- a region of the domain and the height range across
// every surface in it. Built once for all back-ends of a comparison, so their pictures use
// the same camera, colour scale and contour levels. Building one is O(raster points).
#include <vector>

#include "common/geometry.hpp"
#include "common/raster.hpp"

namespace sb {

struct RenderFrame {
  Aabb2 domain;          // the whole raster's extent
  Aabb2 region;          // the part shown (inside domain)
  double z_min_m = 0.0;  // lowest and highest height inside region, over all surfaces
  double z_max_m = 0.0;
  double contour_step_m = 0.0;  // a nice step giving 8 to 15 contour levels
};

enum class FrameRegion {
  Changed,  // where any surface changed (from its initial raster) or differs from another
  Domain,   // the whole domain
};

struct FrameSurface {
  const Raster* initial = nullptr;  // may be null: then only differences between finals count
  const Raster* final = nullptr;    // all finals share one lattice
};

// Changed: points whose change (or difference) exceeds 5% of the largest, boxed with a
// margin of a fifth of the box (at least 8 raster steps) and clamped to the domain; the
// whole domain when nothing changed. Throws std::invalid_argument for an empty list or
// lattices that differ.
RenderFrame make_frame(const std::vector<FrameSurface>& surfaces, FrameRegion region);

}  // namespace sb
