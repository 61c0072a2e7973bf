#pragma once
// Material: the sand's behaviour, shared by every back-end and by the haptic force model.
#include <cmath>
#include <numbers>

namespace sb {

inline double deg_to_rad(double deg) { return deg * std::numbers::pi / 180.0; }
inline double rad_to_deg(double rad) { return rad * 180.0 / std::numbers::pi; }

struct Material {
  double critical_angle_deg = 30.0;  // angle of repose; dry sand 30-35, damp higher
  // Fraction of a pair's excess moved per erosion visit. (0, 1] settles monotonically;
  // (1, 2] overshoots but a pair's transfer still lowers the potential energy; above 2 it
  // can raise it, erosion oscillates and heights diverge, so scenes refuse it.
  double transfer_fraction = 0.5;
  // Haptic parameters (used by the force model): penetration stiffness, velocity drag,
  // Coulomb friction coefficient against the penetration force.
  double stiffness_n_per_m = 800.0;
  double drag_n_s_per_m = 5.0;
  double friction = 0.4;

  double tan_critical() const { return std::tan(deg_to_rad(critical_angle_deg)); }
};

}  // namespace sb
