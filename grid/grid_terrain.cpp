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
  const double carry_before = grid_.carry_m3();
  StampReport report = stamp_grid(grid_, s, changed);
  // What the stored volume changed by: the stamp's own sums, less what rounding put into
  // the carry (zero in double).
  report.volume_change_m3 = report.volume_deposited_m3 - report.volume_removed_m3 - (grid_.carry_m3() - carry_before);
  const GridLayout& layout = grid_.layout();
  for (std::uint32_t k : changed) {
    const auto [ix, iy] = layout.split(k);
    active_.activate_block(ix, iy);
  }
  return report;
}

template <class Real>
ErosionReport GridTerrain<Real>::erode(const ErosionRule& rule, const ErosionBudget& budget) {
  const bool gradient = rule.needs_gradient();
  if (!tables_ || !tables_->built_for(rule, gradient)) tables_.emplace(grid_.layout(), stencil_.size, rule, gradient);
  const double carry_before = grid_.carry_m3();
  ErosionReport report = erode_settling(grid_, active_, *tables_, budget, sweep_path_, multires_);
  // Transfers conserve volume; only rounding into the carry changes the stored volume.
  report.volume_change_m3 = carry_before - grid_.carry_m3();
  return report;
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
void GridTerrain<Real>::stream_mesh(MeshSink& sink) const {
  // The same mesh as mesh(), a row of nodes (and the triangles of a row of cells) at a time.
  const GridLayout& layout = grid_.layout();
  sink.begin(layout.nodes(), 2 * (layout.nx - 1) * (layout.ny - 1), 0);
  std::vector<Vec3> row(layout.nx);
  for (std::size_t iy = 0; iy < layout.ny; ++iy) {
    for (std::size_t ix = 0; ix < layout.nx; ++ix) {
      const Vec2 p = layout.position(ix, iy);
      row[ix] = Vec3(p.x(), p.y(), grid_.z(ix, iy));
    }
    sink.vertices(row);
  }
  row = {};
  std::vector<std::array<std::uint32_t, 3>> cells(2 * (layout.nx - 1));
  for (std::size_t iy = 0; iy + 1 < layout.ny; ++iy) {
    for (std::size_t ix = 0; ix + 1 < layout.nx; ++ix) {
      const std::uint32_t a = layout.index(ix, iy), b = a + 1;
      const std::uint32_t c = layout.index(ix, iy + 1), d = c + 1;
      cells[2 * ix] = {a, b, d};  // as in mesh()
      cells[2 * ix + 1] = {a, d, c};
    }
    sink.triangles(cells);
  }
  sink.constrained_edges({});
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
