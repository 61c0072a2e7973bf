#include "grid/grid_terrain.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "grid/grid_surface.hpp"

namespace sb::grid {

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
