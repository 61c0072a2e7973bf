// Stamping (the paper's step 1a-1f) and pouring.
//
// A stamp: the outer contour O (the footprint offset outwards by a small gap), its heights
// interpolated from the terrain and subdivided where the terrain is not linear, constrained
// first; the inner contour I (the footprint) at tool depth, constrained second; heights inside
// lowered to the tool; redundant inner vertices removed; the displaced volume deposited on the
// rim band by the common rule (ToolStamp::rim_weight). Old constraints within reach of O are
// dropped before anything is inserted, so new constraints never touch or cross old ones.
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "common/input_error.hpp"
#include "tin/detail/tin_impl.hpp"

namespace sb::tin::detail {

namespace {

// A vertex order that is the same in every run: by (x, y), unique among a triangulation's
// vertices. Ordering by address would follow the heap's layout, which differs between
// builds and runs.
bool by_position(VertexHandle a, VertexHandle b) {
  const auto &p = a->point(), &q = b->point();
  return p.x() < q.x() || (p.x() == q.x() && p.y() < q.y());
}

// The polygon's vertices moved outwards by `gap` along the angle bisectors (mitred offset of
// a counter-clockwise polygon; long mitres at sharp corners are cut to 4 gaps).
std::vector<Vec2> offset_polygon(const std::vector<Vec2>& poly, double gap) {
  const std::size_t n = poly.size();
  std::vector<Vec2> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2& prev = poly[(i + n - 1) % n];
    const Vec2& cur = poly[i];
    const Vec2& next = poly[(i + 1) % n];
    Vec2 e0 = cur - prev, e1 = next - cur;
    const double l0 = e0.norm(), l1 = e1.norm();
    const Vec2 n0 = l0 > 0.0 ? Vec2(Vec2(e0.y(), -e0.x()) / l0) : Vec2(Vec2::Zero());
    const Vec2 n1 = l1 > 0.0 ? Vec2(Vec2(e1.y(), -e1.x()) / l1) : Vec2(Vec2::Zero());
    const double denom = 1.0 + n0.dot(n1);
    Vec2 shift = denom > 1e-6 ? Vec2((n0 + n1) * gap / denom) : Vec2((n0 + n1).normalized() * gap);
    if (shift.norm() > 4.0 * gap) shift *= 4.0 * gap / shift.norm();
    out[i] = cur + shift;
  }
  return out;
}

// Convex and simple: no right turn, and the turns add up to one full turn (a pentagram
// turns left at every corner, but twice around).
bool is_convex(const std::vector<Vec2>& poly) {
  const std::size_t n = poly.size();
  double turning = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 a = poly[(i + 1) % n] - poly[i], b = poly[(i + 2) % n] - poly[(i + 1) % n];
    if (cross2(a, b) < 0.0) return false;
    turning += std::atan2(cross2(a, b), a.dot(b));
  }
  return std::abs(turning - 2.0 * std::numbers::pi) < 1e-6;
}

// Sutherland-Hodgman clipping of a polygon to the box. Points on the box's sides are exact.
std::vector<Vec2> clip_to_box(const std::vector<Vec2>& poly, const Aabb2& box) {
  std::vector<Vec2> cur = poly, next;
  for (int side = 0; side < 4; ++side) {
    const int axis = side / 2;
    const bool low = side % 2 == 0;
    const double bound = low ? box.lo[axis] : box.hi[axis];
    auto inside = [&](const Vec2& p) { return low ? p[axis] >= bound : p[axis] <= bound; };
    next.clear();
    const std::size_t n = cur.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Vec2& a = cur[i];
      const Vec2& b = cur[(i + 1) % n];
      const bool ia = inside(a), ib = inside(b);
      if (ia) next.push_back(a);
      if (ia != ib) {
        const double t = (bound - a[axis]) / (b[axis] - a[axis]);
        Vec2 x = a + t * (b - a);
        x[axis] = bound;
        x[1 - axis] = std::clamp(x[1 - axis], box.lo[1 - axis], box.hi[1 - axis]);
        next.push_back(x);
      }
    }
    cur.swap(next);
    if (cur.empty()) break;
  }
  return cur;
}

