#pragma once
// GridTerrainBase<Heights, Active>: what the dense and the sparse grid terrain share -- the
// model of a regular height grid (GridTerrain, grid_terrain.hpp) written once over its
// storage: Heights is HeightGrid<Real> or SparseHeights<Real>, Active the active set that
// goes with it (ActiveSet or SparseActiveSet). It holds the heights, the neighbour stencil,
// the active set and the erosion tables, and implements every Terrain operation whose code
// does not depend on the storage: stamp (the stamp kernel, then the changed nodes and their
// neighbours join the active set), erode (the erosion kernel with the settling cascade),
// simplify (nothing to do), volume, stats, mesh (and its row-by-row stream), sample, max_slope_deg.
// The final classes add their name, check() and what their storage needs besides (the sparse
// grid prunes uniform blocks after settling).
//
// Costs: those stated in grid_terrain.hpp (dense) and sparse_terrain.hpp (sparse).
// The member functions are defined here but instantiated only in grid_terrain.cpp and
// sparse_terrain.cpp (extern template declarations next to each final class).
#include <algorithm>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "common/height_field.hpp"
#include "common/scene.hpp"
#include "common/terrain.hpp"
#include "grid/erosion_kernel.hpp"
#include "grid/grid_layout.hpp"
#include "grid/grid_stamp.hpp"
#include "grid/grid_surface.hpp"
#include "grid/multires_settle.hpp"
#include "grid/stencil.hpp"

namespace sb::grid {

template <class Heights, class Active>
class GridTerrainBase : public Terrain {
 public:
  double height(const Vec2& p) const override { return heights_.height(p); }
  StampReport stamp(const ToolStamp& s) override;
  ErosionReport erode(const ErosionRule& rule, const ErosionBudget& budget) override;
  // Nothing to simplify on a grid: the volume does not change.
  SimplifyReport simplify(const SimplifyParams&) override { return {.volume_change_m3 = 0.0}; }
  double volume() const override { return heights_.volume(); }
  ModelStats stats() const override;
  SurfaceMesh mesh() const override { return grid_mesh(heights_); }
  void stream_mesh(MeshSink& sink) const override { grid_stream_mesh(heights_, sink); }  // O(nx) memory
  void sample(Raster& out) const override { grid_sample(heights_, out); }
  double max_slope_deg() const override { return grid_max_slope_deg(heights_, stencil_); }
  std::optional<HeightLattice> lattice() const override;
  // The 64 x 64 node tiles the active set marked (change_tiles.hpp). O(tiles).
  SurfaceChanges changes_since(std::uint64_t version) override;
  void lattice_heights(const NodeRect& r, double z_ref, float* out, std::size_t stride) const override;

  // For tests and benchmarks: every node a member of the active set, or node (ix, iy) and its
  // 3 x 3 block (as a stamp activates the nodes it changed); which sweep erosion runs
  // (default Auto: the dense pass when the members fill an eighth of their row spans).
  void activate_all() { active_.activate_all(); }
  void activate_block(std::size_t ix, std::size_t iy) { active_.activate_block(ix, iy); }
  void set_sweep_path(SweepPath path) { sweep_path_ = path; }
  // Threads a large dense pass may run on (1 or 2; dense_pass in erosion_kernel.hpp): a
  // matter of time only, the heights are the same bit for bit.
  void set_threads(unsigned threads) { threads_ = threads; }
  unsigned threads() const { return threads_; }
  // Whether large settling budgets start with the multi-resolution cascade (default on;
  // multires_settle.hpp).
  void set_multires(bool on) { multires_ = on; }
  const GridLayout& layout() const { return heights_.layout(); }
  const Heights& heights() const { return heights_; }
  const Active& active_set() const { return active_; }
  const Stencil& stencil() const { return stencil_; }
  // The pile the last stamp heaped, if it carries it on (tool.displacement = "carry").
  const CarriedNodes& carried_pile() const { return carried_; }

 protected:
  // neighbours: 4 or 8; idle_passes: idle visits before a node leaves the active set.
  GridTerrainBase(const GridLayout& layout, const std::function<double(const Vec2&)>& initial, int neighbours,
                  int idle_passes)
      : heights_(layout, initial),
        stencil_(Stencil::make(layout, neighbours)),
        active_(layout.nx, layout.ny, idle_passes) {}

  Heights heights_;
  Stencil stencil_;
  Active active_;

