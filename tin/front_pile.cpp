// Bulldozing on the TIN (common/front_pile.hpp): a moving stamp's cut volume heaped ahead of the
// tool at the angle of repose. The mesh ahead of a tool is often coarse (a flat bed is a few large
// triangles, and a raised vertex there would spread the sand thinly over them): a lattice of
// refine_m_ is filled in over the pile's region first, then the deposit goes to the vertices in
// proportion to their depth under the pile.
#include "common/front_pile.hpp"

#include <algorithm>
#include <cmath>

#include "tin/detail/stamp_work.hpp"
#include "tin/detail/tin_impl.hpp"

namespace sb::tin::detail {

namespace {
// Lattice points per stamp at most: a pile far wider than refine_m_ (a large tool on a finely
// refined TIN) gets a coarser lattice rather than millions of vertices in one stamp.
constexpr double kMaxLatticePoints = 65536.0;
}  // namespace

void TinTerrain::fill_pile_lattice(const StampWork& w, double reach, double band, StampReport& report) {
  const ToolStamp& s = w.tool;
  const Aabb2 region = intersection(bounds(s.footprint).expanded(reach), box_);
  const Vec2 size = region.hi - region.lo;
  if (!(size.x() >= 0.0 && size.y() >= 0.0)) return;
  const double h = std::max(refine_m_, std::sqrt(size.x() * size.y() / kMaxLatticePoints));
  if (!(h > 0.0)) return;
  const PileDistance distance(s);
  // Clear of the border (slivers against it) and of the outer contour O (a gap outside the
  // footprint), by half a spacing; clear of other vertices by as much.
  const double clear = 0.5 * h;
  const Aabb2 inner{box_.lo + Vec2(clear, clear), box_.hi - Vec2(clear, clear)};
  const auto first = [&](int axis) { return static_cast<long>(std::ceil((region.lo[axis] - box_.lo[axis]) / h)); };
  const auto last = [&](int axis) { return static_cast<long>(std::floor((region.hi[axis] - box_.lo[axis]) / h)); };
  for (long j = first(1); j <= last(1); ++j) {
    for (long i = first(0); i <= last(0); ++i) {
      const Vec2 p = box_.lo + h * Vec2(static_cast<double>(i), static_cast<double>(j));
      if (!inner.contains(p) || !in_front_pile(s, p, band) || s.contains(p)) continue;
      if (distance_to_boundary(s.footprint, p) < w.gap + clear || distance(p) > reach) continue;
      const Location loc = locate(p);
      bool near = false;
      for (int k = 0; k < 3; ++k) {
        const VertexHandle v = loc.face->vertex(k);
        near = near || (!cdt_.is_infinite(v) && (xy(v) - p).norm() < clear);
      }
      if (near) continue;
      bool inserted = false;
      insert_on_surface(p, &inserted);
      if (inserted) ++report.vertices_inserted;
    }
  }
}

bool TinTerrain::deposit_front_pile(StampWork& w, double deposit, StampReport& report) {
  const ToolStamp& s = w.tool;
  const double tan = s.rim.tan_repose;
  double reach = std::max({front_pile_flat_reach(deposit, 2.0 * s.half_width_m, tan), s.rim.width_m, refine_m_});
  const PileDistance distance(s);
  const double band = slump_band(s, surface_height(bed_probe(s, refine_m_)));
  std::vector<VertexHandle> found, pile;
  std::vector<PileSample> samples;
  double level = 0.0;
  std::size_t sampled_before = 0;
  // Each round at least 1.5 times wider: 64 outgrow any domain; the bound guards non-finite input.
  for (int round = 0; round < 64; ++round) {
    fill_pile_lattice(w, reach, band, report);
    const Aabb2 window = bounds(s.footprint).expanded(reach);
    collect_vertices(intersection(window, box_), found);
    pile.clear();
    samples.clear();
    double lowest = HUGE_VAL;
    for (VertexHandle v : found) {
      const Vec2 p = xy(v);
      if (!in_front_pile(s, p, band) || w.in_footprint(p)) continue;
      const double d = distance(p);
      if (d > reach) continue;
      pile.push_back(v);
      samples.push_back({d, v->point().z(), cached_area(v)});
      lowest = std::min(lowest, samples.back().z_m);
    }
    if (samples.empty()) return false;
    level = front_pile_level(samples, deposit, tan);
    const double needed = front_pile_reach_needed(level, lowest, tan);
    // No vertex gained since the last round: the corridor runs off the domain (as on the grid).
    const bool off_domain = pile.size() == sampled_before;
    sampled_before = pile.size();
    if (needed <= reach || off_domain || !std::isfinite(needed)) break;
    reach = std::max(1.1 * needed, 1.5 * reach);
  }
  double weight_sum = 0.0;
  for (const PileSample& p : samples) weight_sum += front_pile_depth(p, level, tan) * p.area_m2;
  if (!(weight_sum > 0.0)) return false;
  if (s.carries()) carried_origin_ = carried_origin(s);
  for (std::size_t i = 0; i < pile.size(); ++i) {
    const double depth = front_pile_depth(samples[i], level, tan);
    if (!(depth > 0.0)) continue;
    const double a = samples[i].area_m2, z = pile[i]->point().z();
    if (s.carries()) carried_.emplace_back(xy(pile[i]), z);
    shift_z(pile[i], z + deposit * (depth / weight_sum), a);
    w.changed.push_back(pile[i]);
  }
  return true;
}

double TinTerrain::pick_up_carried(StampWork& w, const CarriedPileOrigin& origin,
                                   const std::vector<std::pair<Vec2, double>>& base) {
  const double keep = carried_fraction(w.tool, origin);
  if (!(keep > 0.0)) return 0.0;
  double taken = 0.0;
  for (const auto& [p, z_base] : base) {
    if (w.in_footprint(p)) continue;  // cut whole by this stamp
    const Location loc = locate(p);
    if (loc.type != Cdt::VERTEX) continue;  // removed by a retriangulation since
    const VertexHandle v = loc.face->vertex(loc.index);
    const double z = v->point().z(), dz = keep * (z - z_base);
    if (!(dz > 0.0)) continue;
    const double before = volume_change_;
    shift_z(v, z - dz, cached_area(v));
    taken -= volume_change_ - before;  // the measured change, as shift_z booked it
    w.picked_up.push_back(p);          // a position: the stamp's retriangulation may remove v next
  }
  return taken;
}

}  // namespace sb::tin::detail
