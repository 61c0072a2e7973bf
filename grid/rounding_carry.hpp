#pragma once
// RoundingCarry<Real>: stores heights in float or double, read and written in double, with
// the rounding error of each write carried on to the next (error diffusion, the way a
// dithered image keeps its mean).
//
// Storing a height in a float loses up to half a unit in the last place (ulp), i.e. up to
// 0.5 ulp(z) * A of volume. That loss is remembered as a volume (`m3`) and added to the
// next node written, so the stored volume never drifts by more than one rounding step
// however many writes are made. With double storage the carry stays zero. O(1) per write.
#include <type_traits>

namespace sb::grid {

// The rounding error (m) of `stored`, the Real that `target` was stored as: what a store of the
// erosion kernel's storage concept returns from put() (erosion_kernel.hpp); 0 in double.
template <class Real>
inline double rounding_error(double target, Real stored) {
  if constexpr (std::is_same_v<Real, double>) {
    (void)target, (void)stored;
    return 0.0;
  } else {
    return target - static_cast<double>(stored);
  }
}

template <class Real>
class RoundingCarry {
  static_assert(std::is_same_v<Real, float> || std::is_same_v<Real, double>);

 public:
  // The value to store for `target` (m) at a node of `area` (m^2).
  Real round(double target, double area) {
    if constexpr (std::is_same_v<Real, double>) {
      (void)area;
      return target;
    } else {
      // 1 / area does not depend on the carry, so it is computed off the carry's chain of
      // dependent operations, which runs through every float write.
      const double inverse_area = 1.0 / area;
      const double wanted = target + m3_ * inverse_area;
      const Real stored = static_cast<Real>(wanted);
      m3_ = (wanted - static_cast<double>(stored)) * area;
      return stored;
    }
  }
  // Volume (m^3) owed to the surface by rounding: true volume = stored volume + m3().
  double m3() const { return m3_; }
  // For kernels that settle the carry themselves (erosion_kernel.hpp).
  double& m3() { return m3_; }

 private:
  double m3_ = 0.0;
};

}  // namespace sb::grid
