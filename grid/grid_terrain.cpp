#include "grid/grid_terrain.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "grid/grid_stamp.hpp"

namespace sb::grid {

template <class Real>
GridTerrain<Real>::GridTerrain(const GridLayout& layout, const std::function<double(const Vec2&)>& initial,
                               int neighbours, int idle_passes)
    : grid_(layout, initial), stencil_(Stencil::make(layout, neighbours)), active_(layout.nx, layout.ny, idle_passes) {}

template <class Real>
StampReport GridTerrain<Real>::stamp(const ToolStamp& s) {
  std::vector<std::uint32_t> changed;
  const StampReport report = stamp_grid(grid_, s, changed);
  const GridLayout& layout = grid_.layout();
  for (std::uint32_t k : changed) {
    const auto [ix, iy] = layout.split(k);
    active_.activate_block(ix, iy);
  }
  return report;
}

template <class Real>
ErosionReport GridTerrain<Real>::erode(const ErosionRule& rule, const ErosionBudget& budget) {
  const bool gradient = false;
  if (!tables_ || !tables_->built_for(rule, gradient)) tables_.emplace(grid_.layout(), stencil_.size, rule, gradient);
  return erode_ordered(grid_, active_, *tables_, budget);
}

template <class Real>
ModelStats GridTerrain<Real>::stats() const {
  ModelStats st;
  st.cells = grid_.layout().nodes();
  st.bytes = grid_.bytes() + active_.bytes() + (tables_ ? tables_->bytes() : 0);
  st.active = active_.size();
  return st;
}

template <class Real>
SurfaceMesh GridTerrain<Real>::mesh() const {
  const GridLayout& layout = grid_.layout();
  SurfaceMesh m;
  m.vertices.reserve(layout.nodes());
  for (std::size_t iy = 0; iy < layout.ny; ++iy)
    for (std::size_t ix = 0; ix < layout.nx; ++ix) {
      const Vec2 p = layout.position(ix, iy);
      m.vertices.emplace_back(p.x(), p.y(), grid_.z(ix, iy));
    }
  m.triangles.reserve(2 * (layout.nx - 1) * (layout.ny - 1));
  for (std::size_t iy = 0; iy + 1 < layout.ny; ++iy)
    for (std::size_t ix = 0; ix + 1 < layout.nx; ++ix) {
      const std::uint32_t a = layout.index(ix, iy), b = a + 1;
      const std::uint32_t c = layout.index(ix, iy + 1), d = c + 1;
      m.triangles.push_back({a, b, d});  // counter-clockwise seen from above
      m.triangles.push_back({a, d, c});
    }
  return m;
}

template <class Real>
void GridTerrain<Real>::sample(Raster& out) const {
  out.values.resize(out.nx * out.ny);
  for (std::size_t iy = 0; iy < out.ny; ++iy)
    for (std::size_t ix = 0; ix < out.nx; ++ix) out.at(ix, iy) = grid_.height(out.point(ix, iy));
}

template <class Real>
IntegrityReport GridTerrain<Real>::check() const {
  IntegrityReport r;
  const GridLayout& layout = grid_.layout();
  if (layout.nx < 2 || layout.ny < 2) r.problems.push_back("grid: fewer than 2 nodes along an axis");
  if (!(layout.dx > 0.0 && layout.dy > 0.0 && std::isfinite(layout.dx) && std::isfinite(layout.dy)))
    r.problems.push_back("grid: cell size not positive and finite");
  if (grid_.heights().size() != layout.nodes())
    r.problems.push_back("grid: " + std::to_string(grid_.heights().size()) + " heights for " +
                         std::to_string(layout.nodes()) + " nodes");
  std::size_t bad = 0;
  double max_abs_z = 0.0;
  for (Real z : grid_.heights()) {
    if (!std::isfinite(z)) {
      if (++bad <= 3) r.problems.push_back("grid: height " + std::to_string(z) + " is not finite");
    } else {
      max_abs_z = std::max(max_abs_z, std::abs(static_cast<double>(z)));
    }
  }
  if (bad > 3) r.problems.push_back("grid: " + std::to_string(bad) + " heights not finite in all");
  // The rounding carry is at most half an ulp of a height times a cell area.
  const double ulp = max_abs_z * std::numeric_limits<Real>::epsilon() + std::numeric_limits<Real>::min();
  if (!(std::abs(grid_.carry_m3()) <= ulp * layout.dx * layout.dy))
    r.problems.push_back("grid: rounding carry " + std::to_string(grid_.carry_m3()) + " m^3 exceeds one ulp");
  if (stencil_.size != 4 && stencil_.size != 8) r.problems.push_back("grid: stencil size not 4 or 8");
  active_.check(r.problems);
  return r;
}

template <class Real>
double GridTerrain<Real>::max_slope_deg() const {
  const GridLayout& layout = grid_.layout();
  double steepest = 0.0;  // tangent
  for (std::size_t iy = 0; iy < layout.ny; ++iy)
    for (std::size_t ix = 0; ix < layout.nx; ++ix) {
      const double z = grid_.z(ix, iy);
      stencil_.for_each(layout, ix, iy, [&](std::size_t jx, std::size_t jy, int slot) {
        // Each pair once: only the neighbours ahead in storage order.
        if (jy < iy || (jy == iy && jx < ix)) return;
        steepest = std::max(steepest, std::abs(grid_.z(jx, jy) - z) / stencil_.distance_m[slot]);
      });
    }
  return rad_to_deg(std::atan(steepest));
}

template class GridTerrain<float>;
template class GridTerrain<double>;

std::unique_ptr<Terrain> make_grid_terrain(const Scene& scene, const HeightField& initial) {
  const GridLayout layout = GridLayout::covering(scene.domain.box(), scene.grid.cell_m);
  const auto z0 = [&initial](const Vec2& p) { return initial(p); };
  if (scene.grid.storage == GridStorage::Float)
    return std::make_unique<GridTerrain<float>>(layout, z0, scene.grid.neighbours, scene.erosion.idle_passes);
  return std::make_unique<GridTerrain<double>>(layout, z0, scene.grid.neighbours, scene.erosion.idle_passes);
}

}  // namespace sb::grid
