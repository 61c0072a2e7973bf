#pragma once
// GridLayout: where the nodes of a regular height grid lie and how much area each stands
// for. Nodes cover the domain exactly, corners included, so cells may be very slightly
// non-square (dx != dy). Every function is O(1).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <utility>

#include "common/geometry.hpp"

namespace sb::grid {

// Inclusive node index ranges; `empty` when the box misses the grid.
struct NodeRange {
  std::size_t x0 = 0, x1 = 0, y0 = 0, y1 = 0;
  bool empty = true;
  std::size_t count() const { return empty ? 0 : (x1 - x0 + 1) * (y1 - y0 + 1); }
};

struct GridLayout {
  Vec2 origin{0.0, 0.0};
  std::size_t nx = 2, ny = 2;
  double dx = 1.0, dy = 1.0;

  // nx = max(2, round(size.x / cell) + 1), dx = size.x / (nx - 1); the same along y.
  static GridLayout covering(const Aabb2& domain, double cell_m) {
    GridLayout g;
    g.origin = domain.lo;
    const Vec2 size = domain.hi - domain.lo;
    g.nx = static_cast<std::size_t>(std::max(2.0, std::round(size.x() / cell_m) + 1.0));
    g.ny = static_cast<std::size_t>(std::max(2.0, std::round(size.y() / cell_m) + 1.0));
    g.dx = size.x() / static_cast<double>(g.nx - 1);
    g.dy = size.y() / static_cast<double>(g.ny - 1);
    return g;
  }

  std::size_t nodes() const { return nx * ny; }
  double diagonal() const { return std::sqrt(dx * dx + dy * dy); }
  Aabb2 box() const {
    return {origin, origin + Vec2(dx * static_cast<double>(nx - 1), dy * static_cast<double>(ny - 1))};
  }
  std::uint32_t index(std::size_t ix, std::size_t iy) const { return static_cast<std::uint32_t>(iy * nx + ix); }
  Vec2 position(std::size_t ix, std::size_t iy) const {
    return {origin.x() + dx * static_cast<double>(ix), origin.y() + dy * static_cast<double>(iy)};
  }

  // Area weights of the bilinear interpolant's integral (trapezoid rule): a full cell
  // inside, half on a border, a quarter at a corner.
  double weight_x(std::size_t ix) const { return ix == 0 || ix + 1 == nx ? 0.5 * dx : dx; }
  double weight_y(std::size_t iy) const { return iy == 0 || iy + 1 == ny ? 0.5 * dy : dy; }
  double area(std::size_t ix, std::size_t iy) const { return weight_x(ix) * weight_y(iy); }
  double area(std::uint32_t k) const {
    const auto [ix, iy] = split(k);
    return area(ix, iy);
  }
  // (ix, iy) of node k, with a single 32-bit division (this is in erosion's inner loop).
  std::pair<std::size_t, std::size_t> split(std::uint32_t k) const {
    const std::uint32_t iy = k / static_cast<std::uint32_t>(nx);
    return {k - iy * static_cast<std::uint32_t>(nx), iy};
  }

  // Nodes inside `box` (closed), clipped to the grid. A node within a billionth of a cell
  // of the box's edge counts as inside: it may lie on the tool's footprint.
  NodeRange nodes_in(const Aabb2& box) const {
    constexpr double slack = 1e-9;
    const double fx0 = std::ceil((box.lo.x() - origin.x()) / dx - slack);
    const double fx1 = std::floor((box.hi.x() - origin.x()) / dx + slack);
    const double fy0 = std::ceil((box.lo.y() - origin.y()) / dy - slack);
    const double fy1 = std::floor((box.hi.y() - origin.y()) / dy + slack);
    const double mx = static_cast<double>(nx - 1), my = static_cast<double>(ny - 1);
    // Written so that NaN bounds give an empty range.
    if (!(fx1 >= 0.0 && fy1 >= 0.0 && fx0 <= mx && fy0 <= my && fx0 <= fx1 && fy0 <= fy1)) return {};
    NodeRange r;
    r.x0 = static_cast<std::size_t>(std::max(0.0, fx0));
    r.x1 = static_cast<std::size_t>(std::min(mx, fx1));
    r.y0 = static_cast<std::size_t>(std::max(0.0, fy0));
    r.y1 = static_cast<std::size_t>(std::min(my, fy1));
    r.empty = false;
    return r;
  }

  // The node nearest to p, p clamped to the grid.
  std::uint32_t nearest(const Vec2& p) const {
    const double fx = std::clamp(std::round((p.x() - origin.x()) / dx), 0.0, static_cast<double>(nx - 1));
    const double fy = std::clamp(std::round((p.y() - origin.y()) / dy), 0.0, static_cast<double>(ny - 1));
    return index(static_cast<std::size_t>(fx), static_cast<std::size_t>(fy));
  }
};

}  // namespace sb::grid
