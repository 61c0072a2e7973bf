// Simplification (the paper's step 3, generalised). A vertex of L_r is redundant when
//  - flat (the paper): every edge to a neighbour makes an angle with the horizontal plane
//    below alpha_flat; or
//  - planar (tin.coarsen, settled vertices only): the vertex and all its neighbours lie within
//    tin.planar_tolerance_m of the least-squares plane of the neighbours, so any
//    retriangulation of the hole stays within twice that of the surface it replaces, and no
//    edge the retriangulation may create is steeper than the critical angle (so coarsening
//    never sets sand moving, and erosion never refines again what was just coarsened).
// Border and constrained vertices stay. Redundant vertices are removed by CGAL (Devillers'
// removal: the star is retriangulated as a constrained Delaunay polygon); the volume change of
// the retriangulation is measured over the hole and given back to the hole's vertices where it
// happened, each taking the removed height over the area it took over (merge_removed_column;
// tin.conserve_volume, the default), so removal conserves volume and keeps the sand in place.
// Vertices whose ring is still in L_e rejoin L_r when it settles.
#include <algorithm>
#include <cmath>

#include "common/input_error.hpp"
#include "common/metrics.hpp"
#include "tin/detail/tin_impl.hpp"

namespace sb::tin::detail {

namespace {

bool is_removable(const Cdt& cdt, VertexHandle v) {
  return !v->info().border && !cdt.are_there_incident_constraints(v);
}

// v and its neighbours have left L_e: no sand flows here, so erosion will not refine the
// region again right after the removal (which would make the two churn).
bool is_settled(const Cdt& cdt, VertexHandle v) {
  if (v->info().erosion_slot != kNoSlot) return false;
  auto c = cdt.incident_vertices(v), done = c;
  do {
    if (!cdt.is_infinite(c) && c->info().erosion_slot != kNoSlot) return false;
  } while (++c != done);
  return true;
}

bool is_flat(const Cdt& cdt, VertexHandle v, double tan_alpha) {
  const Point& p = v->point();
  auto c = cdt.incident_vertices(v), done = c;
  do {
    if (cdt.is_infinite(c)) return false;
    const Point& q = c->point();
    // (The square root of the squared sum, not std::hypot, whose guard against overflow is
    // useless at these scales and cost 11 % of a rest scan over 10^6 vertices; also below.)
    const double dx = q.x() - p.x(), dy = q.y() - p.y();
    const double d = std::sqrt(dx * dx + dy * dy);
    if (!(std::abs(q.z() - p.z()) < tan_alpha * d)) return false;
  } while (++c != done);
  return true;
}

// Least-squares plane z = a + b x + c y of v's neighbours (coordinates relative to v), then
// whether its gradient is at most max_gradient and v and every neighbour lie within `tol` of
// it. O(degree), no allocation.
bool is_planar(const Cdt& cdt, VertexHandle v, double tol, double max_gradient) {
  const Point& p = v->point();
  double n = 0, sx = 0, sy = 0, sz = 0, sxx = 0, sxy = 0, syy = 0, sxz = 0, syz = 0;
  auto c = cdt.incident_vertices(v), done = c;
  do {
    if (cdt.is_infinite(c)) return false;
    const double x = c->point().x() - p.x(), y = c->point().y() - p.y(), z = c->point().z() - p.z();
    n += 1;
    sx += x, sy += y, sz += z, sxx += x * x, sxy += x * y, syy += y * y, sxz += x * z, syz += y * z;
  } while (++c != done);
  // Centred normal equations for the slopes, then the intercept.
  const double mx = sx / n, my = sy / n, mz = sz / n;
  const double cxx = sxx - n * mx * mx, cxy = sxy - n * mx * my, cyy = syy - n * my * my;
  const double cxz = sxz - n * mx * mz, cyz = syz - n * my * mz;
  const double det = cxx * cyy - cxy * cxy;
  if (!(det > 1e-12 * (cxx * cyy)) || !(det > 0.0)) return false;
  const double b = (cxz * cyy - cyz * cxy) / det, g = (cyz * cxx - cxz * cxy) / det;
  if (!(std::sqrt(b * b + g * g) <= max_gradient)) return false;
  const double a = mz - b * mx - g * my;
  if (!(std::abs(a) <= tol)) return false;  // v itself (at the origin, z = 0)
  c = done;
  do {
    const double x = c->point().x() - p.x(), y = c->point().y() - p.y(), z = c->point().z() - p.z();
    if (!(std::abs(z - (a + b * x + g * y)) <= tol)) return false;
  } while (++c != done);
  return true;
}

// Whether every edge the removal could create (between two of v's neighbours) is stable:
// no pair of neighbours lies more than `slack` beyond the critical slope apart. Coarsening
// then never sets sand moving, so erosion does not refine again what was just coarsened.
// O(degree^2), degree about 6.
bool removal_keeps_stable(const Cdt& cdt, VertexHandle v, double tan_critical, double slack) {
  auto a = cdt.incident_vertices(v), done = a;
  do {
    auto b = a;
    for (++b; b != done; ++b) {
      const Point &p = a->point(), &q = b->point();
      const double dx = q.x() - p.x(), dy = q.y() - p.y();
      const double d = std::sqrt(dx * dx + dy * dy);
      if (std::abs(q.z() - p.z()) - d * tan_critical >= slack) return false;
    }
  } while (++a != done);
  return true;
}

}  // namespace

bool TinTerrain::has_steep_triangle(const std::vector<VertexHandle>& link, bool hole_only) const {
  auto in_link = [&link](VertexHandle w) { return std::find(link.begin(), link.end(), w) != link.end(); };
  for (VertexHandle w : link) {
    auto f = cdt_.incident_faces(w), done = f;
    do {
      if (cdt_.is_infinite(f)) continue;
      if (hole_only && (!in_link(f->vertex(0)) || !in_link(f->vertex(1)) || !in_link(f->vertex(2)))) continue;
      const Point &a = f->vertex(0)->point(), &b = f->vertex(1)->point(), &c = f->vertex(2)->point();
      const double ux = b.x() - a.x(), uy = b.y() - a.y(), uz = b.z() - a.z();
      const double vx = c.x() - a.x(), vy = c.y() - a.y(), vz = c.z() - a.z();
      const double nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
      if (std::sqrt(nx * nx + ny * ny) > tan_settle_ * std::abs(nz)) return true;
    } while (++f != done);
  }
  return false;
}

SimplifyReport TinTerrain::simplify(const SimplifyParams& params) {
  if (!std::isfinite(params.alpha_flat_deg) || params.alpha_flat_deg < 0.0 || params.alpha_flat_deg >= 90.0)
    throw InputError("simplify: alpha_flat_deg = " + std::to_string(params.alpha_flat_deg) + " must be in [0, 90)");
  SimplifyReport report;
  volume_change_ = 0.0;
  const double tan_alpha = std::tan(deg_to_rad(params.alpha_flat_deg));
  // The paper's step 3 acts every step: flat vertices of L_r go. Coarsening (tin.coarsen, the
  // planar rule, and the flat rule over every vertex) acts only while the whole terrain is at
  // rest (L_e empty): a region that settled between two stamps is usually flowed over again by
  // the next one (a growing pile's flank and the bed around it, a trench's rim), and erosion
  // would refine it again right after (coarsening between a pile's pours costs more edge
  // splits and erosion updates than it saves). The first simplification at rest after any activity scans
  // every vertex once (O(n)); removals queue their links, cascading until nothing more is
  // redundant.
  const bool at_rest = erosion_list_.empty();
  const bool coarsen = spec_.coarsen && at_rest;
  if (!at_rest) rest_scan_pending_ = true;
  bool scan_all = coarsen && rest_scan_pending_;
  if (scan_all) rest_scan_pending_ = false;
  Stopwatch watch;
  do {
    simplify_round(tan_alpha, coarsen, scan_all, report);
    scan_all = false;
  } while (coarsen && !simplify_list_.empty());
  report.detect_s = watch.seconds() - report.remove_s;
  report.volume_change_m3 = volume_change_;
  return report;
}

void TinTerrain::merge_removed_column(const std::vector<VertexHandle>& link, const std::vector<double>& area_before,
                                      double z_removed, double measured_delta) {
  // The volume is sum_w z_w A_w exactly (A: a third of the star's area), and only the link's
  // areas changed: each neighbour w took over dA_w of the removed vertex's area, and takes the
  // removed height over it, z_w += dA_w (z_removed - z_w) / A_w', which gives back the measured
  // change up to rounding, where it happened. Spread evenly by area over the link instead, the
  // change went mostly to the neighbour with the largest star, a domain corner on a coarse mesh:
  // mass moved across the domain (pile.toml: the pile's centroid 0.8 mm off the pour point).
  double given = 0.0, largest_gain = 0.0;
  VertexHandle largest;
  for (std::size_t k = 0; k < link.size(); ++k) {
    const VertexHandle w = link[k];
    if (cdt_.is_infinite(w)) continue;
    const double area = cached_area(w), gain = area - area_before[k];
    if (!(area > 0.0)) continue;
    const double dz = gain * (z_removed - w->point().z()) / area;
    shift_z(w, w->point().z() + dz, area);
    given += dz * area;
    if (gain > largest_gain) largest_gain = gain, largest = w;
  }
  // Rounding: what is left goes to the neighbour that took most of the area.
  const double residual = measured_delta + given;
  if (residual != 0.0 && largest != VertexHandle())
    shift_z(largest, largest->point().z() - residual / cached_area(largest), cached_area(largest));
}

void TinTerrain::simplify_round(double tan_alpha, bool coarsen, bool scan_all, SimplifyReport& report) {
  const double extent = std::max(domain_.size_m.x(), domain_.size_m.y());
  const double planar_tol = spec_.planar_tolerance_m > 0.0 ? spec_.planar_tolerance_m : 0.25 * spec_.tolerance_m;
  // Planes steeper than this are left alone: a flank at the angle of repose would, once
  // coarsened, have triangles steeper than their (stable) edges.
  const double max_gradient = 0.8 * tan_critical_;
  auto redundant_now = [&](VertexHandle v) {
    if (!is_removable(cdt_, v)) return false;
    if (is_flat(cdt_, v, tan_alpha)) return true;
    return coarsen && is_settled(cdt_, v) && is_planar(cdt_, v, planar_tol, max_gradient) &&
           removal_keeps_stable(cdt_, v, tan_critical_, settle_dz_);
  };

  report.candidates += simplify_list_.size();
  std::vector<VertexHandle>& redundant = redundant_scratch_;
  redundant.clear();
  // A vertex that is not redundant now comes back to L_r when a stamp or erosion changes it,
  // and every vertex is examined at the next rest, so L_r need not carry it.
  for (VertexHandle v : simplify_list_) {
    v->info().simplify_slot = kNoSlot;
    if (!scan_all && redundant_now(v)) redundant.push_back(v);
  }
  simplify_list_.clear();
  if (scan_all) {
    report.candidates += cdt_.number_of_vertices();
    for (auto v = cdt_.finite_vertices_begin(); v != cdt_.finite_vertices_end(); ++v)
      if (redundant_now(v)) redundant.push_back(v);
  }

  Stopwatch watch;
  std::vector<VertexHandle>& link = link_hold_scratch_;
  std::vector<double>& link_z = link_z_scratch_;
  for (VertexHandle v : redundant) {
    // An earlier removal changed v's neighbours: check again (O(degree)).
    if (!redundant_now(v)) continue;
    link.clear();
    auto c = cdt_.incident_vertices(v), done = c;
    do {
      link.push_back(c);
    } while (++c != done);
    const Vec2 p = xy(v);
    // Removing a vertex that is not exactly planar with its star changes the volume:
    // measured over the hole and given back to the hole's vertices (merge_removed_column). The capture's
    // walk starts at v itself (one step; remove_vertex then hands the hint to a neighbour):
    // from wherever the last edit had left the hint, every removal of a rest scan walked across
    // the mesh, O(sqrt(n)) faces each (flat_stroke.toml on 10^6 initial points: ~450 steps a
    // removal, 12 of the run's 22 s).
    edit_walk_.hint = v;
    Capture capture = begin_capture(Aabb2{p, p}.expanded(4.0 * spec_.snap_m + 1e-9 * extent));
    const double z_before = v->point().z();
    std::vector<double>& link_area = link_area_scratch_;
    link_z.clear();
    link_area.clear();
    for (VertexHandle w : link) {
      link_z.push_back(w->point().z());
      link_area.push_back(cdt_.is_infinite(w) ? 0.0 : cached_area(w));
    }
    remove_vertex(v);
    if (!coarsen && has_steep_triangle(link, true)) {
      // The paper's step 3 (as before coarsening existed): a triangle of the hole steeper than
      // all its edges; put the vertex back (the same point gives back the same Delaunay
      // triangulation, so the surface is restored).
      insert_point(p, z_before);
      volume_change_ += end_capture(capture).delta();  // rounding, cocircular ties
      continue;
    }
    const CaptureResult measured = end_capture(capture);
    volume_change_ += measured.delta();
    if (spec_.conserve_volume && measured.delta() != 0.0)
      merge_removed_column(link, link_area, z_before, measured.delta());
    if (coarsen && has_steep_triangle(link, false)) {
      // Coarsening: a triangle of the hole, or one the give-back tilted around it, is steeper
      // than the stable slope (triangles can be steeper than all their edges; a short edge at
      // a rim is tilted by the give-back, which on a trench's rim leaves degrees of slope
      // excess). Undo: the old heights and the same point give back the same
      // Delaunay triangulation, so the surface is restored (up to cocircular ties and
      // rounding: what the removal and the reinsertion leave is measured and given back to v).
      for (std::size_t k = 0; k < link.size(); ++k) shift_z(link[k], link_z[k], cached_area(link[k]));
      Capture undo = begin_capture(Aabb2{p, p}.expanded(4.0 * spec_.snap_m + 1e-9 * extent));
      const VertexHandle back = insert_point(p, z_before);
      const double reinserted = end_capture(undo).delta();
      volume_change_ += reinserted;
      const double residual = measured.delta() + reinserted;
      const double back_area = vertex_area(back);
      if (spec_.conserve_volume && residual != 0.0 && back_area > 0.0)
        shift_z(back, back->point().z() - residual / back_area, back_area);
      continue;
    }
    ++report.removed;
    // The hole's vertices have new neighbours: they may be redundant in turn. Coarsening
    // leaves them at rest: every triangle at them is no steeper than tan_settle, so neither
    // their edges nor their fan gradients (area-weighted means of those triangles) make the
    // rule move sand. The paper's step 3 lets erosion visit them again.
    for (VertexHandle w : link) {
      if (!coarsen) touch(w);
      add_to_simplify(w);
    }
  }
  report.remove_s += watch.seconds();
}

}  // namespace sb::tin::detail
