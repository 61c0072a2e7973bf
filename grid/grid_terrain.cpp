#include "grid/grid_terrain.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "grid/grid_surface.hpp"

namespace sb::grid {

template <class Real>
void GridTerrain<Real>::stream_mesh(MeshSink& sink) const {
  // The same mesh as mesh(), a row of nodes (and the triangles of a row of cells) at a time.
  const GridLayout& layout = this->heights_.layout();
  sink.begin(layout.nodes(), 2 * (layout.nx - 1) * (layout.ny - 1), 0);
  std::vector<Vec3> row(layout.nx);
  for (std::size_t iy = 0; iy < layout.ny; ++iy) {
    for (std::size_t ix = 0; ix < layout.nx; ++ix) {
      const Vec2 p = layout.position(ix, iy);
      row[ix] = Vec3(p.x(), p.y(), this->heights_.z(ix, iy));
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
IntegrityReport GridTerrain<Real>::check() const {
  IntegrityReport r;
  const GridLayout& layout = this->heights_.layout();
  if (this->heights_.heights().size() != layout.nodes())
    r.problems.push_back("grid: " + std::to_string(this->heights_.heights().size()) + " heights for " +
                         std::to_string(layout.nodes()) + " nodes");
  check_grid_heights<Real>(this->heights_, this->stencil_, "grid", r.problems);
  this->active_.check(r.problems);
  return r;
}

template class GridTerrainBase<HeightGrid<float>, ActiveSet>;
template class GridTerrainBase<HeightGrid<double>, ActiveSet>;
template class GridTerrain<float>;
template class GridTerrain<double>;

std::unique_ptr<Terrain> make_grid_terrain(const Scene& scene, const HeightField& initial) {
  return make_grid_model<GridTerrain>(scene, initial);
}

}  // namespace sb::grid
