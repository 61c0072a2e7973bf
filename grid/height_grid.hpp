#pragma once
// HeightGrid<Real>: the heights of a GridLayout's nodes, stored as float or double, read
// and written in double. sizeof(Real) bytes per node.
//
// Writes carry their rounding error: storing a height in a float loses up to half a unit
// in the last place (ulp), i.e. up to 0.5 ulp(z) * A of volume. That loss is remembered as
// a volume (`carry_m3`) and added to the next node written, so the stored volume never
// drifts by more than one rounding step however many writes are made (error diffusion,
// the way a dithered image keeps its mean). With double storage the carry stays zero.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <type_traits>
#include <vector>

#include "grid/compensated_sum.hpp"
#include "grid/grid_layout.hpp"

namespace sb::grid {

template <class Real>
class HeightGrid {
  static_assert(std::is_same_v<Real, float> || std::is_same_v<Real, double>);

 public:
  HeightGrid(const GridLayout& layout, const std::function<double(const Vec2&)>& initial)
      : layout_(layout), z_(layout.nodes()) {
    // Plain rounding here: the initial volume is whatever the grid stores.
    for (std::size_t iy = 0; iy < layout_.ny; ++iy)
      for (std::size_t ix = 0; ix < layout_.nx; ++ix)
        z_[layout_.index(ix, iy)] = static_cast<Real>(initial(layout_.position(ix, iy)));
  }

  const GridLayout& layout() const { return layout_; }
  const std::vector<Real>& heights() const { return z_; }
  double z(std::size_t ix, std::size_t iy) const { return z(std::size_t{layout_.index(ix, iy)}); }

  // Stores `target` (m) at node k; with float storage the rounding error is carried on.
  void set(std::uint32_t k, double target) { set(k, target, layout_.area(k)); }
  // The same, for callers that know the node's area (layout().area(k)) already.
  void set(std::uint32_t k, double target, double area) {
    if constexpr (std::is_same_v<Real, double>) {
      (void)area;
      z_[k] = target;
    } else {
      // 1 / area does not depend on the carry, so it is computed off the carry's chain of
      // dependent operations, which runs through every float write.
      const double inverse_area = 1.0 / area;
      const double wanted = target + carry_m3_ * inverse_area;
      const Real stored = static_cast<Real>(wanted);
      carry_m3_ = (wanted - static_cast<double>(stored)) * area;
      z_[k] = stored;
    }
  }
  // Volume (m^3) owed to the surface by rounding: true volume = volume() + carry_m3().
  double carry_m3() const { return carry_m3_; }

  // The erosion kernel's storage concept (erosion_kernel.hpp): a plain rounded store that
  // returns its rounding error (m), and the carry, which the kernel settles itself.
  static constexpr bool kRounds = !std::is_same_v<Real, double>;
  double z(std::size_t k) const { return static_cast<double>(z_[k]); }
  double put(std::size_t k, double target) {
    const Real stored = static_cast<Real>(target);
    z_[k] = stored;
    if constexpr (kRounds) return target - static_cast<double>(stored);
    return 0.0;
  }
  double& carry() { return carry_m3_; }

  // Bilinear interpolation of the node heights, p clamped to the domain. O(1).
  double height(const Vec2& p) const {
    const double gx = std::clamp((p.x() - layout_.origin.x()) / layout_.dx, 0.0, static_cast<double>(layout_.nx - 1));
    const double gy = std::clamp((p.y() - layout_.origin.y()) / layout_.dy, 0.0, static_cast<double>(layout_.ny - 1));
    const std::size_t ix = std::min(static_cast<std::size_t>(gx), layout_.nx - 2);
    const std::size_t iy = std::min(static_cast<std::size_t>(gy), layout_.ny - 2);
    const double tx = gx - static_cast<double>(ix), ty = gy - static_cast<double>(iy);
    const std::size_t k = iy * layout_.nx + ix;
    const double z00 = z_[k], z10 = z_[k + 1], z01 = z_[k + layout_.nx], z11 = z_[k + layout_.nx + 1];
    return (1.0 - ty) * ((1.0 - tx) * z00 + tx * z10) + ty * ((1.0 - tx) * z01 + tx * z11);
  }

  // The exact integral of the bilinear interpolant over the domain: sum of A_k z_k with
  // the trapezoid weights, summed with compensation. O(nodes).
  double volume() const {
    CompensatedSum total;
    for (std::size_t iy = 0; iy < layout_.ny; ++iy) {
      CompensatedSum row;
      const Real* z = z_.data() + iy * layout_.nx;
      for (std::size_t ix = 0; ix < layout_.nx; ++ix) row.add(layout_.weight_x(ix) * static_cast<double>(z[ix]));
      total.add(layout_.weight_y(iy) * row.value());
    }
    return total.value();
  }

  std::size_t bytes() const { return z_.capacity() * sizeof(Real); }

 private:
  GridLayout layout_;
  std::vector<Real> z_;
  double carry_m3_ = 0.0;
};

}  // namespace sb::grid
