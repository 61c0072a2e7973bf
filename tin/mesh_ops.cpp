// The TIN's primitive operations: point location by walking, interpolation, insertion with
// snapping, vertex removal, constraints with their generation records, the erosion and
// simplification lists, and region captures for measuring retriangulation volume changes.
#include <algorithm>
#include <cmath>

#include "common/input_error.hpp"
#include "tin/detail/tin_impl.hpp"

namespace sb::tin::detail {

FaceHandle TinTerrain::start_face(const Walk& walk) const {
  FaceHandle f = walk.hint != VertexHandle() ? walk.hint->face() : FaceHandle(cdt_.finite_faces_begin());
  if (cdt_.is_infinite(f)) f = f->neighbor(f->index(cdt_.infinite_vertex()));
  return f;
}

// A remembering stochastic visibility walk (Devillers, Pion, Teillaud 2002) from the hint:
// cross an edge that separates the face from p, trying the edges in a random order and never
// straight back. O(1) steps when the hint is near p, which is how the model is queried.
Location TinTerrain::locate(const Vec2& p, Walk& walk) const {
  const Point q(p.x(), p.y(), 0.0);
  const auto orient = cdt_.geom_traits().orientation_2_object();
  FaceHandle f = start_face(walk);
  FaceHandle came_from;
  // A walk can only cycle in a non-Delaunay triangulation, and the random order breaks such
  // cycles with probability 1; the cap is a guard, never expected to be reached. The data
  // structure's own face count (infinite faces included) is O(1); the triangulation's
  // number_of_faces() circulates the whole convex hull, O(sqrt(n)) on a TIN with border points.
  const std::uint64_t cap = 64 + 4 * static_cast<std::uint64_t>(cdt_.tds().number_of_faces());
  std::uint64_t steps = 0;
  bool walked_out = false;
  for (;;) {
    ++steps;
    walk.rng = walk.rng * 1664525u + 1013904223u;
    const int first = static_cast<int>((walk.rng >> 16) % 3);
    FaceHandle next;
    for (int k = 0; k < 3; ++k) {
      const int i = (first + k) % 3;
      const FaceHandle n = f->neighbor(i);
      if (n == came_from) continue;
      if (orient(f->vertex(Cdt::ccw(i))->point(), f->vertex(Cdt::cw(i))->point(), q) == CGAL::RIGHT_TURN) {
        if (cdt_.is_infinite(n))
          walked_out = true;
        else
          next = n;
        break;
      }
    }
    if (next == FaceHandle() || steps > cap) break;
    came_from = f;
    f = next;
  }
  walk_steps_ += steps;

  Location loc;
  loc.face = f;
  int collinear[3];
  int n_collinear = 0;
  bool inside = !walked_out && steps <= cap;
  for (int i = 0; i < 3 && inside; ++i) {
    const auto o = orient(f->vertex(Cdt::ccw(i))->point(), f->vertex(Cdt::cw(i))->point(), q);
    if (o == CGAL::RIGHT_TURN) inside = false;
    if (o == CGAL::COLLINEAR) collinear[n_collinear++] = i;
  }
  if (!inside) {
    // Off the hull (callers clamp to the domain, so only by a guard) or a capped walk.
    int li = 0;
    Cdt::Locate_type lt;
    loc.face = cdt_.locate(q, lt, li, f);
    loc.type = lt;
    loc.index = li;
    if (lt == Cdt::OUTSIDE_CONVEX_HULL || lt == Cdt::OUTSIDE_AFFINE_HULL || cdt_.is_infinite(loc.face)) {
      FaceHandle g = loc.face;
      if (cdt_.is_infinite(g)) g = g->neighbor(g->index(cdt_.infinite_vertex()));
      loc.face = g;
      loc.type = Cdt::FACE;
      loc.index = 0;
    }
    return loc;
  }
  if (n_collinear == 0) {
    loc.type = Cdt::FACE;
  } else if (n_collinear == 1) {
    loc.type = Cdt::EDGE;
    loc.index = collinear[0];
  } else {
    loc.type = Cdt::VERTEX;
    loc.index = 3 - collinear[0] - collinear[1];
  }
  return loc;
}

double TinTerrain::interpolate(FaceHandle f, const Vec2& p) const {
  const Point &a = f->vertex(0)->point(), &b = f->vertex(1)->point(), &c = f->vertex(2)->point();
  const double bx = b.x() - a.x(), by = b.y() - a.y(), cx = c.x() - a.x(), cy = c.y() - a.y();
  const double px = p.x() - a.x(), py = p.y() - a.y();
  const double det = bx * cy - by * cx;
  if (!(std::abs(det) > 0.0)) return (a.z() + b.z() + c.z()) / 3.0;
  const double wb = (px * cy - py * cx) / det;
  const double wc = (bx * py - by * px) / det;
  return a.z() + wb * (b.z() - a.z()) + wc * (c.z() - a.z());
}

Vec2 TinTerrain::clamp_to_domain(const Vec2& p) const {
  return {std::clamp(p.x(), box_.lo.x(), box_.hi.x()), std::clamp(p.y(), box_.lo.y(), box_.hi.y())};
}

bool TinTerrain::on_border(const Vec2& p) const {
  return p.x() == box_.lo.x() || p.x() == box_.hi.x() || p.y() == box_.lo.y() || p.y() == box_.hi.y();
}

double TinTerrain::height(const Vec2& p) const { return height_by(p, query_walk_); }

double TinTerrain::height_by(const Vec2& p, Walk& walk) const {
  if (!std::isfinite(p.x()) || !std::isfinite(p.y())) throw InputError("tin: height query at a non-finite point");
  const Vec2 q = clamp_to_domain(p);
  const Location loc = locate(q, walk);
  walk.hint = loc.face->vertex(0);
  if (loc.type == Cdt::VERTEX) return loc.face->vertex(loc.index)->point().z();
  return interpolate(loc.face, q);
}

void TinTerrain::conflict_region(const Point& q, const Location& loc, double& volume, double& area, double& extent2) {
  volume = 0.0;
  area = 0.0;
  Aabb2 box{xy(q), xy(q)};
  const std::uint32_t in = next_face_epoch();
  const std::uint32_t out = next_face_epoch();
  face_scratch_.clear();
  const auto take = [&](FaceHandle f) {
    if (cdt_.is_infinite(f) || f->info() == in) return;
    f->info() = in;
    face_scratch_.push_back(f);
  };
  take(loc.face);
  if (loc.type == Cdt::EDGE) take(loc.face->neighbor(loc.index));
  for (std::size_t k = 0; k < face_scratch_.size(); ++k) {
    const FaceHandle f = face_scratch_[k];
    volume += face_volume(f);
    area += face_area(f);
    for (int i = 0; i < 3; ++i) box = united(box, Aabb2{xy(f->vertex(i)), xy(f->vertex(i))});
    for (int i = 0; i < 3; ++i) {
      const FaceHandle n = f->neighbor(i);
      if (f->is_constrained(i) || cdt_.is_infinite(n) || n->info() == in || n->info() == out) continue;
      if (cdt_.side_of_oriented_circle(n, q, true) == CGAL::ON_POSITIVE_SIDE)
        take(n);
      else
        n->info() = out;
    }
  }
  extent2 = (box.hi - box.lo).squaredNorm();
}

VertexHandle TinTerrain::insert_point(const Vec2& p_in, double z, bool* inserted, double* volume_change) {
  if (volume_change) *volume_change = 0.0;
  if (inserted) *inserted = false;
  if (!std::isfinite(p_in.x()) || !std::isfinite(p_in.y()) || !std::isfinite(z))
    throw InputError("tin: a vertex must have finite coordinates");
  Vec2 p = clamp_to_domain(p_in);
  const double snap = spec_.snap_m;
  if (p.x() - box_.lo.x() <= snap)
    p.x() = box_.lo.x();
  else if (box_.hi.x() - p.x() <= snap)
    p.x() = box_.hi.x();
  if (p.y() - box_.lo.y() <= snap)
    p.y() = box_.lo.y();
  else if (box_.hi.y() - p.y() <= snap)
    p.y() = box_.hi.y();

  const Location loc = locate(p);
  if (loc.type == Cdt::VERTEX) {
    edit_walk_.hint = loc.face->vertex(loc.index);
    return edit_walk_.hint;
  }
  if (snap > 0.0) {
    VertexHandle nearest;
    double best = snap * snap;
    auto consider = [&](VertexHandle v) {
      if (cdt_.is_infinite(v)) return;
      const double d2 = (xy(v) - p).squaredNorm();
      if (d2 <= best) {
        best = d2;
        nearest = v;
      }
    };
    for (int i = 0; i < 3; ++i) {
      consider(loc.face->vertex(i));
      consider(loc.face->neighbor(i)->vertex(cdt_.mirror_index(loc.face, i)));
    }
    if (nearest != VertexHandle()) {
      edit_walk_.hint = nearest;
      return nearest;
    }
  }

  // A point on a constrained edge splits it; both halves keep the edge's generation.
  bool splits_constraint = false;
  std::uint32_t generation = 0;
  VertexHandle e1, e2;
  if (loc.type == Cdt::EDGE && loc.face->is_constrained(loc.index)) {
    splits_constraint = true;
    e1 = loc.face->vertex(Cdt::ccw(loc.index));
    e2 = loc.face->vertex(Cdt::cw(loc.index));
    const auto it = generations_.find(EdgeKey(e1, e2));
    if (it != generations_.end()) {
      generation = it->second;
      generations_.erase(it);
    }
  }
  double volume_before = 0.0, area_before = 0.0, extent2 = 0.0;
  if (volume_change) conflict_region(Point(p.x(), p.y(), z), loc, volume_before, area_before, extent2);
  const VertexHandle v = cdt_.insert(Point(p.x(), p.y(), z), loc.type, loc.face, loc.index);
  if (volume_change) {
    // The new star covers what the replaced faces covered; if not, an assumption broke:
    // report no change rather than a wrong one (as end_capture does).
    double volume_after = 0.0, area_after = 0.0;
    auto c = cdt_.incident_faces(v), done = c;
    do {
      if (cdt_.is_infinite(c)) continue;
      volume_after += face_volume(c);
      area_after += face_area(c);
    } while (++c != done);
    // Rounding of the faces' areas is relative to their size (a sliver's area can come out
    // wrong by percents): the tolerance is relative to the region's squared extent, as the
    // capture's was to its region's area.
    if (std::abs(area_after - area_before) > 1e-9 * std::max(area_before, extent2))
      ++capture_mismatches_;
    else
      *volume_change = volume_after - volume_before;
  }
  v->info() = VertexInfo{};
  v->info().border = on_border(p) ? 1 : 0;
  hull_vertices_ += v->info().border;
  // Every face the insertion (and its flips) changed is incident to v now.
  forget_star(v);
  mark_star(v);
  if (splits_constraint) {
    generations_[EdgeKey(e1, v)] = generation;
    generations_[EdgeKey(v, e2)] = generation;
  }
  edit_walk_.hint = v;
  if (inserted) *inserted = true;
  return v;
}

void TinTerrain::remove_vertex(VertexHandle v) {
  drop_from_erosion(v);
  drop_from_simplify(v);
  for (Walk* walk : {&edit_walk_, &query_walk_}) {
    if (walk->hint != v) continue;
    walk->hint = VertexHandle();
    auto c = cdt_.incident_vertices(v), done = c;
    do {
      if (!cdt_.is_infinite(c)) {
        walk->hint = c;
        break;
      }
    } while (++c != done);
  }
  link_scratch_.clear();
  bool on_hull = false;
  auto c = cdt_.incident_vertices(v), done = c;
  do {
    if (cdt_.is_infinite(c))
      on_hull = true;
    else
      link_scratch_.push_back(c);
  } while (++c != done);
  mark_star(v);  // the hole is filled inside the link (and, on the hull, its border edge)
  if (on_hull)
    cdt_.remove(v);
  else
    remove_by_flips(v);
  // The hole is retriangulated from its boundary, the removed vertex's neighbours.
  for (VertexHandle w : link_scratch_) forget_caches(w);
}

void TinTerrain::remove_by_flips(VertexHandle v) {
  // Removal by flips: an edge (v, w) whose two faces form a strictly convex
  // quadrilateral is flipped to the quadrilateral's other diagonal (a, b), which takes one
  // neighbour from v; the link of an interior vertex is star-shaped around it, so some edge
  // qualifies until 3 are left, and the last triangle is merged. Lawson flips from the
  // diagonals then restore the (perturbed, so unique) Delaunay triangulation CGAL's hole
  // filling builds, without its lists (an allocation per edge), so a removal costs about half
  // the instructions of CGAL's (callgrind on trench.toml's stroke shows both).
  const auto orientation = cdt_.geom_traits().orientation_2_object();
  auto& diagonals = diagonal_scratch_;
  diagonals.clear();
  std::size_t degree = link_scratch_.size();
  while (degree > 3) {
    const FaceHandle start = v->face();
    FaceHandle f = start;
    bool flipped = false;
    do {
      const int iv = f->index(v), j = Cdt::ccw(iv);
      // Edge j of f joins v and w; a faces it in f, b in the neighbour.
      const FaceHandle g = f->neighbor(j);
      const VertexHandle w = f->vertex(Cdt::cw(iv)), a = f->vertex(j), b = g->vertex(cdt_.mirror_index(f, j));
      const auto side_v = orientation(a->point(), b->point(), v->point());
      const auto side_w = orientation(a->point(), b->point(), w->point());
      if (side_v != CGAL::COLLINEAR && side_w != CGAL::COLLINEAR && side_v != side_w) {
        FaceHandle flip_face = f;
        cdt_.flip(flip_face, j);
        diagonals.emplace_back(a, b);
        --degree;
        flipped = true;
        break;
      }
      f = f->neighbor(Cdt::ccw(f->index(v)));
    } while (f != start);
    if (!flipped) break;  // (collinear neighbours: CGAL's hole filling finishes)
  }
  if (degree > 3) {
    cdt_.remove(v);
  } else {
    // Degree 3: the merged face keeps the outer faces' constraint marks on its edges.
    const FaceHandle merged = v->face();
    cdt_.tds().remove_degree_3(v, merged);
    for (int i = 0; i < 3; ++i)
      merged->set_constraint(i, merged->neighbor(i)->is_constrained(cdt_.mirror_index(merged, i)));
  }
  // Lawson: a flipped edge's quadrilateral sides are checked in turn (CGAL's propagating_flip
  // checks only the two facing an inserted vertex).
  while (!diagonals.empty()) {
    const auto [a, b] = diagonals.back();
    diagonals.pop_back();
    FaceHandle f;
    int i = 0;
    if (!cdt_.is_edge(a, b, f, i) || !cdt_.is_flipable(f, i)) continue;
    const VertexHandle c = f->vertex(i), d = f->neighbor(i)->vertex(cdt_.mirror_index(f, i));
    cdt_.flip(f, i);
    if (changes_.tracking()) mark_changed(united(united(box_of(a), box_of(b)), united(box_of(c), box_of(d))));
    diagonals.insert(diagonals.end(), {{a, c}, {c, b}, {b, d}, {d, a}});
  }
}

void TinTerrain::constrain(VertexHandle a, VertexHandle b, std::uint32_t generation) {
  if (a == b) return;
  try {
    cdt_.insert_constraint(a, b);
  } catch (const Cdt::Intersection_of_constraints_exception&) {
    // An old constraint crosses a-b where the stamp could not drop it (found by the stamp
    // fuzzer: a footprint grazing the domain border). CGAL throws while searching, before it
    // changes the triangulation, so a-b stays unconstrained; pieces of it inserted before the
    // crossing are recorded here. Rare, so the O(n) scan is acceptable.
    record_unrecorded_constraints(generation);
    return;
  }
  // The constraint is split where it passes through vertices: record every piece.
  const auto orient = cdt_.geom_traits().orientation_2_object();
  VertexHandle cur = a, prev;
  for (std::size_t guard = 0; cur != b && guard < cdt_.number_of_vertices(); ++guard) {
    FaceHandle f;
    int i = 0;
    if (cdt_.is_edge(cur, b, f, i)) {
      generations_[EdgeKey(cur, b)] = generation;
      return;
    }
    VertexHandle next;
    auto c = cdt_.incident_vertices(cur), done = c;
    do {
      const VertexHandle w = c;
      if (cdt_.is_infinite(w) || w == prev) continue;
      if (orient(a->point(), b->point(), w->point()) != CGAL::COLLINEAR) continue;
      if ((xy(w) - xy(cur)).dot(xy(b) - xy(cur)) <= 0.0) continue;
      if (cdt_.is_edge(cur, w, f, i) && f->is_constrained(i)) {
        next = w;
        break;
      }
    } while (++c != done);
    if (next == VertexHandle()) return;  // cannot happen: CGAL enforced the segment
    generations_[EdgeKey(cur, next)] = generation;
    prev = cur;
    cur = next;
  }
}

void TinTerrain::record_unrecorded_constraints(std::uint32_t generation) {
  for (auto e = cdt_.finite_edges_begin(); e != cdt_.finite_edges_end(); ++e) {
    if (!e->first->is_constrained(e->second)) continue;
    const EdgeKey key(e->first->vertex(Cdt::ccw(e->second)), e->first->vertex(Cdt::cw(e->second)));
    generations_.try_emplace(key, generation);
  }
}

void TinTerrain::unconstrain(VertexHandle a, VertexHandle b) {
  generations_.erase(EdgeKey(a, b));
  FaceHandle f;
  int i = 0;
  if (cdt_.is_edge(a, b, f, i) && f->is_constrained(i)) cdt_.remove_constrained_edge(f, i);
}

bool TinTerrain::has_constraints(VertexHandle v) const { return cdt_.are_there_incident_constraints(v); }

double TinTerrain::vertex_area(VertexHandle v) const {
  double area = 0.0;
  auto c = cdt_.incident_faces(v), done = c;
  do {
    if (!cdt_.is_infinite(c)) area += face_area(c);
  } while (++c != done);
  return area / 3.0;
}

void TinTerrain::forget_star(VertexHandle v) {
  forget_caches(v);
  auto c = cdt_.incident_vertices(v), done = c;
  do {
    if (!cdt_.is_infinite(c)) forget_caches(c);
  } while (++c != done);
}

bool TinTerrain::has_long_edges(VertexHandle v) const {
  if (v->info().short_edges) return false;
  const double limit2 = refine_m_ * refine_m_;
  auto c = cdt_.incident_vertices(v), done = c;
  do {
    if (!cdt_.is_infinite(c) && (xy(c) - xy(v)).squaredNorm() > limit2) return true;
  } while (++c != done);
  v->info().short_edges = 1;
  return false;
}

void TinTerrain::set_z(VertexHandle v, double z) {
  const Point& p = v->point();
  v->set_point(Point(p.x(), p.y(), z));
  if (changes_.tracking() && !v->info().display_pending) {
    v->info().display_pending = 1;
    display_pending_.push_back(v);
  }
}

void TinTerrain::mark_pending_stars() {
  // A listed vertex since removed: its hole was marked then (remove_vertex); its slot, if
  // reused, holds a new vertex whose star insert_point marked.
  for (const VertexHandle v : display_pending_) {
    if (!cdt_.tds().vertices().is_used(v) || !v->info().display_pending) continue;
    v->info().display_pending = 0;
    mark_star(v);
  }
  display_pending_.clear();
}

void TinTerrain::mark_star(VertexHandle v) {
  if (!changes_.tracking()) return;
  Aabb2 star = box_of(v);
  auto c = cdt_.incident_vertices(v), done = c;
  do {
    if (!cdt_.is_infinite(c)) star = united(star, box_of(c));
  } while (++c != done);
  mark_changed(star);
}

namespace {

// Whether the circumcircle of f (in xy) comes within `margin` of the box.
bool circumcircle_meets(FaceHandle f, const Aabb2& box, double margin) {
  const Point &a = f->vertex(0)->point(), &b = f->vertex(1)->point(), &c = f->vertex(2)->point();
  const double bx = b.x() - a.x(), by = b.y() - a.y(), cx = c.x() - a.x(), cy = c.y() - a.y();
  const double d = 2.0 * (bx * cy - by * cx);
  if (!(std::abs(d) > 0.0)) return true;
  const double b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;
  const double ux = (cy * b2 - by * c2) / d, uy = (bx * c2 - cx * b2) / d;
  const double r = std::sqrt(ux * ux + uy * uy);
  // A sliver's circle is computed with a large relative error: include it (it is rare).
  const double longest = std::sqrt(std::max({b2, c2, (bx - cx) * (bx - cx) + (by - cy) * (by - cy)}));
  if (!std::isfinite(r) || r > 1e3 * longest) return true;
  const double ox = a.x() + ux, oy = a.y() + uy;
  const double dx = std::max({box.lo.x() - ox, 0.0, ox - box.hi.x()});
  const double dy = std::max({box.lo.y() - oy, 0.0, oy - box.hi.y()});
  const double reach = r * (1.0 + 1e-9) + margin;
  return dx * dx + dy * dy <= reach * reach;
}

}  // namespace

Capture TinTerrain::begin_capture(const Aabb2& box) {
  Capture c;
  const std::uint32_t inside = next_face_epoch();
  const std::uint32_t outside = next_face_epoch();
  const double margin = 1e-9 * std::max(domain_.size_m.x(), domain_.size_m.y()) + spec_.snap_m;
  const Location loc = locate(clamp_to_domain(0.5 * (box.lo + box.hi)));
  face_scratch_.clear();
  face_scratch_.push_back(loc.face);
  loc.face->info() = inside;
  for (std::size_t k = 0; k < face_scratch_.size(); ++k) {
    const FaceHandle f = face_scratch_[k];
    c.volume += face_volume(f);
    c.area += face_area(f);
    for (int i = 0; i < 3; ++i) {
      const FaceHandle n = f->neighbor(i);
      if (cdt_.is_infinite(n) || n->info() == inside || n->info() == outside) continue;
      if (circumcircle_meets(n, box, margin)) {
        n->info() = inside;
        face_scratch_.push_back(n);
      } else {
        n->info() = outside;
        c.outer.push_back({n, {&*n->vertex(0), &*n->vertex(1), &*n->vertex(2)}, n->index(f)});
      }
    }
  }
  c.faces = face_scratch_.size();
  return c;
}

CaptureResult TinTerrain::end_capture(Capture& c, std::vector<VertexHandle>* region_vertices) {
  CaptureResult r;
  r.volume_before = c.volume;
  r.area_before = c.area;
  // The fence marked afresh (the edits since begin_capture marked faces for their own walks):
  // every recorded outer face still in use, as a search of the recorded addresses would find.
  const std::uint32_t fence = next_face_epoch();
  for (const OuterFace& o : c.outer)
    if (cdt_.tds().faces().is_used(o.face)) o.face->info() = fence;
  const auto is_outer = [fence](FaceHandle f) { return f->info() == fence; };
  // The outer faces must have survived unchanged; then they fence in the same area. The walk
  // over the region after starts from the first of them in discovery order, so the order of
  // the region's vertices (and of the erosion list they join) does not depend on addresses.
  bool intact = true;
  FaceHandle start;
  for (const OuterFace& o : c.outer) {
    const FaceHandle f = o.face;
    if (!cdt_.tds().faces().is_used(f) || &*f->vertex(0) != o.vertices[0] || &*f->vertex(1) != o.vertices[1] ||
        &*f->vertex(2) != o.vertices[2]) {
      intact = false;
      continue;
    }
    const FaceHandle n = f->neighbor(o.toward);
    if (start == FaceHandle() && !cdt_.is_infinite(n) && !is_outer(n)) start = n;
  }
  if (start == FaceHandle()) start = cdt_.finite_faces_begin();

  const std::uint32_t after = next_face_epoch();
  const std::uint32_t seen = region_vertices ? next_vertex_epoch() : 0;
  if (region_vertices) region_vertices->clear();
  face_scratch_.clear();
  face_scratch_.push_back(start);
  start->info() = after;
  for (std::size_t k = 0; k < face_scratch_.size(); ++k) {
    const FaceHandle f = face_scratch_[k];
    r.volume_after += face_volume(f);
    r.area_after += face_area(f);
    for (int i = 0; i < 3; ++i) {
      if (region_vertices && f->vertex(i)->info().mark != seen) {
        f->vertex(i)->info().mark = seen;
        region_vertices->push_back(f->vertex(i));
      }
      const FaceHandle n = f->neighbor(i);
      if (cdt_.is_infinite(n) || n->info() == after || is_outer(n)) continue;
      n->info() = after;
      face_scratch_.push_back(n);
    }
  }
  r.faces_after = face_scratch_.size();
  // What the edits in between changed lies in the region (constraints' flips included).
  if (changes_.tracking()) {
    if (!intact) changes_.mark_all();
    Aabb2 region = box_of(start->vertex(0));
    for (const FaceHandle f : face_scratch_)
      for (int i = 0; i < 3; ++i) region = united(region, box_of(f->vertex(i)));
    mark_changed(region);
  }
  if (!intact || std::abs(r.area_after - r.area_before) > 1e-9 * std::max(r.area_before, 1e-30)) {
    ++capture_mismatches_;
    r.volume_after = r.volume_before;  // unknown: report no change rather than a wrong one
  }
  return r;
}

void TinTerrain::collect_vertices(const Aabb2& box, std::vector<VertexHandle>& out) {
  out.clear();
  const std::uint32_t seen = next_vertex_epoch();
  visit_faces_overlapping(box, clamp_to_domain(0.5 * (box.lo + box.hi)), edit_walk_, face_scratch_, [&](FaceHandle f) {
    for (int i = 0; i < 3; ++i) {
      const VertexHandle v = f->vertex(i);
      if (v->info().mark == seen) continue;
      v->info().mark = seen;
      if (box.contains(xy(v))) out.push_back(v);
    }
  });
}

std::span<const VertexHandle> TinTerrain::fill_ring(VertexHandle v) {
  ErosionEntry* e = &erosion_list_[v->info().erosion_slot];
  // The vertex circulator's walk, unrolled: the same start and counter-clockwise order.
  std::vector<VertexHandle>& ring = ring_scratch_;
  ring.clear();
  const VertexHandle infinite = cdt_.infinite_vertex();
  const FaceHandle start = v->face();
  FaceHandle f = start;
  do {
    const int i = Cdt::ccw(f->index(v));
    const VertexHandle w = f->vertex(i);
    f = f->neighbor(i);
    if (w != infinite) ring.push_back(w);
  } while (f != start);
  if (ring.size() > 0xffffu) return ring;  // (never in a triangulation built by the stamps): not cached
  const auto n = static_cast<std::uint16_t>(ring.size());
  if (e->ring == kNoSlot || e->ring_capacity < n) {
    if (e->ring != kNoSlot) {
      ring_pool_live_ -= e->ring_capacity;
      e->ring = kNoSlot;
    }
    // (No spare slot: splits are rare next to visits, and the pool is most of the cache's memory.)
    const std::uint16_t capacity = n;
    if (ring_pool_.size() + capacity > ring_pool_.capacity()) {
      // Full: reclaim the garbage when it is an eighth of the pool, else grow by a quarter
      // (amortized O(1) per slot either way, and the pool stays within about 1.4 times its
      // live part).
      const std::size_t garbage = ring_pool_.size() - ring_pool_live_;
      const std::size_t live = ring_pool_live_ + capacity;
      compact_ring_pool(garbage >= ring_pool_.size() / 8
                            ? std::max(ring_pool_.capacity(), live + live / 8)
                            : ring_pool_.capacity() + ring_pool_.capacity() / 4 + capacity + 64);
      e = &erosion_list_[v->info().erosion_slot];
    }
    e->ring = static_cast<std::uint32_t>(ring_pool_.size());
    e->ring_capacity = capacity;
    ring_pool_.resize(ring_pool_.size() + capacity);
    ring_pool_live_ += capacity;
  }
  std::copy(ring.begin(), ring.end(), ring_pool_.begin() + e->ring);
  e->ring_size = n;
  return {ring_pool_.data() + e->ring, e->ring_size};
}

void TinTerrain::compact_ring_pool(std::size_t capacity) {
  // In L_e's order, so the layout depends on the run only (never on addresses).
  std::vector<VertexHandle> pool;
  pool.reserve(std::max(capacity, ring_pool_live_));
  for (ErosionEntry& e : erosion_list_) {
    if (e.ring == kNoSlot) continue;
    const auto from = ring_pool_.begin() + e.ring;
    e.ring = static_cast<std::uint32_t>(pool.size());
    pool.insert(pool.end(), from, from + e.ring_capacity);
  }
  ring_pool_.swap(pool);
  ring_pool_live_ = ring_pool_.size();
}

void TinTerrain::drop_from_erosion(VertexHandle v) {
  const std::uint32_t slot = v->info().erosion_slot;
  if (slot == kNoSlot) return;
  if (erosion_list_[slot].ring != kNoSlot) ring_pool_live_ -= erosion_list_[slot].ring_capacity;
  const ErosionEntry last = erosion_list_.back();
  erosion_list_[slot] = last;
  last.vertex->info().erosion_slot = slot;
  erosion_list_.pop_back();
  v->info().erosion_slot = kNoSlot;
}

void TinTerrain::add_to_simplify(VertexHandle v) {
  VertexInfo& in = v->info();
  if (in.simplify_slot != kNoSlot) return;
  in.simplify_slot = static_cast<std::uint32_t>(simplify_list_.size());
  simplify_list_.push_back(v);
}

void TinTerrain::drop_from_simplify(VertexHandle v) {
  const std::uint32_t slot = v->info().simplify_slot;
  if (slot == kNoSlot) return;
  const VertexHandle last = simplify_list_.back();
  simplify_list_[slot] = last;
  last->info().simplify_slot = slot;
  simplify_list_.pop_back();
  v->info().simplify_slot = kNoSlot;
}

std::uint32_t TinTerrain::next_face_epoch() const {
  if (face_epoch_ >= 0xFFFFFF00u) {
    for (auto f = cdt_.all_faces_begin(); f != cdt_.all_faces_end(); ++f) f->info() = 0;
    face_epoch_ = 0;
  }
  return ++face_epoch_;
}

std::uint32_t TinTerrain::next_vertex_epoch() {
  if (vertex_epoch_ >= 0xFFFFFF00u) {
    for (auto v = cdt_.finite_vertices_begin(); v != cdt_.finite_vertices_end(); ++v) v->info().mark = 0;
    vertex_epoch_ = 0;
  }
  return ++vertex_epoch_;
}

}  // namespace sb::tin::detail
