// Erosion (the paper's step 2a-2e): the common rule (sb::erosion_transfers) over the TIN's
// edges with barycentric vertex areas, so every transfer conserves volume exactly. Vertices
// that exchange sand first get edges no longer than refine_m_ (long edges are split at their
// middle): a pile poured on a coarse TIN can only spread if the mesh refines where the sand
// goes, and sand on a vertex with far-reaching triangles would be spread thinly over them.
#include <algorithm>
#include <cmath>

#include "common/geometry.hpp"
#include "common/input_error.hpp"
#include "tin/detail/tin_impl.hpp"

namespace sb::tin::detail {

namespace {

// refine_around leaves an edge whole when a vertex facing it lies within this fraction of
// refine_m_ from its middle: such pairs arise where long edges run from one vertex to two close
// ones (the contours O and I, a contour gap apart), whose middles are half as close again.
// Measured against leaving them (with the passed contours thinned, stamp.cpp): pile.toml RMSE
// 164 -> 91 um, flank 3.2 -> 1.0 degrees below critical, settling 127k -> 41k visits; trench
// walls at 7 azimuths within 0.62 degrees of critical on average (worst 0.82) against 0.57
// (0.87); a tool deeper than the bed settles in 264k visits instead of 326k. A fraction of the
// edge's length instead of refine_m_ would also leave the long edges of a coarse TIN whole, and
// sand would spread over their far-reaching triangles.
constexpr double kCrowdedSplit = 0.2;

// split_edge leaves an edge whole when its middle lies within this fraction of its length of a
// constrained edge, or of the domain's border, on the faces beside it (an angle of about 1 degree).
constexpr double kBesideConstraint = 0.02;

}  // namespace

double TinTerrain::gather_neighbours(VertexHandle v) {
  const Point& p = v->point();
  // The hottest loop of a step: the ring comes from the cache (its walk is repeated only when
  // v's star changed), heights and areas are read fresh.
  // The scratch vectors only grow (a resize per visit costs more than the visit's arithmetic):
  // ring_n_ of their entries are v's.
  const std::span<const VertexHandle> ring = ring_of(v);
  ring_n_ = ring.size();
  // (vertex_scratch_ apart: the stamp collects vertices in it.)
  if (vertex_scratch_.size() < ring_n_) vertex_scratch_.resize(ring_n_);
  if (nbr_scratch_.size() < ring_n_) {
    nbr_scratch_.resize(ring_n_);
    transfer_scratch_.resize(ring_n_);
  }
  std::copy(ring.begin(), ring.end(), vertex_scratch_.begin());
  for (std::size_t k = 0; k < ring.size(); ++k) {
    const Point& q = ring[k]->point();
    const double ex = q.x() - p.x(), ey = q.y() - p.y();
    nbr_scratch_[k] = {q.z(), std::sqrt(ex * ex + ey * ey), cached_area(ring[k]), ex, ey};
  }
  return cached_area(v);
}

bool TinTerrain::beside_a_constraint(VertexHandle a, VertexHandle b, const Vec2& m) const {
  FaceHandle f;
  int i = 0;
  if (!cdt_.is_edge(a, b, f, i)) return false;
  const double reach = kBesideConstraint * (xy(a) - xy(b)).norm();
  const FaceHandle faces[2] = {f, f->neighbor(i)};
  const int skip[2] = {i, cdt_.mirror_index(f, i)};
  for (int s = 0; s < 2; ++s) {
    if (cdt_.is_infinite(faces[s])) continue;
    for (int j = 0; j < 3; ++j) {
      // The domain's border (an edge next to the infinite face) holds like a constraint.
      if (j == skip[s] || !(faces[s]->is_constrained(j) || cdt_.is_infinite(faces[s]->neighbor(j)))) continue;
      const Vec2 p = xy(faces[s]->vertex(cdt_.cw(j))), q = xy(faces[s]->vertex(cdt_.ccw(j)));
      if (distance_to_segment(m, p, q) < reach) return true;
    }
  }
  return false;
}

VertexHandle TinTerrain::split_edge(VertexHandle a, VertexHandle b, bool* inserted) {
  Vec2 m = 0.5 * (xy(a) + xy(b));
  // An edge lying almost along a constrained edge of its own faces (a vertex a hair beside a
  // stamp's contour) stays whole: its middle would sit beside the constraint too, the apex of a
  // sliver the constraint keeps, and the next split beside it another (trench_azimuth.toml with
  // curvature refinement: chains of slivers whose vertices of near-zero area throttled erosion
  // until it never settled, facets at 89.9 degrees). The border too: edges running almost along it
  // were split into chains of slivers against it (long-sided tools swept across it,
  // tests/stress/tin_stress_test.cpp: unsettled after 40000 passes, facets at 54 degrees).
  if (beside_a_constraint(a, b, m)) {
    *inserted = false;
    return a;
  }
  // A middle a hair from the domain's border (closer than kBesideConstraint of the edge's length,
  // as beside a constraint) goes onto it. Edges at a shallow angle to the border (a narrow
  // domain's first diagonal: 1.9 degrees on a 0.3 x 0.01 m strip), halved again and again, put
  // vertices microns from it, the apices of slivers along it whose near-zero areas throttled every
  // transfer: a pile poured on that strip never settled (facets at 88 degrees after 20000
  // passes, 127 M updates) where the grid settles at once. (Snapping every middle within a crowded
  // split of the border instead unsettled other narrow domains, whose interiors it kept coarse.)
  const double near = std::min(kCrowdedSplit * refine_m_, kBesideConstraint * (xy(a) - xy(b)).norm());
  for (int axis = 0; axis < 2; ++axis) {
    if (m[axis] - box_.lo[axis] < near) m[axis] = box_.lo[axis];
    if (box_.hi[axis] - m[axis] < near) m[axis] = box_.hi[axis];
  }
  return insert_on_surface(m, inserted);
}

VertexHandle TinTerrain::insert_on_surface(const Vec2& p, bool* inserted) {
  double change = 0.0;
  const VertexHandle v = insert_point(p, surface_height(p), inserted, &change);
  if (!*inserted) return v;
  // The insertion itself keeps the surface; the Delaunay flips after it may not: their volume
  // change (measured over the faces the insertion replaced) is given back to the new vertex
  // (tin.conserve_volume, the default).
  volume_change_ += change;
  if (spec_.conserve_volume && change != 0.0) {
    const double area = vertex_area(v);
    if (area > 0.0) shift_z(v, v->point().z() - change / area, area);
  }
  touch_with_neighbours(v);
  return v;
}

bool TinTerrain::middle_on_edge(VertexHandle v, VertexHandle w) const {
  const Vec2 m = 0.5 * (xy(v) + xy(w));
  return cdt_.geom_traits().orientation_2_object()(v->point(), w->point(), Point(m.x(), m.y(), 0.0)) == CGAL::COLLINEAR;
}

std::size_t TinTerrain::split_long_edges(VertexHandle v) {
  std::size_t splits = 0;
  const double crowded2 = kCrowdedSplit * kCrowdedSplit * refine_m_ * refine_m_;
  for (int guard = 0; guard < 64 && has_long_edges(v); ++guard) {
    // The longest edge that can be split: a constrained edge only where its middle is
    // exactly on it (else the new vertex would sit beside the constraint, in a sliver).
    VertexHandle far;
    double longest = refine_m_;
    auto c = cdt_.incident_vertices(v), done = c;
    do {
      if (cdt_.is_infinite(c)) continue;
      const double d = (xy(c) - xy(v)).norm();
      if (d <= longest) continue;
      FaceHandle f;
      int i = 0;
      if (!cdt_.is_edge(v, c, f, i)) continue;
      const Vec2 middle = 0.5 * (xy(c) + xy(v));
      if (f->is_constrained(i) && !middle_on_edge(v, c)) continue;
      // Nor where a vertex facing the edge lies within kCrowdedSplit refine_m_ of its
      // middle: that vertex already resolves the edge, and the new one would be its close
      // neighbour, two small areas that throttle every transfer through them.
      const VertexHandle facing[2] = {f->vertex(i), f->neighbor(i)->vertex(cdt_.mirror_index(f, i))};
      bool crowded = false;
      for (VertexHandle o : facing)
        crowded = crowded || (!cdt_.is_infinite(o) && (xy(o) - middle).squaredNorm() < crowded2);
      if (crowded) continue;
      longest = d;
      far = c;
    } while (++c != done);
    if (far == VertexHandle()) break;
    bool inserted = false;
    split_edge(v, far, &inserted);
    if (!inserted) break;
    ++splits;
  }
  return splits;
}

bool TinTerrain::refine_crease(VertexHandle v) {
  // Only edges that sand crosses now (transfer_scratch_ > 0): measured on pile.toml, also
  // splitting creases nothing flows across adds vertices without making the pile rounder.
  // Facet k is (v, ring[k], ring[k + 1]) (the ring is counter-clockwise); edge (v, ring[k])
  // lies between facets k - 1 and k. A pair spanning 180 degrees or more (a border vertex's
  // gap) forms no facet, and its edges are not creases.
  const std::size_t n = ring_n_;
  if (n < 3) return false;
  const double z = v->point().z();
  const auto facet_gradient = [&](std::size_t k, Vec2& g) {
    double gx = 0.0, gy = 0.0, cross = 0.0;
    if (!facet_moment(z, nbr_scratch_[k], nbr_scratch_[(k + 1) % n], gx, gy, cross)) return false;
    g = Vec2(gx / cross, gy / cross);
    return true;
  };
  // Only the edges sand crosses, longer than the best so far, need their two facets.
  std::size_t best = n;
  double longest = fine_m_;
  for (std::size_t k = 0; k < n; ++k) {
    const double d = nbr_scratch_[k].distance;
    if (!(transfer_scratch_[k] > 0.0) || d <= longest) continue;
    Vec2 before(0.0, 0.0), after(0.0, 0.0);
    if (!facet_gradient((k + n - 1) % n, before) || !facet_gradient(k, after)) continue;
    if (0.25 * d * (after - before).norm() > curvature_tolerance_m_) {
      best = k;
      longest = d;
    }
  }
  if (best == n) return false;
  // A constrained edge only where its middle is exactly on it (as in refine_around).
  const VertexHandle w = vertex_scratch_[best];
  FaceHandle f;
  int i = 0;
  if (cdt_.is_edge(v, w, f, i) && f->is_constrained(i) && !middle_on_edge(v, w)) return false;
  bool inserted = false;
  split_edge(v, w, &inserted);
  return inserted;
}

ErosionReport TinTerrain::erode(const ErosionRule& given, const ErosionBudget& budget) {
  // Drops capped by the steepest facet, where the sand comes to rest (common/erosion.hpp).
  ErosionRule rule = given;
  rule.cap_drop = budget.settling;
  if (!std::isfinite(rule.tan_critical) || !std::isfinite(rule.tan_settle) || !std::isfinite(rule.fraction) ||
      rule.tan_critical < 0.0 || rule.fraction < 0.0)
    throw InputError("erosion: the rule's slopes and fraction must be finite and non-negative");
  ErosionReport report;
  volume_change_ = 0.0;
  std::vector<VertexHandle>& work = work_scratch_;
  // The gradient rule's input: the area-weighted facet gradients of v's star (gather_neighbours
  // lists the neighbours counter-clockwise, so consecutive ones span v's triangles).
  const auto gradient_at = [&](VertexHandle v) {
    return rule.needs_gradient() ? fan_gradient(v->point().z(), nbrs(), rule.cap_drop) : SurfaceGradient{};
  };
  // Curvature refinement (tin.curvature_tolerance_m), unless it waits for the sand to settle.
  const bool creases = fine_m_ < refine_m_ && (budget.settling || spec_.curvature_while_stamping);
  // No tool: the last stamp has passed too. Its O and I pairs, a contour gap apart, had areas
  // far below their neighbours' and throttled the settling's last passes (a 0.2 m spike on
  // flat_stroke.toml: 35,212 settling updates, 9,234 once released).
  if (budget.settling) release_passed_stamps();
  // Settling budgets: the cascade moves the sand far first (settle_region.cpp), the passes finish.
  settle_with_cascade(rule, budget, report);
  for (int pass = report.passes;
       pass < budget.max_passes && !erosion_list_.empty() && report.updates < budget.max_updates; ++pass) {
    ++report.passes;
    work.resize(erosion_list_.size());
    for (std::size_t k = 0; k < work.size(); ++k) work[k] = erosion_list_[k].vertex;
    for (VertexHandle v : work) {
      if (report.updates >= budget.max_updates) break;
      if (v->info().erosion_slot == kNoSlot) continue;
      ++report.updates;
      double area = gather_neighbours(v);
      double total =
          erosion_transfers(v->point().z(), area, gradient_at(v), nbrs(), rule, transfers(), NeighbourLayout::Fan);
      // Sand moving between vertices with long edges would spread over far-reaching
      // triangles: refine the stars of the giver and the receivers first, then recompute.
      for (int round = 0; round < 3 && total > 0.0; ++round) {
        std::size_t splits = refine_around(v);
        for (std::size_t k = 0; k < ring_n_; ++k)
          if (transfer_scratch_[k] > 0.0) splits += refine_around(vertex_scratch_[k]);
        if (splits == 0 && creases && refine_crease(v)) splits = 1;
        if (splits == 0) break;
        area = gather_neighbours(v);
        total =
            erosion_transfers(v->point().z(), area, gradient_at(v), nbrs(), rule, transfers(), NeighbourLayout::Fan);
      }
      // Settling criterion (slope excess): the rule moves nothing where every slope is below
      // tan_settle (erosion.settle_tolerance_deg above critical); a transfer removes a fixed
      // fraction of the excess, so each slope settles in O(log(excess / tolerance)) visits,
      // and with the mesh refined no finer than refine_m_ the work is bounded.
      if (total > 0.0 && area > 0.0) {
        shift_z(v, v->point().z() - total / area, area);
        // One ring: v fell, so its neighbours' drops towards v grew; a receiver rose, which
        // only its own drops grow (its neighbours' drops towards it shrank).
        // (vertex_scratch_ holds v's neighbours: no second circulation.)
        touch(v);
        for (std::size_t k = 0; k < ring_n_; ++k) touch(vertex_scratch_[k]);
        add_to_simplify(v);
        for (std::size_t k = 0; k < ring_n_; ++k) {
          if (transfer_scratch_[k] <= 0.0 || nbr_scratch_[k].area <= 0.0) continue;
          const VertexHandle w = vertex_scratch_[k];
          shift_z(w, w->point().z() + transfer_scratch_[k] / nbr_scratch_[k].area, nbr_scratch_[k].area);
          // The gradient rule reads w's height in its neighbours' fan gradients too.
          if (rule.needs_gradient())
            touch_with_neighbours(w);
          else
            touch(w);
          add_to_simplify(w);
          ++report.transfers;
        }
        report.volume_moved_m3 += total;
      } else if (++v->info().idle >= idle_passes_) {
        drop_from_erosion(v);  // (coarsening scans every vertex once the terrain is at rest)
      }
    }
  }
  // A settling region leaves L_e, and its rings become garbage: give the memory back (all of
  // it, with L_e's, once everything has settled).
  if (erosion_list_.empty()) {
    std::vector<ErosionEntry>().swap(erosion_list_);
    std::vector<VertexHandle>().swap(work);  // (a copy of L_e as it was at its largest)
    std::vector<VertexHandle>().swap(ring_pool_);
    ring_pool_live_ = 0;
  } else if (ring_pool_.capacity() > 256 && 4 * ring_pool_live_ < ring_pool_.capacity()) {
    compact_ring_pool(2 * ring_pool_live_);
  }
  report.active = erosion_list_.size();
  report.volume_change_m3 = volume_change_;
  return report;
}

}  // namespace sb::tin::detail
