#include "grid/sparse_terrain.hpp"

#include "grid/grid_surface.hpp"
#include "grid/stamp_kernel.hpp"

namespace sb::grid {

template <class Real>
ErosionReport SparseGridTerrain<Real>::erode(const ErosionRule& rule, const ErosionBudget& budget) {
  ErosionReport report = GridTerrainBase<SparseHeights<Real>, SparseActiveSet>::erode(rule, budget);
  // Settled: blocks that came back to one height become tiles again.
  if (this->active_.empty()) this->heights_.prune();
  return report;
}

template <class Real>
IntegrityReport SparseGridTerrain<Real>::check() const {
  IntegrityReport r;
  check_grid_heights<Real>(this->heights_, this->stencil_, "sparse", r.problems);
  this->heights_.check(r.problems);
  this->active_.check(r.problems);
  return r;
}

template class GridTerrainBase<SparseHeights<float>, SparseActiveSet>;
template class GridTerrainBase<SparseHeights<double>, SparseActiveSet>;
template class SparseGridTerrain<float>;
template class SparseGridTerrain<double>;

std::unique_ptr<Terrain> make_sparse_terrain(const Scene& scene, const HeightField& initial) {
  return make_grid_model<SparseGridTerrain>(scene, initial);
}

}  // namespace sb::grid
