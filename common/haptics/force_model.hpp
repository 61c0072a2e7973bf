#pragma once
// The force model (Benes et al. 2006; Purchart): penetration resistance pushing the tool up,
// proportional to the sand it displaces, plus drag and Coulomb friction against its velocity
// while it is in sand. It reads only a published HeightPatch, never the terrain.
//
//   displaced  V = integral over the footprint F of max(0, h - tool bottom) dA
//   depth      d = V / area(F)
//   contact    c = integral over F of min(1, max(0, h - tool bottom) / kContactDepth) dA / area(F)
//   force      F = k d z^ - b c v - mu k d v_xy / max(|v_xy|, v_eps)
// with k = min(material stiffness, device max stiffness), b the drag and mu the friction.
//
// Continuous by construction: h is the patch's bilinear interpolation, the footprint is
// clipped exactly against every patch cell it overlaps (footprint_integral.hpp) and the
// integrands are continuous, so the force is a continuous function of the tool's pose and
// velocity: a small move changes it a little, across contact onset and across lattice lines
// alike. Each footprint point engages in the drag over its first kContactDepth of depth, so
// the drag too grows from zero with the sand displaced (a flat tool meeting flat sand does not
// switch the whole drag on at once). In sand deeper than kContactDepth under the whole
// footprint, d, c = 1 and F are those of the former point-sampled model. Cost: O(cells the
// footprint overlaps + footprint edges per row of cells); no allocation.
#include "common/geometry.hpp"
#include "common/haptics/height_patch.hpp"

namespace sb::haptics {

inline constexpr double kFrictionVelocityEps = 0.005;  // m/s; below it friction fades linearly
inline constexpr double kContactDepth_m = 0.003;       // a footprint point's drag engages over this depth

struct ForceOutput {
  Vec3 force_n{0.0, 0.0, 0.0};    // as the model asks, before the device's force limit
  double penetration_m = 0.0;     // d above
  double displaced_m3 = 0.0;      // V above: sand above the tool bottom inside the footprint
  double contact_fraction = 0.0;  // c above
  double surface_z_m = 0.0;       // patch height under the tool's centre
  int footprint_cells = 0;        // patch cells the footprint overlaps
  bool in_contact = false;        // V > 0
  bool outside_patch = false;     // part of the footprint lies beyond the patch (not felt)
};

ForceOutput compute_force(const HeightPatch& patch, const Vec3& position_m, const Vec3& velocity_m_s,
                          double max_stiffness_n_per_m);

// The device-safe force: zero when any component is not finite, scaled down to max_force_n
// when longer. Every force the servo commands goes through this.
struct LimitedForce {
  Vec3 force_n{0.0, 0.0, 0.0};
  bool clamped = false;
  bool nonfinite = false;
};
LimitedForce limit_force(const Vec3& force_n, double max_force_n);

}  // namespace sb::haptics
