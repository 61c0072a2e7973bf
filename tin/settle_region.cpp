// The TIN's side of the settling cascade (settle_cascade.hpp): the region around L_e handed
// over as arrays, the heights taken back, the vertices that changed re-activated.
#include <algorithm>
#include <unordered_map>

#include "tin/detail/tin_impl.hpp"
#include "tin/settle_cascade.hpp"

namespace sb::tin::detail {

void TinTerrain::settle_with_cascade(const ErosionRule& rule, const ErosionBudget& budget, ErosionReport& report) {
  const std::size_t active = erosion_list_.size();
  if (!cascade_pays(active, budget)) return;
  // Not with curvature refinement (tin.curvature_tolerance_m > 0): it is asked for accuracy, and
  // the clusters move sand the fine rule would have kept (pile.toml refined at rest, 0.2 mm:
  // RMSE 44.9 um without them, 47.4 with), while its crease splits need the fine passes anyway.
  if (fine_m_ < refine_m_) return;
  // The region: L_e's bounding box widened by a quarter of its larger side (at least two
  // refinement lengths), the vertices in it without long edges.
  Aabb2 box{xy(erosion_list_[0].vertex), xy(erosion_list_[0].vertex)};
  for (const ErosionEntry& e : erosion_list_) box = united(box, Aabb2{xy(e.vertex), xy(e.vertex)});
  const Vec2 side = box.hi - box.lo;
  box = intersection(box.expanded(std::max(0.25 * std::max(side.x(), side.y()), 2.0 * refine_m_)), box_);
  std::vector<VertexHandle> vertices;
  // (collect_vertices queues the box's faces in face_scratch_: its growth is given back, the
  // stamps never need that much.)
  const std::size_t face_capacity = face_scratch_.capacity();
  collect_vertices(box, vertices);
  if (face_scratch_.capacity() > face_capacity) {
    std::vector<FaceHandle>().swap(face_scratch_);
    face_scratch_.reserve(face_capacity);
  }
  std::erase_if(vertices, [&](VertexHandle v) { return has_long_edges(v); });
  if (vertices.size() > static_cast<std::size_t>(budget.max_passes) * active) return;

  std::unordered_map<const void*, std::uint32_t> index;
  index.reserve(vertices.size());
  for (std::size_t i = 0; i < vertices.size(); ++i) index.emplace(&*vertices[i], static_cast<std::uint32_t>(i));
  CascadeRegion region;
  const std::size_t n = vertices.size();
  region.x.resize(n);
  region.y.resize(n);
  region.area.resize(n);
  region.z.resize(n);
  region.active.resize(n);
  region.edges.reserve(6 * n);
  region.ring_begin.assign(n + 1, 0);
  region.ring.reserve(7 * n);
  for (std::size_t i = 0; i < n; ++i) {
    const VertexHandle v = vertices[i];
    region.x[i] = v->point().x();
    region.y[i] = v->point().y();
    region.z[i] = v->point().z();
    region.area[i] = cached_area(v);
    region.active[i] = v->info().erosion_slot != kNoSlot;
    const std::size_t ring_start = region.ring.size();
    bool whole = true;
    auto c = cdt_.incident_vertices(v), done = c;
    do {
      if (cdt_.is_infinite(c)) continue;
      const auto it = index.find(&*c);
      if (it == index.end()) {
        whole = false;
        continue;
      }
      region.ring.push_back(it->second);
      if (it->second <= i) continue;
      region.edges.push_back(static_cast<std::uint32_t>(i));
      region.edges.push_back(it->second);
    } while (++c != done);
    if (!whole) region.ring.resize(ring_start);
    region.ring_begin[i + 1] = static_cast<std::uint32_t>(region.ring.size());
  }
  CascadeOptions options;
  options.fine_level = true;
  options.cell_m = refine_m_;
  // erosion.cascade = false: no clusters; the fine level is the fine rule itself (over arrays).
  if (!budget.cascade) options.max_levels = 0;
  const CascadeReport cr = settle_cascade(region, rule, options);
  if (cr.levels.empty() && cr.fine.updates == 0) return;
  ++report.passes;
  report.updates += cr.updates;
  report.transfers += cr.transfers;
  report.volume_moved_m3 += cr.moved_m3;
  for (std::size_t i = 0; i < n; ++i) {
    const VertexHandle v = vertices[i];
    if (region.z[i] == v->point().z()) continue;
    shift_z(v, region.z[i], region.area[i]);
    touch_with_neighbours(v);
    add_to_simplify(v);
  }
}

}  // namespace sb::tin::detail