// Drops points within `tolerance` of their predecessor (cyclically).
void drop_near_duplicates(std::vector<Vec2>& poly, double tolerance) {
  std::vector<Vec2> out;
  for (const Vec2& p : poly)
    if (out.empty() || (p - out.back()).norm() > tolerance) out.push_back(p);
  while (out.size() > 1 && (out.front() - out.back()).norm() <= tolerance) out.pop_back();
  poly.swap(out);
}

double segment_distance(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const double o1 = cross2(b - a, c - a), o2 = cross2(b - a, d - a);
  const double o3 = cross2(d - c, a - c), o4 = cross2(d - c, b - c);
  if (((o1 > 0) != (o2 > 0)) && ((o3 > 0) != (o4 > 0)) && o1 != 0 && o2 != 0 && o3 != 0 && o4 != 0) return 0.0;
  return std::min({distance_to_segment(a, c, d), distance_to_segment(b, c, d), distance_to_segment(c, a, b),
                   distance_to_segment(d, a, b)});
}

// Whether segment ab comes within `margin` of the closed polygon region.
bool segment_near_region(const Vec2& a, const Vec2& b, const std::vector<Vec2>& poly, double margin) {
  if (point_in_polygon(poly, a) || point_in_polygon(poly, b)) return true;
  const std::size_t n = poly.size();
  for (std::size_t i = 0; i < n; ++i)
    if (segment_distance(a, b, poly[i], poly[(i + 1) % n]) <= margin) return true;
  return false;
}

Aabb2 unite(const Aabb2& a, const Aabb2& b) { return {a.lo.cwiseMin(b.lo), a.hi.cwiseMax(b.hi)}; }

Aabb2 intersect(const Aabb2& a, const Aabb2& b) { return {a.lo.cwiseMax(b.lo), a.hi.cwiseMin(b.hi)}; }

bool same_border_side(const Vec2& a, const Vec2& b, const Aabb2& box) {
  return (a.x() == box.lo.x() && b.x() == box.lo.x()) || (a.x() == box.hi.x() && b.x() == box.hi.x()) ||
         (a.y() == box.lo.y() && b.y() == box.lo.y()) || (a.y() == box.hi.y() && b.y() == box.hi.y());
}

}  // namespace

double TinTerrain::drop_stale_constraints(std::uint32_t generation) {
  std::vector<std::pair<VertexHandle, VertexHandle>> stale;
  for (const auto& [key, g] : generations_) {
    if (g >= generation) continue;
    auto handle = [this](const void* p) {
      return cdt_.tds().vertices().iterator_to(*static_cast<Tds::Vertex*>(const_cast<void*>(p)));
    };
    stale.emplace_back(handle(key.a), handle(key.b));
  }
  if (stale.empty()) return 0.0;
  // The hash map's order follows vertex addresses, which differ between processes: sort by
  // position so that the flips after unconstraining, and so every run, are reproducible.
  const auto by_position = [this](const std::pair<VertexHandle, VertexHandle>& p) {
    const Vec2 a = xy(p.first), b = xy(p.second);
    const bool swap = std::make_pair(b.x(), b.y()) < std::make_pair(a.x(), a.y());
    return swap ? std::array<double, 4>{b.x(), b.y(), a.x(), a.y()} : std::array<double, 4>{a.x(), a.y(), b.x(), b.y()};
  };
  std::sort(stale.begin(), stale.end(), [&](const auto& l, const auto& r) { return by_position(l) < by_position(r); });
  Aabb2 box{xy(stale.front().first), xy(stale.front().first)};
  for (const auto& [a, b] : stale) box = unite(box, bounds(std::vector<Vec2>{xy(a), xy(b)}));
  const double extent = std::max(domain_.size_m.x(), domain_.size_m.y());
  Capture capture = begin_capture(box.expanded(4.0 * spec_.snap_m + 1e-9 * extent));
  for (const auto& [a, b] : stale) unconstrain(a, b);
  std::vector<VertexHandle> region_vertices;
  const CaptureResult measured = end_capture(capture, &region_vertices);
  for (VertexHandle v : region_vertices) {
    v->info().area = -1.0;
    v->info().short_edges = 0;
  }
  for (VertexHandle v : region_vertices) {
    touch(v);
    add_to_simplify(v);
  }
  // The flips that restore the Delaunay property change the surface a little: the caller
  // gives the volume back with the stamp's deposit.
  return measured.delta();
}

