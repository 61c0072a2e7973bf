#include "common/haptics/height_patch.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace sb::haptics {

ForceParams ForceParams::from(const Material& material, const ToolSpec& tool, double heading_rad) {
  ForceParams p;
  p.stiffness_n_per_m = material.stiffness_n_per_m;
  p.drag_n_s_per_m = material.drag_n_s_per_m;
  p.friction = material.friction;
  p.profile = tool.profile;
  p.sphere_radius_m = tool.sphere_radius_m;
  p.heading_rad = heading_rad;
  std::vector<Vec2> poly = tool.footprint_local();
  if (poly.empty()) {  // pour: a disk of the pour radius
    for (int k = 0; k < 16; ++k) {
      const double t = 2.0 * std::numbers::pi * k / 16;
      poly.emplace_back(tool.radius_m * std::cos(t), tool.radius_m * std::sin(t));
    }
  }
  const std::size_t stride = (poly.size() + kMaxFootprint - 1) / kMaxFootprint;
  for (std::size_t i = 0; i < poly.size() && p.footprint_size < kMaxFootprint; i += stride) {
    p.footprint[static_cast<std::size_t>(p.footprint_size++)] = poly[i];
    p.reach_m = std::max(p.reach_m, poly[i].norm());
  }
  return p;
}

PatchLayout PatchLayout::for_tool(double reach_m, double margin_m, std::size_t cells) {
  PatchLayout l;
  l.cells = std::max<std::size_t>(3, cells | 1);
  l.half_m = std::max(reach_m + margin_m, 1e-6);
  l.spacing_m = 2.0 * l.half_m / static_cast<double>(l.cells - 1);
  return l;
}

void reserve_patches(PatchBuffer& buffer, std::size_t cells) {
  buffer.for_each_slot([&](HeightPatch& p) { p.heights.values.reserve(cells * cells); });
}

void fill_patch(const Terrain& terrain, const Vec2& centre, const PatchLayout& layout, const ForceParams& params,
                std::uint64_t version, HeightPatch& out) {
  Raster& r = out.heights;
  r.origin_m = centre - Vec2(layout.half_m, layout.half_m);
  r.spacing_m = layout.spacing_m;
  r.nx = r.ny = layout.cells;
  r.values.resize(layout.cells * layout.cells);
  terrain.sample(r);
  out.centre_m = centre;
  out.params = params;
  out.version = version;
  out.valid = true;
}

}  // namespace sb::haptics
