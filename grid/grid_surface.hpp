#pragma once
// The surface operations every grid storage `H` shares (HeightGrid, SparseHeights: they
// provide layout(), z(ix, iy) and carry_m3()): the mesh, sampling, the steepest slope and
// the height checks, written once so that the dense and sparse grids answer alike.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "common/raster.hpp"
#include "common/terrain.hpp"
#include "grid/grid_layout.hpp"
#include "grid/stencil.hpp"

namespace sb::grid {

// The two triangles of cell (ix, iy), counter-clockwise seen from above; vertex k = node k.
inline std::array<std::array<std::uint32_t, 3>, 2> grid_cell_triangles(const GridLayout& layout, std::size_t ix,
                                                                       std::size_t iy) {
  const std::uint32_t a = layout.index(ix, iy), b = a + 1;
  const std::uint32_t c = layout.index(ix, iy + 1), d = c + 1;
  return {{{a, b, d}, {a, d, c}}};
}

// The same mesh as grid_mesh, handed to `sink` a row of nodes (then a row of cells) at a
// time, so that writing it holds no copy of the whole mesh: the run file's writer for
// either storage. O(nodes) time, O(nx) memory.
template <class H>
void grid_stream_mesh(const H& h, MeshSink& sink) {
  const GridLayout& layout = h.layout();
  sink.begin(layout.nodes(), 2 * (layout.nx - 1) * (layout.ny - 1), 0);
  std::vector<Vec3> row(layout.nx);
  for (std::size_t iy = 0; iy < layout.ny; ++iy) {
    for (std::size_t ix = 0; ix < layout.nx; ++ix) {
      const Vec2 p = layout.position(ix, iy);
      row[ix] = Vec3(p.x(), p.y(), h.z(ix, iy));
    }
    sink.vertices(row);
  }
  row = {};
  std::vector<std::array<std::uint32_t, 3>> cells(2 * (layout.nx - 1));
  for (std::size_t iy = 0; iy + 1 < layout.ny; ++iy) {
    for (std::size_t ix = 0; ix + 1 < layout.nx; ++ix) {
      const auto pair = grid_cell_triangles(layout, ix, iy);
      cells[2 * ix] = pair[0];
      cells[2 * ix + 1] = pair[1];
    }
    sink.triangles(cells);
  }
  sink.constrained_edges({});
}

// Two triangles per cell (grid_cell_triangles); vertex k = node k. O(nodes).
template <class H>
SurfaceMesh grid_mesh(const H& h) {
  const GridLayout& layout = h.layout();
  SurfaceMesh m;
  m.vertices.reserve(layout.nodes());
  for (std::size_t iy = 0; iy < layout.ny; ++iy)
    for (std::size_t ix = 0; ix < layout.nx; ++ix) {
      const Vec2 p = layout.position(ix, iy);
      m.vertices.emplace_back(p.x(), p.y(), h.z(ix, iy));
    }
  m.triangles.reserve(2 * (layout.nx - 1) * (layout.ny - 1));
  for (std::size_t iy = 0; iy + 1 < layout.ny; ++iy)
    for (std::size_t ix = 0; ix + 1 < layout.nx; ++ix) {
      const auto pair = grid_cell_triangles(layout, ix, iy);
      m.triangles.push_back(pair[0]);
      m.triangles.push_back(pair[1]);
    }
  return m;
}

// The interpolant at every raster point. O(raster points).
template <class H>
void grid_sample(const H& h, Raster& out) {
  out.values.resize(out.nx * out.ny);
  for (std::size_t iy = 0; iy < out.ny; ++iy)
    for (std::size_t ix = 0; ix < out.nx; ++ix) out.at(ix, iy) = h.height(out.point(ix, iy));
}

// Steepest slope between stencil neighbours, degrees. O(nodes * stencil).
template <class H>
double grid_max_slope_deg(const H& h, const Stencil& stencil) {
  const GridLayout& layout = h.layout();
  double steepest = 0.0;  // tangent
  for (std::size_t iy = 0; iy < layout.ny; ++iy)
    for (std::size_t ix = 0; ix < layout.nx; ++ix) {
      const double z = h.z(ix, iy);
      stencil.for_each(layout, ix, iy, [&](std::size_t jx, std::size_t jy, int slot) {
        // Each pair once: only the neighbours ahead in storage order.
        if (jy < iy || (jy == iy && jx < ix)) return;
        steepest = std::max(steepest, std::abs(h.z(jx, jy) - z) / stencil.distance_m[slot]);
      });
    }
  return rad_to_deg(std::atan(steepest));
}

// The layout is sane, every height finite, the rounding carry within one ulp of a height
// times a cell area, the stencil 4 or 8. Problems are prefixed with `who`. O(nodes).
template <class Real, class H>
void check_grid_heights(const H& h, const Stencil& stencil, const std::string& who,
                        std::vector<std::string>& problems) {
  const GridLayout& layout = h.layout();
  if (layout.nx < 2 || layout.ny < 2) problems.push_back(who + ": fewer than 2 nodes along an axis");
  if (!(layout.dx > 0.0 && layout.dy > 0.0 && std::isfinite(layout.dx) && std::isfinite(layout.dy)))
    problems.push_back(who + ": cell size not positive and finite");
  std::size_t bad = 0;
  double max_abs_z = 0.0;
  for (std::size_t iy = 0; iy < layout.ny; ++iy)
    for (std::size_t ix = 0; ix < layout.nx; ++ix) {
      const double z = h.z(ix, iy);
      if (!std::isfinite(z)) {
        if (++bad <= 3) problems.push_back(who + ": height " + std::to_string(z) + " is not finite");
      } else {
        max_abs_z = std::max(max_abs_z, std::abs(z));
      }
    }
  if (bad > 3) problems.push_back(who + ": " + std::to_string(bad) + " heights not finite in all");
  const double ulp = max_abs_z * std::numeric_limits<Real>::epsilon() + std::numeric_limits<Real>::min();
  if (!(std::abs(h.carry_m3()) <= ulp * layout.dx * layout.dy))
    problems.push_back(who + ": rounding carry " + std::to_string(h.carry_m3()) + " m^3 exceeds one ulp");
  if (stencil.size != 4 && stencil.size != 8) problems.push_back(who + ": stencil size not 4 or 8");
}

}  // namespace sb::grid
