#include "grid/multires_settle.hpp"

#include <array>
#include <stdexcept>

#include "grid/stencil.hpp"

namespace sb::grid {

MultiresAxis MultiresAxis::coarsen(const MultiresAxis& finer, bool halve) {
  MultiresAxis a;
  const std::size_t n = finer.size(), step = halve ? 2 : 1;
  a.parent.resize(n);
  for (std::size_t i = 0; i < n; i += step) {
    const std::size_t c0 = i, c1 = i + 1;
    a.parent[c0] = static_cast<std::uint32_t>(a.weight.size());
    if (step == 2 && c1 < n) {
      a.parent[c1] = a.parent[c0];
      const double w = finer.weight[c0] + finer.weight[c1];
      a.position.push_back((finer.weight[c0] * finer.position[c0] + finer.weight[c1] * finer.position[c1]) / w);
      a.weight.push_back(w);
    } else {
      a.position.push_back(finer.position[c0]);
      a.weight.push_back(finer.weight[c0]);
    }
  }
  return a;
}

namespace {

// What a node's class depends on along one axis: which neighbours exist, the weights of the
// node and its neighbours, the distances to them.
struct AxisKey {
  bool has_lo = false, has_hi = false;
  double w = 0.0, w_lo = 0.0, w_hi = 0.0, d_lo = 0.0, d_hi = 0.0;
};

AxisKey key_of(const MultiresAxis& a, std::size_t i) {
  AxisKey k;
  k.has_lo = i > 0;
  k.has_hi = i + 1 < a.size();
  k.w = a.weight[i];
  if (k.has_lo) k.w_lo = a.weight[i - 1], k.d_lo = a.position[i] - a.position[i - 1];
  if (k.has_hi) k.w_hi = a.weight[i + 1], k.d_hi = a.position[i + 1] - a.position[i];
  return k;
}

// Equal up to the rounding of the centroids (interior spacings are equal in exact
// arithmetic; their floating-point differences must not make a class per node).
bool same(const AxisKey& a, const AxisKey& b) {
  const auto near = [](double u, double v) { return std::abs(u - v) <= 1e-9 * std::max(std::abs(u), std::abs(v)); };
  return a.has_lo == b.has_lo && a.has_hi == b.has_hi && near(a.w, b.w) && near(a.w_lo, b.w_lo) &&
         near(a.w_hi, b.w_hi) && near(a.d_lo, b.d_lo) && near(a.d_hi, b.d_hi);
}

// Per node of the axis, the index of its key among the distinct keys; the first node with
// each key represents it.
std::vector<std::uint8_t> categories(const MultiresAxis& a, std::vector<std::size_t>& representative) {
  std::vector<std::uint8_t> cat(a.size());
  std::vector<AxisKey> keys;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const AxisKey k = key_of(a, i);
    std::size_t c = 0;
    while (c < keys.size() && !same(keys[c], k)) ++c;
    if (c == keys.size()) {
      if (keys.size() == 255) throw std::logic_error("multires: too many node classes along an axis");
      keys.push_back(k);
      representative.push_back(i);
    }
    cat[i] = static_cast<std::uint8_t>(c);
  }
  return cat;
}

}  // namespace

MultiresClasses::MultiresClasses(const MultiresAxis& x, const MultiresAxis& y, int neighbours,
                                 const ErosionTables& fine) {
  std::vector<std::size_t> rep_x, rep_y;
  cx_ = categories(x, rep_x);
  cy_ = categories(y, rep_y);
  ny_classes_ = rep_y.size();
  classes_.resize(rep_x.size() * rep_y.size());
  const auto nx = static_cast<std::ptrdiff_t>(x.size());
  for (std::size_t a = 0; a < rep_x.size(); ++a) {
    for (std::size_t b = 0; b < rep_y.size(); ++b) {
      const std::size_t ix = rep_x[a], iy = rep_y[b];
      NodeClass& c = classes_[a * ny_classes_ + b];
      c.area_i = x.weight[ix] * y.weight[iy];
      c.inv_area_i = 1.0 / c.area_i;
      for (int s = 0; s < 8; ++s) {
        const int ox = kStencilOffsets[s][0], oy = kStencilOffsets[s][1];
        const std::size_t jx = ix + static_cast<std::size_t>(ox), jy = iy + static_cast<std::size_t>(oy);
        if (s < neighbours && jx < x.size() && jy < y.size())  // (wraps below 0)
          c.set_neighbour(s, ox + oy * nx, x.weight[jx] * y.weight[jy], x.position[jx] - x.position[ix],
                          y.position[jy] - y.position[iy], fine.tan_critical(), fine.tan_settle());
        else
          c.set_missing(s);
      }
      const bool xlo = ix > 0, xhi = ix + 1 < x.size(), ylo = iy > 0, yhi = iy + 1 < y.size();
      c.gx_hi = xhi ? 1 : 0;
      c.gx_lo = xlo ? -1 : 0;
      c.gy_hi = yhi ? nx : 0;
      c.gy_lo = ylo ? -nx : 0;
      const double run_x = x.position[xhi ? ix + 1 : ix] - x.position[xlo ? ix - 1 : ix];
      const double run_y = y.position[yhi ? iy + 1 : iy] - y.position[ylo ? iy - 1 : iy];
      c.inv_run_x = run_x > 0.0 ? 1.0 / run_x : 0.0;
      c.inv_run_y = run_y > 0.0 ? 1.0 / run_y : 0.0;
    }
  }
}

}  // namespace sb::grid
