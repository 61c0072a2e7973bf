#include "grid/sparse_terrain.hpp"

#include "grid/grid_stamp.hpp"
#include "grid/grid_surface.hpp"
#include "grid/stamp_kernel.hpp"

namespace sb::grid {

template <class Real>
SparseGridTerrain<Real>::SparseGridTerrain(const GridLayout& layout, const std::function<double(const Vec2&)>& initial,
                                           int neighbours, int idle_passes)
    : heights_(layout, initial),
      stencil_(Stencil::make(layout, neighbours)),
      active_(layout.nx, layout.ny, idle_passes) {}

template <class Real>
StampReport SparseGridTerrain<Real>::stamp(const ToolStamp& s) {
  std::vector<std::uint32_t> changed;
  const double carry_before = heights_.carry_m3();
  StampReport report = stamp_grid(heights_, s, changed);
  // What the stored volume changed by, as on the dense grid: the stamp's own sums, less what
  // rounding put into the carry (zero in double).
  report.volume_change_m3 =
      report.volume_deposited_m3 - report.volume_removed_m3 - (heights_.carry_m3() - carry_before);
  const GridLayout& layout = heights_.layout();
  for (std::uint32_t k : changed) {
    const auto [ix, iy] = layout.split(k);
    active_.activate_block(ix, iy);
  }
  return report;
}

template <class Real>
ErosionReport SparseGridTerrain<Real>::erode(const ErosionRule& rule, const ErosionBudget& budget) {
  const bool gradient = rule.needs_gradient();
  if (!tables_ || !tables_->built_for(rule, gradient))
    tables_.emplace(heights_.layout(), stencil_.size, rule, gradient);
  const double carry_before = heights_.carry_m3();
  ErosionReport report = erode_settling(heights_, active_, *tables_, budget, sweep_path_, multires_);
  // Transfers conserve volume; only rounding into the carry changes the stored volume.
  report.volume_change_m3 = carry_before - heights_.carry_m3();
  // Settled: blocks that came back to one height become tiles again.
  if (active_.empty()) heights_.prune();
  return report;
}

template <class Real>
ModelStats SparseGridTerrain<Real>::stats() const {
  ModelStats st;
  st.cells = heights_.layout().nodes();
  st.bytes = heights_.bytes() + active_.bytes() + (tables_ ? tables_->bytes() : 0);
  st.active = active_.size();
  return st;
}

template <class Real>
SurfaceMesh SparseGridTerrain<Real>::mesh() const {
  return grid_mesh(heights_);
}

template <class Real>
void SparseGridTerrain<Real>::sample(Raster& out) const {
  grid_sample(heights_, out);
}

template <class Real>
IntegrityReport SparseGridTerrain<Real>::check() const {
  IntegrityReport r;
  check_grid_heights<Real>(heights_, stencil_, "sparse", r.problems);
  heights_.check(r.problems);
  active_.check(r.problems);
  return r;
}

template <class Real>
double SparseGridTerrain<Real>::max_slope_deg() const {
  return grid_max_slope_deg(heights_, stencil_);
}

template class SparseGridTerrain<float>;
template class SparseGridTerrain<double>;

std::unique_ptr<Terrain> make_sparse_terrain(const Scene& scene, const HeightField& initial) {
  const GridLayout layout = GridLayout::covering(scene.domain.box(), scene.grid.cell_m);
  const auto z0 = [&initial](const Vec2& p) { return initial(p); };
  if (scene.grid.storage == GridStorage::Float)
    return std::make_unique<SparseGridTerrain<float>>(layout, z0, scene.grid.neighbours, scene.erosion.idle_passes);
  return std::make_unique<SparseGridTerrain<double>>(layout, z0, scene.grid.neighbours, scene.erosion.idle_passes);
}

}  // namespace sb::grid