void TinTerrain::snap_border_crossings(std::vector<Vec2>& contour, double reach) {
  const auto on_side = [this](const Vec2& p, int axis) { return p[axis] == box_.lo[axis] || p[axis] == box_.hi[axis]; };
  std::vector<VertexHandle> near;
  for (Vec2& p : contour) {
    for (int axis = 0; axis < 2; ++axis) {
      if (!on_side(p, axis) || on_side(p, 1 - axis)) continue;  // not on this side, or a corner
      collect_vertices(Aabb2{p, p}.expanded(reach), near);
      double best = reach;
      for (VertexHandle v : near) {
        const Vec2 q = xy(v);
        const double d = std::abs(q[1 - axis] - p[1 - axis]);
        if (q[axis] == p[axis] && d > 0.0 && d <= best) {
          best = d;
          p[1 - axis] = q[1 - axis];
        }
      }
    }
  }
}

StampReport TinTerrain::stamp(const ToolStamp& s) {
  // The constraints of stamps that have passed only kept their walls from being flipped:
  // dropped, so the surface between old stamps is free to relax and coarsen (the Delaunay
  // triangulation minimises roughness, Rippa 1990).
  const double unconstrained = drop_stale_constraints(s.generation);
  stale_delta_ = spec_.conserve_volume ? unconstrained : 0.0;
  if (s.is_pour()) return pour(s);
  if (s.footprint.size() < 3) throw InputError("stamp: the footprint needs at least 3 points");
  for (const Vec2& p : s.footprint)
    if (!p.allFinite()) throw InputError("stamp: the footprint has a non-finite point");
  if (!s.pose.xy.allFinite() || !std::isfinite(s.pose.bottom_z) || !std::isfinite(s.rim.width_m) ||
      !std::isfinite(s.rim.forward_bias) || !s.motion_dir.allFinite())
    throw InputError("stamp: the pose, rim and motion must be finite");
  if (s.profile == BottomProfile::SphereCap && !(s.sphere_radius_m > 0.0))
    throw InputError("stamp: a sphere-cap tool needs a positive sphere radius");
  StampReport report;
  const double extent = std::max(domain_.size_m.x(), domain_.size_m.y());
  const double tiny = 1e-12 * extent;
  std::vector<Vec2> footprint = make_ccw(s.footprint);
  drop_near_duplicates(footprint, tiny);
  const double area = std::abs(signed_area(footprint));
  if (footprint.size() < 3 || !(area > 0.0)) throw InputError("stamp: the footprint has zero area");
  // A many-sided convex tool (tool.sides up to 4096) is cut to kMaxSides evenly spaced
  // corners: the mesh resolves no more (contour edges would be far below refine_m_), and
  // each corner costs insertions, constraints and removals. A subset of a convex polygon's
  // corners is convex and inscribed, so in_footprint still holds inside it.
  constexpr std::size_t kMaxSides = 64;
  if (footprint.size() > kMaxSides && is_convex(footprint)) {
    std::vector<Vec2> fewer;
    for (std::size_t k = 0; k < kMaxSides; ++k) fewer.push_back(footprint[k * footprint.size() / kMaxSides]);
    footprint.swap(fewer);
  }
  // Its edges become constraints, which must not cross.
  if (!is_convex(footprint) && !is_simple_polygon(footprint))
    throw InputError("stamp: the footprint must be a simple polygon (its edges cross)");
  const double snap = spec_.snap_m;
  const double margin = 4.0 * snap + 1e-9 * extent;
  const double radius = std::sqrt(area / std::numbers::pi);
  double gap = spec_.contour_gap_m > 0.0 ? spec_.contour_gap_m : 0.05 * radius;
  gap = std::max(gap, 16.0 * snap + 1e-9 * extent);

  // O: the footprint offset outwards. A thin non-convex footprint may need a smaller gap.
  std::vector<Vec2> outer = offset_polygon(footprint, gap);
  if (!is_convex(footprint)) {
    for (int tries = 0; !is_simple_polygon(outer); ++tries) {
      if (tries == 8) throw InputError("stamp: the footprint is too thin for the contour gap (tin.contour_gap_m)");
      gap *= 0.5;
      outer = offset_polygon(footprint, gap);
    }
  }
  std::vector<Vec2> outer_clip = clip_to_box(outer, box_);
  std::vector<Vec2> inner_clip = clip_to_box(footprint, box_);
  // Where the contours cross the border, stamps that follow each other along a stroke leave
  // border vertices at arbitrary distances. A border vertex a hair from the next has a tiny
  // area, which throttles every transfer through it (a transfer is limited by the smaller
  // area), so the slopes there settled only after millions of passes. A crossing within a
  // quarter gap of an existing border vertex takes that vertex's place instead; O and I,
  // at least a gap apart along the border, stay apart.
  snap_border_crossings(outer_clip, 0.25 * gap);
  snap_border_crossings(inner_clip, 0.25 * gap);
  drop_near_duplicates(outer_clip, 2.0 * snap + tiny);
  drop_near_duplicates(inner_clip, 2.0 * snap + tiny);
  if (outer_clip.size() < 3 || !(std::abs(signed_area(outer_clip)) > 0.0)) return report;  // off the domain
  if (inner_clip.size() < 3 || !(std::abs(signed_area(inner_clip)) > 0.0)) inner_clip.clear();

  // 1a: the outer contour's heights from the terrain, subdivided where it is not linear.
  struct ContourPoint {
    Vec2 p;
    double z;
  };
  std::vector<ContourPoint> o_pts;
  {
    const double step = spec_.contour_subdivision_m;
    const double tol = spec_.tolerance_m;
    auto refine = [&](auto&& self, const Vec2& a, double za, const Vec2& b, double zb, int depth) -> void {
      const Vec2 m = 0.5 * (a + b);
      if (depth >= 8 || (b - a).norm() < 8.0 * snap + 16.0 * tiny) return;
      const double zm = height(m);
      if (std::abs(zm - 0.5 * (za + zb)) <= tol) return;
      self(self, a, za, m, zm, depth + 1);
      o_pts.push_back({m, zm});
      self(self, m, zm, b, zb, depth + 1);
    };
    const std::size_t n = outer_clip.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Vec2 a = outer_clip[i], b = outer_clip[(i + 1) % n];
      const double za = height(a);
      o_pts.push_back({a, za});
      if (same_border_side(a, b, box_)) continue;
      const int pieces = step > 0.0 ? std::max(1, static_cast<int>(std::ceil((b - a).norm() / step))) : 1;
      Vec2 pa = a;
      double zpa = za;
      for (int k = 1; k <= pieces; ++k) {
        const Vec2 pb = k == pieces ? b : Vec2(a + (b - a) * (static_cast<double>(k) / pieces));
        const double zpb = height(pb);
        refine(refine, pa, zpa, pb, zpb, 0);
        if (k < pieces) o_pts.push_back({pb, zpb});
        pa = pb;
        zpa = zpb;
      }
    }
  }
  // I (at the terrain's height until 1d lowers it); interior points for a curved bottom.
  std::vector<ContourPoint> i_pts, interior_pts;
  for (const Vec2& p : inner_clip) i_pts.push_back({p, height(p)});
  if (s.profile == BottomProfile::SphereCap && !inner_clip.empty()) {
    for (double t : {0.75, 0.5, 0.25}) {
      for (const Vec2& f : footprint) {
        const Vec2 p = s.pose.xy + t * (f - s.pose.xy);
        if (box_.contains(p) && s.contains(p) && distance_to_boundary(footprint, p) > gap)
          interior_pts.push_back({p, height(p)});
      }
    }
    if (box_.contains(s.pose.xy) && s.contains(s.pose.xy)) interior_pts.push_back({s.pose.xy, height(s.pose.xy)});
  }
  // Rim vertices where the band has none nearby: a ring in the band's middle to take the
  // deposit, and a ring on its outer edge so the deposit stays in the band (on a coarse TIN
  // a raised vertex would otherwise spread sand thinly over triangles reaching far away).
  std::vector<ContourPoint> rim_pts;
  if (s.rim.width_m > gap) {
    for (double offset : {0.5 * (gap + s.rim.width_m), s.rim.width_m}) {
      const std::vector<Vec2> ring = offset_polygon(footprint, offset);
      double perimeter = 0.0;
      for (std::size_t i = 0; i < ring.size(); ++i) perimeter += (ring[(i + 1) % ring.size()] - ring[i]).norm();
      const double needed = 0.5 * perimeter / static_cast<double>(ring.size());
      for (const Vec2& p : ring) {
        if (!box_.contains(p) || point_in_polygon(outer, p) || s.rim_weight(p) <= 0.0) continue;
        const Location loc = locate(p);
        bool has_near = false;
        for (int i = 0; i < 3; ++i) has_near = has_near || (xy(loc.face->vertex(i)) - p).norm() < needed;
        if (!has_near) rim_pts.push_back({p, interpolate(loc.face, p)});
      }
    }
  }

  // Old constraints within reach of O are dropped (whatever their generation): afterwards no
  // old constraint can touch or cross the new ones, which all lie inside O. The reach extends
  // a gap beyond O, where old vertices are cleared (below) so that repeated stamps at one
  // spot (or turning ones) do not pile up contour vertices just outside each other.
  const double clearance = gap;
  std::vector<std::pair<VertexHandle, VertexHandle>> dropped;
  Aabb2 reach = bounds(outer_clip).expanded(clearance + margin);
  {
    // Every constrained edge that meets O belongs to faces overlapping O's box: walk them.
    std::vector<FaceHandle> faces;
    const std::uint32_t walked = next_face_epoch();
    const Location loc = locate(clamp_to_domain(0.5 * (reach.lo + reach.hi)));
    faces.push_back(loc.face);
    loc.face->info() = walked;
    for (std::size_t k = 0; k < faces.size(); ++k) {
      const FaceHandle f = faces[k];
      for (int i = 0; i < 3; ++i) {
        if (f->is_constrained(i)) {
          const VertexHandle a = f->vertex(Cdt::ccw(i)), b = f->vertex(Cdt::cw(i));
          if (segment_near_region(xy(a), xy(b), outer_clip, clearance + margin)) dropped.emplace_back(a, b);
        }
        const FaceHandle n = f->neighbor(i);
        if (cdt_.is_infinite(n) || n->info() == walked) continue;
        const Point &p0 = n->vertex(0)->point(), &p1 = n->vertex(1)->point(), &p2 = n->vertex(2)->point();
        const bool overlaps =
            std::max({p0.x(), p1.x(), p2.x()}) >= reach.lo.x() && std::min({p0.x(), p1.x(), p2.x()}) <= reach.hi.x() &&
            std::max({p0.y(), p1.y(), p2.y()}) >= reach.lo.y() && std::min({p0.y(), p1.y(), p2.y()}) <= reach.hi.y();
        if (!overlaps) continue;
        n->info() = walked;
        faces.push_back(n);
      }
    }
    // Ordered by position, not address: the order they are unconstrained in shapes the mesh,
    // and addresses depend on the heap's layout (a run must not).
    for (auto& [a, b] : dropped)
      if (by_position(b, a)) std::swap(a, b);
    std::sort(dropped.begin(), dropped.end(), [](const auto& x, const auto& y) {
      return by_position(x.first, y.first) || (x.first == y.first && by_position(x.second, y.second));
    });
    dropped.erase(std::unique(dropped.begin(), dropped.end()), dropped.end());
  }

  // Everything the stamp changes lies in this box: O, the rim band, the dropped constraints.
  Aabb2 region = unite(reach, intersect(s.influence_bounds(), box_));
  for (const ContourPoint& r : rim_pts) region = unite(region, Aabb2{r.p, r.p});
  for (const auto& [a, b] : dropped) region = unite(region, bounds(std::vector<Vec2>{xy(a), xy(b)}));
  Capture capture = begin_capture(region.expanded(margin));

  for (const auto& [a, b] : dropped) unconstrain(a, b);

  // The stamp's own vertices (contours, interior): kept by the removals below.
  std::vector<VertexHandle> o_verts, i_verts;
  std::vector<const void*> own;
  std::vector<VertexHandle> fresh;
  auto add = [&](const ContourPoint& c) {
    bool inserted = false;
    const VertexHandle v = insert_point(c.p, c.z, &inserted);
    if (inserted) {
      ++report.vertices_inserted;
      fresh.push_back(v);
    }
    return v;
  };
  for (const ContourPoint& c : o_pts) o_verts.push_back(add(c));
  for (const ContourPoint& c : i_pts) i_verts.push_back(add(c));
  for (const ContourPoint& c : interior_pts) own.push_back(&*add(c));
  for (const ContourPoint& c : rim_pts) add(c);
  for (VertexHandle v : o_verts) own.push_back(&*v);
  for (VertexHandle v : i_verts) own.push_back(&*v);
  std::sort(own.begin(), own.end());
  auto is_own = [&own](VertexHandle v) { return std::binary_search(own.begin(), own.end(), &*v); };
  const Aabb2 footprint_bounds = bounds(footprint).expanded(2.0 * tiny);
  auto in_footprint = [&](const Vec2& p) {
    return footprint_bounds.contains(p) && (s.contains(p) || distance_to_boundary(footprint, p) <= tiny);
  };

  // Old vertices between I and O would bend the wall, and those just outside O would crowd
  // it: removed.
  collect_vertices(reach, vertex_scratch_);
  std::vector<VertexHandle> band;
  for (VertexHandle v : vertex_scratch_) {
    const Vec2 p = xy(v);
    if (is_own(v) || v->info().border || in_footprint(p) || has_constraints(v)) continue;
    const double to_outer = distance_to_boundary(outer_clip, p);
    if (to_outer <= tiny) continue;
    if (point_in_polygon(outer_clip, p) || to_outer < clearance) band.push_back(v);
  }
  for (VertexHandle v : band) {
    remove_vertex(v);
    ++report.vertices_removed;
  }
  std::vector<VertexHandle> survivors;
  for (VertexHandle v : fresh)
    if (std::find(band.begin(), band.end(), v) == band.end()) survivors.push_back(v);
  fresh.swap(survivors);

  // 1b, 1c: O constrained first, then I; edges along the domain border stay unconstrained.
  auto constrain_ring = [&](const std::vector<VertexHandle>& ring) {
    for (std::size_t k = 0; k < ring.size(); ++k) {
      const VertexHandle a = ring[k], b = ring[(k + 1) % ring.size()];
      if (a == b || same_border_side(xy(a), xy(b), box_)) continue;
      constrain(a, b, s.generation);
    }
  };
  if (o_verts.size() >= 3) constrain_ring(o_verts);
  if (i_verts.size() >= 3) constrain_ring(i_verts);

  // 1d: heights inside lowered to the tool; the volume taken is exact (barycentric areas).
  // A tool deeper than the bed stops at its floor, z = 0: there is no sand below to push away.
  auto bottom = [&s](const Vec2& p) { return std::max(s.bottom_z(p), 0.0); };
  std::vector<VertexHandle> inside;
  std::vector<VertexHandle> changed;
  const Aabb2 footprint_box = intersect(bounds(footprint).expanded(margin), box_);
  collect_vertices(footprint_box, vertex_scratch_);
  double lowered_volume = 0.0;
  for (VertexHandle v : vertex_scratch_) {
    const Vec2 p = xy(v);
    if (!in_footprint(p)) continue;
    inside.push_back(v);
    const double z = v->point().z(), tool = bottom(p);
    if (z > tool) {
      lowered_volume += (z - tool) * vertex_area(v);
      set_z(v, tool);
      changed.push_back(v);
    }
  }

  // 1e: redundant inner vertices: at tool level, not on the footprint's border or the
  // domain's, no deeper neighbour.
  const double level_eps = 1e-9 * std::max(1.0, std::abs(s.pose.bottom_z));
  std::vector<VertexHandle> redundant;
  for (VertexHandle v : inside) {
    const Vec2 p = xy(v);
    if (is_own(v) || v->info().border || distance_to_boundary(footprint, p) <= tiny || has_constraints(v)) continue;
    if (std::abs(v->point().z() - bottom(p)) > level_eps) continue;
    bool deeper = false;
    auto c = cdt_.incident_vertices(v), done = c;
    do {
      if (cdt_.is_infinite(c)) continue;
      const Vec2 q = xy(c->point());
      const double tool = in_footprint(q) ? bottom(q) : std::max(s.pose.bottom_z, 0.0);
      deeper = deeper || c->point().z() < tool - level_eps;
    } while (++c != done && !deeper);
    if (!deeper) redundant.push_back(v);
  }
  // Removed in position order (the order shapes the retriangulation; see by_position).
  std::sort(redundant.begin(), redundant.end(), by_position);
  for (VertexHandle v : redundant) {
    remove_vertex(v);
    ++report.vertices_removed;
  }
  auto removed = [&](VertexHandle v) { return std::binary_search(redundant.begin(), redundant.end(), v, by_position); };
  std::erase_if(changed, removed);
  std::erase_if(fresh, removed);

  // The retriangulation's own volume change (flips, removals of non-planar vertices).
  std::vector<VertexHandle> region_vertices;
  const CaptureResult measured = end_capture(capture, &region_vertices);
  const double surface_change = measured.delta() + lowered_volume;
  // Constraint changes retriangulate inside the region, beyond the inserted vertices' stars.
  for (VertexHandle v : region_vertices) {
    v->info().area = -1.0;
    v->info().short_edges = 0;
  }

  // 1d (cont.): the displaced volume goes to the rim band, weighted by the common rule. The
  // band's vertices first get short edges (refine_around), so the sand stays in the band.
  double deposit = lowered_volume - (spec_.conserve_volume ? surface_change : 0.0) - stale_delta_;
  const Aabb2 band_box = intersect(s.influence_bounds(), box_);
  collect_vertices(band_box, vertex_scratch_);
  std::vector<VertexHandle> band_vertices;
  // rim_weight: 0 inside the footprint; the inner contour lies on its boundary, which
  // point-in-polygon may put either side, so it is excluded explicitly.
  auto rim_weight = [&](const Vec2& p) { return in_footprint(p) ? 0.0 : s.rim_weight(p); };
  for (VertexHandle v : vertex_scratch_)
    if (rim_weight(xy(v)) > 0.0) band_vertices.push_back(v);
  for (VertexHandle v : band_vertices) report.vertices_inserted += refine_around(v);
  collect_vertices(band_box, vertex_scratch_);
  std::vector<std::pair<VertexHandle, double>> targets;
  double weight_sum = 0.0;
  for (VertexHandle v : vertex_scratch_) {
    const double w = rim_weight(xy(v));
    if (w <= 0.0) continue;
    const double wa = w * vertex_area(v);
    targets.emplace_back(v, wa);
    weight_sum += wa;
  }
  if (!(weight_sum > 0.0)) {  // the band is off the domain or has no area: use O
    targets.clear();
    for (VertexHandle v : o_verts) {
      const double a = vertex_area(v);
      targets.emplace_back(v, a);
      weight_sum += a;
    }
  }
  if (weight_sum > 0.0 && deposit != 0.0) {
    for (const auto& [v, wa] : targets) {
      const double a = vertex_area(v);
      if (a <= 0.0) continue;
      set_z(v, v->point().z() + deposit * (wa / weight_sum) / a);
      changed.push_back(v);
    }
  } else {
    deposit = 0.0;
  }

  // 1f: changed vertices join L_e and L_r; the retriangulated region joins L_e.
  for (VertexHandle v : region_vertices) touch(v);
  for (VertexHandle v : changed) {
    touch_with_neighbours(v);
    add_to_simplify(v);
  }
  for (VertexHandle v : fresh) add_to_simplify(v);

  report.volume_removed_m3 = lowered_volume;
  report.volume_deposited_m3 = deposit;
  report.elements_touched = measured.faces_after;
  return report;
}

