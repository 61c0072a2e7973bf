#pragma once
// The force model (Benes et al. 2006; Purchart): penetration resistance pushing the tool up,
// proportional to the sand it displaces, plus drag and Coulomb friction against its velocity
// while it is in sand. It reads only a published HeightPatch, never the terrain.
//
//   depth    d = mean over the footprint's patch points of max(0, h - tool bottom)
//   force    F = k d z^ - b c v - mu k d v_xy / max(|v_xy|, v_eps)
// with k = min(material stiffness, device max stiffness), b the drag, mu the friction and c
// the fraction of footprint points in contact. The footprint is scan-converted onto the
// patch lattice row by row: O(rows * footprint edges + points inside), a few microseconds for
// a 32-gon on a 49 x 49 patch. No allocation.
#include "common/geometry.hpp"
#include "common/haptics/height_patch.hpp"

namespace sb::haptics {

inline constexpr double kFrictionVelocityEps = 0.005;  // m/s; below it friction fades linearly

struct ForceOutput {
  Vec3 force_n{0.0, 0.0, 0.0};  // as the model asks, before the device's force limit
  double penetration_m = 0.0;   // d above
  double displaced_m3 = 0.0;    // sand above the tool bottom inside the footprint
  double contact_fraction = 0.0;
  double surface_z_m = 0.0;  // patch height under the tool's centre
  int footprint_points = 0;  // patch points inside the footprint
  bool in_contact = false;
  bool outside_patch = false;  // part of the footprint lies beyond the patch (not felt)
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
