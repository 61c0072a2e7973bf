#pragma once
// Patches and tools shared by the haptics unit tests.
#include <functional>

#include "common/haptics/device.hpp"
#include "common/haptics/height_patch.hpp"
#include "common/haptics/rendering.hpp"

namespace sb::haptics::test {

inline ToolSpec disk(double radius_m, BottomProfile profile = BottomProfile::Flat) {
  ToolSpec t;
  t.shape = ToolShape::Disk;
  t.radius_m = radius_m;
  t.sides = 32;
  t.profile = profile;
  t.sphere_radius_m = radius_m;
  return t;
}

// A device's limits with a workspace of [0, 1] x [0, 1] x [0, 0.3] m.
inline DeviceLimits limits(double max_force_n = 8.0, double max_stiffness = 2000.0) {
  DeviceLimits l;
  l.max_force_n = max_force_n;
  l.max_stiffness_n_per_m = max_stiffness;
  l.workspace.lo = Vec3(0.0, 0.0, 0.0);
  l.workspace.hi = Vec3(1.0, 1.0, 0.3);
  return l;
}

// Publishes `p` as the simulation does.
inline void publish(PatchBuffer& b, const HeightPatch& p) {
  b.back() = p;
  b.publish();
}

// The force model's output sent as it is: no blend, no rate limit, no passivity control.
inline RenderingOptions raw_rendering() {
  RenderingOptions r;
  r.blend_s = 0.0;
  r.max_force_rate_n_per_s = 0.0;
  r.passivity = false;
  return r;
}

inline Material sand(double stiffness = 800.0, double drag = 5.0, double friction = 0.4) {
  Material m;
  m.stiffness_n_per_m = stiffness;
  m.drag_n_s_per_m = drag;
  m.friction = friction;
  return m;
}

// A patch around `centre` with heights z(x, y).
inline HeightPatch patch(const std::function<double(const Vec2&)>& z, const Vec2& centre, const ForceParams& params,
                         std::size_t cells = 49) {
  HeightPatch p;
  const PatchLayout l = PatchLayout::for_tool(params.reach_m, 0.02, cells);
  p.heights.origin_m = centre - Vec2(l.half_m, l.half_m);
  p.heights.spacing_m = l.spacing_m;
  p.heights.nx = p.heights.ny = l.cells;
  p.heights.values.resize(l.cells * l.cells);
  for (std::size_t iy = 0; iy < l.cells; ++iy)
    for (std::size_t ix = 0; ix < l.cells; ++ix) p.heights.at(ix, iy) = z(p.heights.point(ix, iy));
  p.centre_m = centre;
  p.params = params;
  p.version = 1;
  p.valid = true;
  return p;
}

inline HeightPatch flat_patch(double height_m, const Vec2& centre, const ForceParams& params) {
  return patch([=](const Vec2&) { return height_m; }, centre, params);
}

}  // namespace sb::haptics::test
