#pragma once
// Stencil: a node's erosion neighbours on the grid -- 8 (axis neighbours at dx and dy,
// diagonals at sqrt(dx^2 + dy^2)) or 4 (axis neighbours only).
#include <array>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "grid/grid_layout.hpp"

namespace sb::grid {

// The neighbours' (x, y) index offsets, axis ones first. The order is fixed: part of what
// makes erosion deterministic, shared by the stencil and the erosion kernel's node classes.
inline constexpr int kStencilOffsets[8][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, 1}, {-1, 1}, {1, -1}, {-1, -1}};

struct Stencil {
  int size = 8;
  std::array<int, 8> ox{}, oy{};       // index offsets
  std::array<double, 8> distance_m{};  // horizontal distance to the neighbour

  static Stencil make(const GridLayout& layout, int neighbours) {
    if (neighbours != 4 && neighbours != 8)
      throw std::invalid_argument("grid stencil: neighbours must be 4 or 8, not " + std::to_string(neighbours));
    Stencil s;
    s.size = neighbours;
    const double d = layout.diagonal();
    for (int i = 0; i < 8; ++i) {
      s.ox[i] = kStencilOffsets[i][0];
      s.oy[i] = kStencilOffsets[i][1];
      s.distance_m[i] = i < 2 ? layout.dx : i < 4 ? layout.dy : d;
    }
    return s;
  }

  // Calls f(neighbour index, stencil slot) for each neighbour of (ix, iy) inside the grid.
  template <class F>
  void for_each(const GridLayout& layout, std::size_t ix, std::size_t iy, F&& f) const {
    const bool interior = ix > 0 && iy > 0 && ix + 1 < layout.nx && iy + 1 < layout.ny;
    for (int i = 0; i < size; ++i) {
      const std::size_t jx = ix + static_cast<std::size_t>(ox[i]);  // wraps below 0: out of range
      const std::size_t jy = iy + static_cast<std::size_t>(oy[i]);
      if (!interior && (jx >= layout.nx || jy >= layout.ny)) continue;
      f(jx, jy, i);
    }
  }
};

}  // namespace sb::grid