StampReport TinTerrain::pour(const ToolStamp& s) {
  if (!s.pose.xy.allFinite() || !std::isfinite(s.pour_volume_m3) || !std::isfinite(s.pour_radius_m))
    throw InputError("pour: the position, volume and radius must be finite");
  StampReport report;
  const double extent = std::max(domain_.size_m.x(), domain_.size_m.y());
  const double margin = 4.0 * spec_.snap_m + 1e-9 * extent;
  const Vec2 centre = clamp_to_domain(s.pose.xy);
  const double radius = s.pour_radius_m > 0.0 ? s.pour_radius_m : refine_m_;

  // The point itself and a ring at the pour radius, where there are no vertices yet.
  struct Pending {
    Vec2 p;
    double z;
  };
  std::vector<Pending> pending{{centre, height(centre)}};
  constexpr int kRing = 12;
  for (int k = 0; k < kRing; ++k) {
    const double t = 2.0 * std::numbers::pi * k / kRing;
    const Vec2 p = centre + radius * Vec2(std::cos(t), std::sin(t));
    if (!box_.contains(p)) continue;
    const Location loc = locate(p);
    bool has_near = false;
    for (int i = 0; i < 3; ++i) has_near = has_near || (xy(loc.face->vertex(i)) - p).norm() < 0.5 * radius;
    if (!has_near) pending.push_back({p, interpolate(loc.face, p)});
  }
  Capture capture = begin_capture(Aabb2{centre, centre}.expanded(radius + margin));
  std::vector<VertexHandle> fresh;
  for (const Pending& q : pending) {
    bool inserted = false;
    const VertexHandle v = insert_point(q.p, q.z, &inserted);
    if (inserted) {
      ++report.vertices_inserted;
      fresh.push_back(v);
    }
  }
  std::vector<VertexHandle> region_vertices;
  const CaptureResult measured = end_capture(capture, &region_vertices);

  // The volume lands as a cone of the pour radius (weights 1 - d / r times vertex areas), on
  // vertices with short edges (refine_around), so the sand stays within the radius.
  const double volume = s.pour_volume_m3 - (spec_.conserve_volume ? measured.delta() : 0.0) - stale_delta_;
  const Aabb2 reach = intersect(Aabb2{centre, centre}.expanded(radius), box_);
  collect_vertices(reach, vertex_scratch_);
  std::vector<VertexHandle> receivers;
  for (VertexHandle v : vertex_scratch_)
    if ((xy(v) - centre).norm() < radius) receivers.push_back(v);
  for (VertexHandle v : receivers) report.vertices_inserted += refine_around(v);
  collect_vertices(reach, vertex_scratch_);
  std::vector<std::pair<VertexHandle, double>> targets;
  double weight_sum = 0.0;
  for (VertexHandle v : vertex_scratch_) {
    const double w = 1.0 - (xy(v) - centre).norm() / radius;
    if (w <= 0.0) continue;
    const double wa = w * vertex_area(v);
    targets.emplace_back(v, wa);
    weight_sum += wa;
  }
  for (const auto& [v, wa] : targets) {
    const double a = vertex_area(v);
    if (a <= 0.0) continue;
    set_z(v, v->point().z() + volume * (wa / weight_sum) / a);
    touch_with_neighbours(v);
    add_to_simplify(v);
  }
  for (VertexHandle v : region_vertices) touch(v);
  for (VertexHandle v : fresh) add_to_simplify(v);
  report.volume_deposited_m3 = weight_sum > 0.0 ? volume : 0.0;
  report.elements_touched = measured.faces_after;
  return report;
}

}  // namespace sb::tin::detail
