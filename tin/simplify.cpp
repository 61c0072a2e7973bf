// Simplification (the paper's step 3): a vertex of L_r is redundant when every edge to a
// neighbour makes an angle with the horizontal plane below alpha_flat; border and constrained
// vertices stay. Redundant vertices are removed by CGAL (Devillers' removal: the star is
// retriangulated as a constrained Delaunay polygon).
#include <cmath>

#include "common/input_error.hpp"
#include "common/metrics.hpp"
#include "tin/detail/tin_impl.hpp"

namespace sb::tin::detail {

namespace {

bool is_flat(const Cdt& cdt, VertexHandle v, double tan_alpha) {
  if (v->info().border || cdt.are_there_incident_constraints(v)) return false;
  const Point& p = v->point();
  auto c = cdt.incident_vertices(v), done = c;
  do {
    if (cdt.is_infinite(c)) return false;
    const Point& q = c->point();
    const double d = std::hypot(q.x() - p.x(), q.y() - p.y());
    if (!(std::abs(q.z() - p.z()) < tan_alpha * d)) return false;
  } while (++c != done);
  return true;
}

}  // namespace

SimplifyReport TinTerrain::simplify(const SimplifyParams& params) {
  if (!std::isfinite(params.alpha_flat_deg) || params.alpha_flat_deg < 0.0 || params.alpha_flat_deg >= 90.0)
    throw InputError("simplify: alpha_flat_deg = " + std::to_string(params.alpha_flat_deg) + " must be in [0, 90)");
  SimplifyReport report;
  const double tan_alpha = std::tan(deg_to_rad(params.alpha_flat_deg));
  const double extent = std::max(domain_.size_m.x(), domain_.size_m.y());

  Stopwatch watch;
  report.candidates = simplify_list_.size();
  std::vector<VertexHandle> redundant;
  for (VertexHandle v : simplify_list_) {
    v->info().simplify_slot = kNoSlot;
    if (is_flat(cdt_, v, tan_alpha)) redundant.push_back(v);
  }
  simplify_list_.clear();
  report.detect_s = watch.seconds();

  watch.restart();
  std::vector<VertexHandle> link;
  for (VertexHandle v : redundant) {
    // An earlier removal changed v's neighbours: check again (O(degree)).
    if (!is_flat(cdt_, v, tan_alpha)) continue;
    link.clear();
    auto c = cdt_.incident_vertices(v), done = c;
    do {
      link.push_back(c);
    } while (++c != done);
    const Vec2 p = xy(v);
    if (spec_.conserve_volume) {
      // Removing a vertex that is not exactly planar with its star changes the volume:
      // measured over the hole and spread back over the hole's vertices by area.
      Capture capture = begin_capture(Aabb2{p, p}.expanded(4.0 * spec_.snap_m + 1e-9 * extent));
      remove_vertex(v);
      const CaptureResult measured = end_capture(capture);
      double link_area = 0.0;
      for (VertexHandle w : link) link_area += vertex_area(w);
      if (measured.delta() != 0.0 && link_area > 0.0) {
        const double dz = -measured.delta() / link_area;
        for (VertexHandle w : link) set_z(w, w->point().z() + dz);
      }
    } else {
      remove_vertex(v);
    }
    ++report.removed;
    // The hole's vertices have new neighbours: they may now be unstable, or flat in turn.
    for (VertexHandle w : link) {
      touch(w);
      add_to_simplify(w);
    }
  }
  report.remove_s = watch.seconds();
  return report;
}

}  // namespace sb::tin::detail
