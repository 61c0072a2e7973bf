#include <algorithm>
#include <stdexcept>
#include <string>

#include "grid/erosion_kernel.hpp"
#include "grid/stencil.hpp"

namespace sb::grid {

namespace {

// The weight of a node along one axis (trapezoid rule: half a cell on the border), from
// the axis code's bits for its lower (1, 2) or upper (4, 8) side.
struct AxisNeighbourhood {
  bool has_lo, has_hi;
  double own, lo, hi;  // weights of the node and of its neighbours (0 where missing)
};

AxisNeighbourhood axis(unsigned code, double d) {
  AxisNeighbourhood a;
  a.has_lo = code & 1u;
  a.has_hi = code & 4u;
  a.own = a.has_lo && a.has_hi ? d : 0.5 * d;
  a.lo = !a.has_lo ? 0.0 : (code & 2u) ? 0.5 * d : d;
  a.hi = !a.has_hi ? 0.0 : (code & 8u) ? 0.5 * d : d;
  return a;
}

}  // namespace

ErosionTables::ErosionTables(const GridLayout& layout, int neighbours, const ErosionRule& rule, bool gradient)
    : layout_(layout),
      neighbours_(neighbours),
      gradient_(gradient),
      fraction_(rule.fraction),
      tan_critical_(rule.tan_critical),
      tan_settle_(rule.tan_settle) {
  if (neighbours != 4 && neighbours != 8)
    throw std::invalid_argument("grid stencil: neighbours must be 4 or 8, not " + std::to_string(neighbours));
  const auto nx = static_cast<std::ptrdiff_t>(layout.nx);
  // The axis codes that occur: those of the first two and last two nodes, and one inside.
  const auto codes = [](std::size_t n) {
    std::vector<unsigned> c;
    for (std::size_t i : {std::size_t{0}, std::size_t{1}, n / 2, n - 2, n - 1}) {
      if (i >= n) continue;
      const unsigned code = axis_code(i, n);
      if (std::find(c.begin(), c.end(), code) == c.end()) c.push_back(code);
    }
    return c;
  };
  const std::vector<unsigned> codes_x = codes(layout.nx), codes_y = codes(layout.ny);
  classes_.resize(codes_x.size() * codes_y.size());
  std::size_t next = 0;
  for (unsigned cy : codes_y) {
    for (unsigned cx : codes_x) {
      const AxisNeighbourhood ax = axis(cx, layout.dx), ay = axis(cy, layout.dy);
      slot_[cx | (cy << 4)] = static_cast<std::uint8_t>(next);
      NodeClass& c = classes_[next++];
      c.area_i = ax.own * ay.own;
      c.inv_area_i = 1.0 / c.area_i;
      for (int s = 0; s < 8; ++s) {
        const int ox = kStencilOffsets[s][0], oy = kStencilOffsets[s][1];
        const double wx = ox == 0 ? ax.own : ox > 0 ? ax.hi : ax.lo;
        const double wy = oy == 0 ? ay.own : oy > 0 ? ay.hi : ay.lo;
        c.ox[s] = ox * layout.dx;
        c.oy[s] = oy * layout.dy;
        if (s < neighbours && wx > 0.0 && wy > 0.0)
          c.set_neighbour(s, ox + oy * nx, wx * wy, ox * layout.dx, oy * layout.dy, rule.tan_critical, rule.tan_settle);
        else
          c.set_missing(s);
      }
      c.gx_hi = ax.has_hi ? 1 : 0;
      c.gx_lo = ax.has_lo ? -1 : 0;
      c.gy_hi = ay.has_hi ? nx : 0;
      c.gy_lo = ay.has_lo ? -nx : 0;
      const int span_x = (ax.has_hi ? 1 : 0) + (ax.has_lo ? 1 : 0);
      const int span_y = (ay.has_hi ? 1 : 0) + (ay.has_lo ? 1 : 0);
      c.inv_run_x = span_x > 0 ? 1.0 / (span_x * layout.dx) : 0.0;
      c.inv_run_y = span_y > 0 ? 1.0 / (span_y * layout.dy) : 0.0;
    }
  }
}

}  // namespace sb::grid