 private:
  SweepPath sweep_path_ = SweepPath::Auto;
  unsigned threads_ = 1;
  bool multires_ = true;
  std::optional<ErosionTables> tables_;  // built on the first erode, rebuilt when the rule changes
  CarriedNodes carried_;                 // the pile a carrying stamp left for the next
};

template <class Heights, class Active>
StampReport GridTerrainBase<Heights, Active>::stamp(const ToolStamp& s) {
  std::vector<std::uint32_t> changed;
  const double carry_before = heights_.carry_m3();
  StampReport report = stamp_grid(heights_, s, changed, &carried_);
  // What the stored volume changed by: the stamp's own sums, less what rounding put into
  // the carry (zero in double).
  report.volume_change_m3 =
      report.volume_deposited_m3 - report.volume_removed_m3 - (heights_.carry_m3() - carry_before);
  const GridLayout& layout = heights_.layout();
  for (std::uint32_t k : changed) {
    const auto [ix, iy] = layout.split(k);
    active_.activate_block(ix, iy);
  }
  return report;
}

template <class Heights, class Active>
ErosionReport GridTerrainBase<Heights, Active>::erode(const ErosionRule& rule, const ErosionBudget& budget) {
  const bool gradient = rule.needs_gradient();
  if (!tables_ || !tables_->built_for(rule, gradient))
    tables_.emplace(heights_.layout(), stencil_.size, rule, gradient);
  const double carry_before = heights_.carry_m3();
  ErosionReport report = erode_settling(heights_, active_, *tables_, budget, sweep_path_, multires_, threads_);
  // Transfers conserve volume; only rounding into the carry changes the stored volume.
  report.volume_change_m3 = carry_before - heights_.carry_m3();
  return report;
}

template <class Heights, class Active>
std::optional<HeightLattice> GridTerrainBase<Heights, Active>::lattice() const {
  const GridLayout& l = heights_.layout();
  return HeightLattice{l.origin, l.dx, l.dy, l.nx, l.ny};
}

template <class Heights, class Active>
SurfaceChanges GridTerrainBase<Heights, Active>::changes_since(std::uint64_t version) {
  std::vector<std::uint32_t> tiles;
  ChangeTiles& changes = active_.changes();
  SurfaceChanges c{.version = changes.since(version, tiles), .tracked = true, .rects = {}};
  const GridLayout& l = heights_.layout();
  constexpr std::size_t side = ChangeTiles::kSide;
  c.rects.reserve(tiles.size());
  for (const std::uint32_t t : tiles) {
    const std::size_t x0 = (t % changes.cols()) * side, y0 = (t / changes.cols()) * side;
    c.rects.push_back({x0, y0, std::min(l.nx, x0 + side), std::min(l.ny, y0 + side)});
  }
  return c;
}

template <class Heights, class Active>
void GridTerrainBase<Heights, Active>::lattice_heights(const NodeRect& r, double z_ref, float* out,
                                                       std::size_t stride) const {
  for (std::size_t y = r.y0; y < r.y1; ++y)
    for (std::size_t x = r.x0; x < r.x1; ++x)
      out[(y - r.y0) * stride + (x - r.x0)] = static_cast<float>(heights_.z(x, y) - z_ref);
}

template <class Heights, class Active>
ModelStats GridTerrainBase<Heights, Active>::stats() const {
  ModelStats st;
  st.cells = heights_.layout().nodes();
  st.bytes = heights_.bytes() + active_.bytes() + (tables_ ? tables_->bytes() : 0) +
             carried_.base.capacity() * sizeof(carried_.base[0]);
  st.active = active_.size();
  return st;
}

// The grid terrain Model<float> or Model<double>, as the scene's [grid] storage says, on
// the layout of its [grid] cell size with its neighbours and [erosion] idle passes: the
// factory both grids share (make_grid_terrain, make_sparse_terrain).
template <template <class> class Model>
std::unique_ptr<Terrain> make_grid_model(const Scene& scene, const HeightField& initial) {
  const GridLayout layout = GridLayout::covering(scene.domain.box(), scene.grid.cell_m);
  const auto z0 = [&initial](const Vec2& p) { return initial(p); };
  const auto made = [&scene](auto model) -> std::unique_ptr<Terrain> {
    model->set_threads(static_cast<unsigned>(scene.grid.threads));
    return model;
  };
  if (scene.grid.storage == GridStorage::Float)
    return made(std::make_unique<Model<float>>(layout, z0, scene.grid.neighbours, scene.erosion.idle_passes));
  return made(std::make_unique<Model<double>>(layout, z0, scene.grid.neighbours, scene.erosion.idle_passes));
}

}  // namespace sb::grid
