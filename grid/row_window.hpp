#pragma once
// RowWindow: three rows of a store whose heights are not contiguous (the sparse grid), copied
// into contiguous buffers for the dense erosion pass (erosion_kernel.hpp), which then runs
// its vector classing and lane visits on them as on the dense grid, and written back.
//
// A visit of a node of row iy reads and writes only rows iy - 1 .. iy + 1, columns ix - 1 ..
// ix + 1, and the pass finishes a row before it starts the next: with the window loaded with
// the columns a row's visits touch (load, extend) and written back before the next row's load
// (store_back), the visits see exactly the heights they would see on the store itself, so the
// heights come out the same, bit for bit. Only heights whose bits changed are written back.
//
// The storage concept of erosion_kernel.hpp, node k = r * nx + ix of window row r (row
// iy - 1 + r); the rounding carry is the store's. The Store provides value_type, read_row(iy,
// x0, x1, out) and write_changed(iy, x0, x1, values, before) (SparseHeights).
// Memory: 2 x 3 x nx heights. Costs: load / store_back O(columns), z / put O(1).
#include <cstddef>
#include <vector>

#include "grid/rounding_carry.hpp"

namespace sb::grid {

template <class Store>
class RowWindow {
 public:
  using Real = typename Store::value_type;
  static constexpr bool kRounds = Store::kRounds;

  RowWindow(Store& store, std::size_t nx, std::size_t ny)
      : store_(store), nx_(nx), ny_(ny), z_(3 * nx), before_(3 * nx) {}

  // Columns x0..x1 of the rows iy - 1 .. iy + 1 that exist.
  void load(std::size_t iy, std::size_t x0, std::size_t x1) {
    iy_ = iy, lo_ = x0, hi_ = x1;
    copy_in(x0, x1);
  }
  // The loaded columns grown to hold x0..x1 (a span that grows at its end).
  void extend(std::size_t x0, std::size_t x1) {
    if (x0 < lo_) copy_in(x0, lo_ - 1), lo_ = x0;
    if (x1 > hi_) copy_in(hi_ + 1, x1), hi_ = x1;
  }
  // The heights that changed, back into the store.
  void store_back() {
    for (std::size_t r = 0; r < 3; ++r)
      if (exists(r))
        store_.write_changed(iy_ + r - 1, lo_, hi_, z_.data() + r * nx_ + lo_, before_.data() + r * nx_ + lo_);
  }

  double z(std::size_t k) const { return static_cast<double>(z_[k]); }
  double put(std::size_t k, double target) {
    z_[k] = static_cast<Real>(target);
    return rounding_error(target, z_[k]);
  }
  double& carry() { return store_.carry(); }
  Real* data() { return z_.data(); }
  const Real* data() const { return z_.data(); }

 private:
  bool exists(std::size_t r) const { return iy_ + r >= 1 && iy_ + r - 1 < ny_; }
  void copy_in(std::size_t x0, std::size_t x1) {
    for (std::size_t r = 0; r < 3; ++r)
      if (exists(r)) {
        store_.read_row(iy_ + r - 1, x0, x1, z_.data() + r * nx_ + x0);
        for (std::size_t x = x0; x <= x1; ++x) before_[r * nx_ + x] = z_[r * nx_ + x];
      }
  }

  Store& store_;
  std::size_t nx_, ny_;
  std::size_t iy_ = 0, lo_ = 0, hi_ = 0;
  std::vector<Real> z_, before_;  // rows iy - 1, iy, iy + 1 at r * nx; as loaded
};

}  // namespace sb::grid
