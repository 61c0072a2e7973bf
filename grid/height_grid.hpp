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

#include "grid/grid_layout.hpp"
#include "grid/height_queries.hpp"
#include "grid/rounding_carry.hpp"

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
  void set(std::uint32_t k, double target, double area) { z_[k] = carry_.round(target, area); }
  // Volume (m^3) owed to the surface by rounding: true volume = volume() + carry_m3().
  double carry_m3() const { return carry_.m3(); }

  // The erosion kernel's storage concept (erosion_kernel.hpp): a plain rounded store that
  // returns its rounding error (m), and the carry, which the kernel settles itself.
  static constexpr bool kRounds = !std::is_same_v<Real, double>;
  double z(std::size_t k) const { return static_cast<double>(z_[k]); }
  double put(std::size_t k, double target) {
    z_[k] = static_cast<Real>(target);
    return rounding_error(target, z_[k]);
  }
  double& carry() { return carry_.m3(); }
  // The heights, row-major (k = iy * nx + ix): the kernel's dense pass reads rows of them at once.
  const Real* data() const { return z_.data(); }
  // The same, writable: the kernel's eight-node visits store rows of a block at once
  // (erosion_lanes_avx512.hpp). Writes through it bypass the rounding carry: the kernel
  // settles the carry itself.
  Real* data() { return z_.data(); }

  double height(const Vec2& p) const { return bilinear_height(*this, p); }
  double volume() const { return trapezoid_volume(*this); }

  std::size_t bytes() const { return z_.capacity() * sizeof(Real); }

 private:
  GridLayout layout_;
  std::vector<Real> z_;
  RoundingCarry<Real> carry_;
};

}  // namespace sb::grid
