#include "grid/grid_terrain.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "grid/grid_stamp.hpp"
#include "grid/grid_surface.hpp"

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
  return grid_mesh(grid_);
}

template <class Real>
void GridTerrain<Real>::sample(Raster& out) const {
  grid_sample(grid_, out);
}

template <class Real>
IntegrityReport GridTerrain<Real>::check() const {
  IntegrityReport r;
  const GridLayout& layout = grid_.layout();
  if (grid_.heights().size() != layout.nodes())
    r.problems.push_back("grid: " + std::to_string(grid_.heights().size()) + " heights for " +
                         std::to_string(layout.nodes()) + " nodes");
  check_grid_heights<Real>(grid_, stencil_, "grid", r.problems);
  active_.check(r.problems);
  return r;
}

template <class Real>
double GridTerrain<Real>::max_slope_deg() const {
  return grid_max_slope_deg(grid_, stencil_);
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
