// Stamping (the paper's step 1a-1f) and pouring.
//
// A stamp: the outer contour O (the footprint offset outwards by a small gap), its heights
// interpolated from the terrain and subdivided where the terrain is not linear, constrained
// first; the inner contour I (the footprint) at tool depth, constrained second; heights inside
// lowered to the tool; redundant inner vertices removed; the displaced volume deposited on the
// rim band by the common rule (ToolStamp::rim_weight). Old constraints within reach of O are
// dropped before anything is inserted, so new constraints never touch or cross old ones.
// stamp() reads as that list; each step is one function below, sharing a StampWork. A
// footprint narrower than the mesh resolves (resolves) skips 1a-1c and 1e: 1d lowers the
// vertices it covers, as a grid lowers its nodes.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <unordered_map>

#include "common/input_error.hpp"
#include "tin/detail/stamp_work.hpp"
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

// A convex footprint keeps about one corner per refine_m_ of its perimeter (evenly spaced,
// at least kMinSides, at most kMaxSides): the mesh around a stamp has edges of refine_m_, so
// finer contours are not resolved, and every corner costs insertions, constraints, rim
// points and erosion visits (tool.sides = 4096 is allowed). The 32-gon disk of the shipped
// scenes becomes a 16-gon of the same area.
constexpr std::size_t kMaxSides = 64;
constexpr std::size_t kMinSides = 8;

// Contour vertices of a passed stamp closer than this fraction of refine_m_ to a lower one
// are removed (thin_passed_contours). Measured on trench_azimuth.toml at 7 azimuths: walls
// within 0.57 degrees of critical on average (worst 0.87) against 0.86 (1.68) without.
constexpr double kPassedContourSpacing = 1.0 / 3.0;

// A footprint whose width (4 area / perimeter: a disk's diameter, a square's side) is below
// this fraction of refine_m_ is narrower than the contours' shortest pieces (contour_points)
// and than anything the mesh resolves: it is not cut in (see TinTerrain::resolves).
constexpr double kResolvedWidth = 0.25;

// Step 1e keeps redundant vertices at least this fraction of refine_m_ from the others
// (keep_resolving_vertices). Removing every one emptied the tool's floor, and the sand sliding
// in from the walls then split its edges again (trench.toml: 23 removals and 42 splits a
// step). Measured on trench.toml, trench_azimuth.toml at 4 azimuths and flat_stroke.toml
// (callgrind, the strokes' steps): 9 % fewer instructions at 0.5, 5 % at 0.35, none at 0.7.
constexpr double kRedundantSpacing = 0.5;

}  // namespace

double TinTerrain::drop_stale_constraints(std::uint32_t generation, std::vector<VertexHandle>& region_vertices) {
  region_vertices.clear();
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
  for (const auto& [a, b] : stale) box = united(box, bounds(std::vector<Vec2>{xy(a), xy(b)}));
  const double extent = std::max(domain_.size_m.x(), domain_.size_m.y());
  Capture capture = begin_capture(box.expanded(4.0 * spec_.snap_m + 1e-9 * extent));
  for (const auto& [a, b] : stale) unconstrain(a, b);
  // Only where the volume change is given back: the removals change the surface.
  if (spec_.conserve_volume) thin_passed_contours(stale);
  const CaptureResult measured = end_capture(capture, &region_vertices);
  for (VertexHandle v : region_vertices) forget_caches(v);
  // The flips change edges, not heights: only vertices by a steep face can erode now.
  for (VertexHandle v : region_vertices) {
    if (next_to_steep_face(v)) touch(v);
    add_to_simplify(v);
  }
  // The flips that restore the Delaunay property change the surface a little: the caller
  // gives the volume back with the stamp's deposit.
  return measured.delta();
}

void TinTerrain::thin_passed_contours(const std::vector<std::pair<VertexHandle, VertexHandle>>& stale) {
  // O and I lie a contour gap apart (5 % of the tool's radius), far below the mesh's edges
  // around them (refine_m_): once the stamp has passed, such a pair is two vertices with areas
  // tens of times below their neighbours', and a transfer is limited by the smaller area, so
  // sand crossed the old wall only slowly (a tool deeper than the bed on flat_stroke.toml:
  // 794k settling visits; trench.toml: the step's erosion). The upper vertex of each pair (the
  // wall's top) goes; the lower keeps the trench's floor and wall foot.
  std::vector<VertexHandle> ends;
  ends.reserve(2 * stale.size());
  for (const auto& [a, b] : stale) {
    ends.push_back(a);
    ends.push_back(b);
  }
  std::sort(ends.begin(), ends.end(), by_position);
  ends.erase(std::unique(ends.begin(), ends.end()), ends.end());
  const std::uint32_t on_contour = next_vertex_epoch();
  for (VertexHandle v : ends) v->info().mark = on_contour;
  const double crowded2 = kPassedContourSpacing * kPassedContourSpacing * refine_m_ * refine_m_;
  std::vector<VertexHandle> tops;
  for (VertexHandle v : ends) {
    if (v->info().border) continue;
    bool top = false;
    auto c = cdt_.incident_vertices(v), done = c;
    do {
      top = !cdt_.is_infinite(c) && c->info().mark == on_contour && c->point().z() < v->point().z() &&
            (xy(c) - xy(v)).squaredNorm() < crowded2;
    } while (!top && ++c != done);
    if (top) tops.push_back(v);
  }
  // In position order (the order shapes the retriangulation; see by_position).
  for (VertexHandle v : tops) remove_vertex(v);
}

void TinTerrain::spread_volume(const std::vector<VertexHandle>& vertices, double volume) {
  double total = 0.0;
  for (VertexHandle v : vertices) total += cached_area(v);
  if (volume == 0.0 || !(total > 0.0)) return;
  // Raising every vertex by the same dz changes the volume by dz times their areas' sum.
  const double dz = volume / total;
  for (VertexHandle v : vertices) {
    shift_z(v, v->point().z() + dz, cached_area(v));
    touch_with_neighbours(v);
    add_to_simplify(v);
  }
}

void TinTerrain::release_passed_stamps() {
  if (generations_.empty()) return;
  std::vector<VertexHandle> region;
  const double delta = drop_stale_constraints(std::numeric_limits<std::uint32_t>::max(), region);
  volume_change_ += delta;
  if (spec_.conserve_volume) spread_volume(region, -delta);
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
  volume_change_ = 0.0;
  // The pile the stamp before left: this stamp carries it on or not, and leaves its own or none.
  const CarriedPileOrigin carried_origin = std::exchange(carried_origin_, CarriedPileOrigin{});
  const std::vector<std::pair<Vec2, double>> carried = std::exchange(carried_, {});
  std::vector<VertexHandle> stale_region;
  const double unconstrained = drop_stale_constraints(s.generation, stale_region);
  volume_change_ += unconstrained;
  stale_delta_ = spec_.conserve_volume ? unconstrained : 0.0;
  if (s.is_pour()) return pour(s);
  StampReport report;
  StampWork w;
  if (!plan_stamp(s, w)) {  // off the domain: no deposit to give the flips' change back with
    spread_volume(stale_region, -stale_delta_);
    report.volume_change_m3 = volume_change_;
    return report;
  }
  // What a carrying stamp picks up lies outside the footprint: taken before the stamp's
  // retriangulation, which removes old vertices just outside it (1e) and with them the record
  // of the sand they carried (the grids' cut leaves the nodes outside alone). Outside any capture.
  const double picked = pick_up_carried(w, carried_origin, carried);
  if (w.cut) {
    contour_points(w);  // 1a
    find_constraints_near(w);
  }

  // Everything the stamp changes lies in this box: O, the rim band, the dropped constraints.
  Capture capture = begin_capture(w.region.expanded(w.margin));
  if (w.cut) {
    for (const auto& [a, b] : w.dropped) unconstrain(a, b);
    insert_stamp_vertices(w, report);
    constrain_contours(w);  // 1b, 1c
  }
  lower_to_tool(w);                        // 1d
  if (w.cut) remove_redundant(w, report);  // 1e

  // The retriangulation's own volume change (flips, removals of non-planar vertices).
  std::vector<VertexHandle> region_vertices;
  const CaptureResult measured = end_capture(capture, &region_vertices);
  volume_change_ += measured.delta();
  const double surface_change = measured.delta() + w.lowered_volume;
  // Constraint changes retriangulate inside the region, beyond the inserted vertices' stars.
  for (VertexHandle v : region_vertices) forget_caches(v);
  // The carried pile's vertices the retriangulation kept changed height (the removed ones' faces
  // are the region's).
  for (const Vec2& p : w.picked_up)
    if (const Location loc = locate(p); loc.type == Cdt::VERTEX) w.changed.push_back(loc.face->vertex(loc.index));

  // 1d (cont.): the displaced volume, and what the retriangulation changed (tin.conserve_volume).
  const double deposit = picked + w.lowered_volume - (spec_.conserve_volume ? surface_change : 0.0) - stale_delta_;
  // (An uncut stamp that lowered nothing leaves the mesh as it was: no rim to refine.)
  report.volume_deposited_m3 = w.cut || deposit != 0.0 ? deposit_on_rim(w, deposit, report) : 0.0;
  activate(w, region_vertices);  // 1f
  report.volume_removed_m3 = w.lowered_volume + picked;
  report.elements_touched = measured.faces_after;
  report.volume_change_m3 = volume_change_;
  return report;
}

bool TinTerrain::plan_stamp(const ToolStamp& s, StampWork& w) {
  if (s.footprint.size() < 3) throw InputError("stamp: the footprint needs at least 3 points");
  for (const Vec2& p : s.footprint)
    if (!p.allFinite()) throw InputError("stamp: the footprint has a non-finite point");
  if (!s.pose.xy.allFinite() || !std::isfinite(s.pose.bottom_z) || !std::isfinite(s.rim.width_m) ||
      !std::isfinite(s.rim.forward_bias) || !s.motion_dir.allFinite())
    throw InputError("stamp: the pose, rim and motion must be finite");
  if (s.profile == BottomProfile::SphereCap && !(s.sphere_radius_m > 0.0))
    throw InputError("stamp: a sphere-cap tool needs a positive sphere radius");
  const double extent = std::max(domain_.size_m.x(), domain_.size_m.y());
  w.tiny = 1e-12 * extent;
  w.tool = s;
  std::vector<Vec2>& footprint = w.tool.footprint;
  footprint = make_ccw(s.footprint);
  drop_near_duplicates(footprint, w.tiny);
  const double area = std::abs(signed_area(footprint));
  if (footprint.size() < 3 || !(area > 0.0)) throw InputError("stamp: the footprint has zero area");
  const bool convex = is_convex_polygon(footprint);
  if (convex) {
    const auto resolved = static_cast<std::size_t>(std::ceil(perimeter(footprint) / refine_m_));
    footprint = fewer_corners(footprint, corners_to_keep(footprint.size(), std::max(resolved, kMinSides), kMaxSides));
  } else if (!is_simple_polygon(footprint)) {
    // Its edges become constraints, which must not cross.
    throw InputError("stamp: the footprint must be a simple polygon (its edges cross)");
  }
  const double snap = spec_.snap_m;
  w.margin = 4.0 * snap + 1e-9 * extent;
  w.bound_footprint();
  w.cut = resolves(footprint);
  if (!w.cut) {  // lowered vertex by vertex (lower_to_tool, deposit_on_rim): no contours
    w.region = intersection(w.tool.influence_bounds(), box_);
    return (w.region.lo.array() <= w.region.hi.array()).all();
  }
  const double radius = std::sqrt(area / std::numbers::pi);
  w.gap = std::max(spec_.contour_gap_m > 0.0 ? spec_.contour_gap_m : 0.05 * radius, 16.0 * snap + 1e-9 * extent);

  // O: the footprint offset outwards. A thin non-convex footprint may need a smaller gap.
  w.outer = offset_polygon(footprint, w.gap);
  for (int tries = 0; !convex && !is_simple_polygon(w.outer); ++tries) {
    if (tries == 8) throw InputError("stamp: the footprint is too thin for the contour gap (tin.contour_gap_m)");
    w.gap *= 0.5;
    w.outer = offset_polygon(footprint, w.gap);
  }
  w.outer_clip = clip_to_box(w.outer, box_);
  w.inner_clip = clip_to_box(footprint, box_);
  // Where the contours cross the border, stamps that follow each other along a stroke leave
  // border vertices at arbitrary distances. A border vertex a hair from the next has a tiny
  // area, which throttles every transfer through it (a transfer is limited by the smaller
  // area), so the slopes there settled only after millions of passes. A crossing within a
  // quarter gap of an existing border vertex takes that vertex's place instead; O and I,
  // at least a gap apart along the border, stay apart.
  snap_border_crossings(w.outer_clip, 0.25 * w.gap);
  snap_border_crossings(w.inner_clip, 0.25 * w.gap);
  drop_near_duplicates(w.outer_clip, 2.0 * snap + w.tiny);
  drop_near_duplicates(w.inner_clip, 2.0 * snap + w.tiny);
  if (w.outer_clip.size() < 3 || !(std::abs(signed_area(w.outer_clip)) > 0.0)) return false;
  if (w.inner_clip.size() < 3 || !(std::abs(signed_area(w.inner_clip)) > 0.0)) w.inner_clip.clear();
  return true;
}

bool TinTerrain::resolves(const std::vector<Vec2>& footprint) const {
  // A 0.4 mm box on flat_stroke.toml (7 mm edges) was cut in as 8 vertices a hair apart and a
  // hole a hundred times deeper than wide, which erosion then filled on the coarse mesh: 58x
  // the grid's time, and farther from a 0.1 mm grid's surface (61 um rms around the stroke)
  // than the flat sand it leaves uncut (6 um; a 1.7 mm box: 89 against 40 um, a 4 mm one,
  // which is cut, 197 against 94). A smaller tin.refine_m resolves such a tool.
  return 4.0 * std::abs(signed_area(footprint)) >= kResolvedWidth * refine_m_ * perimeter(footprint);
}

int TinTerrain::long_edge_pieces(const Vec2& a, const Vec2& b) const {
  // A contour edge much longer than the mesh's edges (a box's or a polygon's side; a disk's
  // sides are about refine_m_ long) is cut into equal pieces of at most refine_m_, on O and on I
  // alike: else the band between them, a gap wide, is triangulated by slivers as long as the
  // edge, whose splits land beside the contours (a 0.2 m spike swept sideways on
  // flat_stroke.toml settled after 29 M visits of a mesh full of sub-millimetre slivers).
  const double length = (b - a).norm();
  return length > 2.0 * refine_m_ ? static_cast<int>(std::ceil(length / refine_m_)) : 1;
}

void TinTerrain::contour_points(StampWork& w) const {
  // O's heights from the terrain, subdivided (recursively, at midpoints) where the terrain
  // along an edge is not linear within tin.tolerance_m.
  const double snap = spec_.snap_m, tiny = w.tiny;
  const double step = spec_.contour_subdivision_m;
  const double tol = spec_.tolerance_m;
  // Pieces no shorter than the gap between O and I, nor than a quarter of refine_m_: finer
  // O vertices (where O crosses an old stamp's steep wall) would have areas hundreds of times
  // below their neighbours', and a transfer is limited by the smaller area, so the wall would
  // settle only after thousands of passes (a tool deeper than the bed: 7900 settling passes
  // at the old floor of 8 snaps, and settling 0.53 s -> 0.23 s -> 0.17 s with these floors).
  const double shortest = std::max({8.0 * snap + 16.0 * tiny, w.gap, 0.25 * refine_m_});
  auto refine = [&](auto&& self, const Vec2& a, double za, const Vec2& b, double zb, int depth) -> void {
    const Vec2 m = 0.5 * (a + b);
    if (depth >= 8 || (b - a).norm() < shortest) return;
    const double zm = surface_height(m);
    if (std::abs(zm - 0.5 * (za + zb)) <= tol) return;
    self(self, a, za, m, zm, depth + 1);
    w.o_pts.push_back({m, zm});
    self(self, m, zm, b, zb, depth + 1);
  };
  const std::size_t n = w.outer_clip.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2 a = w.outer_clip[i], b = w.outer_clip[(i + 1) % n];
    const double za = surface_height(a);
    w.o_pts.push_back({a, za});
    if (on_same_box_side(a, b, box_)) continue;
    const int pieces =
        std::max(step > 0.0 ? static_cast<int>(std::ceil((b - a).norm() / step)) : 1, long_edge_pieces(a, b));
    Vec2 pa = a;
    double zpa = za;
    for (int k = 1; k <= pieces; ++k) {
      const Vec2 pb = k == pieces ? b : Vec2(a + (b - a) * (static_cast<double>(k) / pieces));
      const double zpb = surface_height(pb);
      refine(refine, pa, zpa, pb, zpb, 0);
      if (k < pieces) w.o_pts.push_back({pb, zpb});
      pa = pb;
      zpa = zpb;
    }
  }

  // I (at the terrain's height until 1d lowers it); interior points for a curved bottom.
  const ToolStamp& s = w.tool;
  const std::vector<Vec2>& footprint = s.footprint;
  const std::size_t ni = w.inner_clip.size();
  for (std::size_t i = 0; i < ni; ++i) {
    const Vec2 a = w.inner_clip[i], b = w.inner_clip[(i + 1) % ni];
    w.i_pts.push_back({a, surface_height(a)});
    if (on_same_box_side(a, b, box_)) continue;
    const int pieces = long_edge_pieces(a, b);
    for (int k = 1; k < pieces; ++k) {
      const Vec2 p = a + (b - a) * (static_cast<double>(k) / pieces);
      w.i_pts.push_back({p, surface_height(p)});
    }
  }
  if (s.profile == BottomProfile::SphereCap && !w.inner_clip.empty()) {
    for (double t : {0.75, 0.5, 0.25}) {
      for (const Vec2& f : footprint) {
        const Vec2 p = s.pose.xy + t * (f - s.pose.xy);
        if (box_.contains(p) && s.contains(p) && distance_to_boundary(footprint, p) > w.gap)
          w.interior_pts.push_back({p, surface_height(p)});
      }
    }
    if (box_.contains(s.pose.xy) && s.contains(s.pose.xy))
      w.interior_pts.push_back({s.pose.xy, surface_height(s.pose.xy)});
  }

  // Rim vertices where the band has none nearby: a ring in the band's middle to take the
  // deposit, and a ring on its outer edge so the deposit stays in the band (on a coarse TIN
  // a raised vertex would otherwise spread sand thinly over triangles reaching far away).
  // (A bulldozing stamp's pile gets vertices of its own: fill_pile_lattice.)
  if (s.rim.width_m > w.gap && !s.bulldozes()) {
    for (double offset : {0.5 * (w.gap + s.rim.width_m), s.rim.width_m}) {
      const std::vector<Vec2> ring = offset_polygon(footprint, offset);
      const double needed = 0.5 * perimeter(ring) / static_cast<double>(ring.size());
      for (const Vec2& p : ring) {
        if (!box_.contains(p) || point_in_polygon(w.outer, p) || s.rim_weight(p) <= 0.0) continue;
        const Location loc = locate(p);
        bool has_near = false;
        for (int i = 0; i < 3; ++i) has_near = has_near || (xy(loc.face->vertex(i)) - p).norm() < needed;
        if (!has_near) w.rim_pts.push_back({p, interpolate(loc.face, p)});
      }
    }
  }
}

void TinTerrain::find_constraints_near(StampWork& w) {
  // Old constraints within reach of O are dropped (whatever their generation): afterwards no
  // old constraint can touch or cross the new ones, which all lie inside O. The reach extends
  // a gap beyond O, where old vertices are cleared (insert_stamp_vertices) so that repeated
  // stamps at one spot (or turning ones) do not pile up contour vertices just outside each other.
  const double clearance = w.gap;
  w.reach = bounds(w.outer_clip).expanded(clearance + w.margin);
  const Aabb2& reach = w.reach;
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
        if (segment_near_polygon(xy(a), xy(b), w.outer_clip, clearance + w.margin)) w.dropped.emplace_back(a, b);
      }
      const FaceHandle n = f->neighbor(i);
      if (cdt_.is_infinite(n) || n->info() == walked) continue;
      if (!face_overlaps(n, reach)) continue;
      n->info() = walked;
      faces.push_back(n);
    }
  }
  // Ordered by position, not address: the order they are unconstrained in shapes the mesh,
  // and addresses depend on the heap's layout (a run must not).
  auto& dropped = w.dropped;
  for (auto& [a, b] : dropped)
    if (by_position(b, a)) std::swap(a, b);
  std::sort(dropped.begin(), dropped.end(), [](const auto& x, const auto& y) {
    return by_position(x.first, y.first) || (x.first == y.first && by_position(x.second, y.second));
  });
  dropped.erase(std::unique(dropped.begin(), dropped.end()), dropped.end());

  w.region = united(reach, intersection(w.tool.influence_bounds(), box_));
  for (const ContourPoint& r : w.rim_pts) w.region = united(w.region, Aabb2{r.p, r.p});
  for (const auto& [a, b] : dropped) w.region = united(w.region, bounds(std::vector<Vec2>{xy(a), xy(b)}));
}

void TinTerrain::insert_stamp_vertices(StampWork& w, StampReport& report) {
  // The stamp's own vertices (contours, interior) are kept by the removals below and in 1e.
  auto add = [&](const ContourPoint& c) {
    bool inserted = false;
    const VertexHandle v = insert_point(c.p, c.z, &inserted);
    if (inserted) {
      ++report.vertices_inserted;
      w.fresh.push_back(v);
    }
    return v;
  };
  for (const ContourPoint& c : w.o_pts) w.o_verts.push_back(add(c));
  for (const ContourPoint& c : w.i_pts) w.i_verts.push_back(add(c));
  for (const ContourPoint& c : w.interior_pts) w.own.push_back(&*add(c));
  for (const ContourPoint& c : w.rim_pts) add(c);
  for (VertexHandle v : w.o_verts) w.own.push_back(&*v);
  for (VertexHandle v : w.i_verts) w.own.push_back(&*v);
  std::sort(w.own.begin(), w.own.end());

  // Old vertices between I and O would bend the wall, and those just outside O would crowd
  // it: removed.
  const double clearance = w.gap;
  collect_vertices(w.reach, vertex_scratch_);
  std::vector<VertexHandle> band;
  for (VertexHandle v : vertex_scratch_) {
    const Vec2 p = xy(v);
    if (w.is_own(v) || v->info().border || w.in_footprint(p) || has_constraints(v)) continue;
    const double to_outer = distance_to_boundary(w.outer_clip, p);
    if (to_outer <= w.tiny) continue;
    if (point_in_polygon(w.outer_clip, p) || to_outer < clearance) band.push_back(v);
  }
  for (VertexHandle v : band) {
    remove_vertex(v);
    ++report.vertices_removed;
  }
  std::erase_if(w.fresh, [&band](VertexHandle v) { return std::find(band.begin(), band.end(), v) != band.end(); });
}

void TinTerrain::constrain_contours(const StampWork& w) {
  // O constrained first, then I; edges along the domain border stay unconstrained.
  auto constrain_ring = [&](const std::vector<VertexHandle>& ring) {
    if (ring.size() < 3) return;
    for (std::size_t k = 0; k < ring.size(); ++k) {
      const VertexHandle a = ring[k], b = ring[(k + 1) % ring.size()];
      if (a == b || on_same_box_side(xy(a), xy(b), box_)) continue;
      constrain(a, b, w.tool.generation);
    }
  };
  constrain_ring(w.o_verts);
  constrain_ring(w.i_verts);
}

void TinTerrain::lower_to_tool(StampWork& w) {
  // Heights inside lowered to the tool; the volume taken is exact (barycentric areas).
  const Aabb2 footprint_box = intersection(bounds(w.tool.footprint).expanded(w.margin), box_);
  collect_vertices(footprint_box, vertex_scratch_);
  for (VertexHandle v : vertex_scratch_) {
    const Vec2 p = xy(v);
    if (!w.in_footprint(p)) continue;
    w.inside.push_back(v);
    const double z = v->point().z(), tool = w.bottom(p);
    if (z > tool) {
      w.lowered_volume += (z - tool) * vertex_area(v);
      set_z(v, tool);
      w.changed.push_back(v);
    }
  }
}

void TinTerrain::remove_redundant(StampWork& w, StampReport& report) {
  // Redundant inner vertices: at tool level, not on the footprint's border or the domain's,
  // no deeper neighbour.
  const ToolStamp& s = w.tool;
  const double level_eps = 1e-9 * std::max(1.0, std::abs(s.pose.bottom_z));
  std::vector<VertexHandle> redundant;
  for (VertexHandle v : w.inside) {
    const Vec2 p = xy(v);
    if (w.is_own(v) || v->info().border || has_constraints(v)) continue;
    if (!w.deep_inside(p) && distance_to_boundary(s.footprint, p) <= w.tiny) continue;
    if (std::abs(v->point().z() - w.bottom(p)) > level_eps) continue;
    bool deeper = false;
    auto c = cdt_.incident_vertices(v), done = c;
    do {
      if (cdt_.is_infinite(c)) continue;
      const Vec2 q = xy(c->point());
      const double tool = w.in_footprint(q) ? w.bottom(q) : std::max(s.pose.bottom_z, 0.0);
      deeper = deeper || c->point().z() < tool - level_eps;
    } while (++c != done && !deeper);
    if (!deeper) redundant.push_back(v);
  }
  // Removed in position order (the order shapes the retriangulation; see by_position).
  std::sort(redundant.begin(), redundant.end(), by_position);
  // Only where the volume change is given back: a kept vertex that a later stamp removes off
  // the floor changes the surface (the paper's model removes every redundant vertex).
  if (spec_.conserve_volume) keep_resolving_vertices(redundant);
  for (VertexHandle v : redundant) {
    remove_vertex(v);
    ++report.vertices_removed;
  }
  auto removed = [&](VertexHandle v) { return std::binary_search(redundant.begin(), redundant.end(), v, by_position); };
  std::erase_if(w.changed, removed);
  std::erase_if(w.fresh, removed);
}

void TinTerrain::keep_resolving_vertices(std::vector<VertexHandle>& redundant) {
  // A redundant vertex goes only where a vertex that stays lies within kRedundantSpacing
  // refine_m_ of it: the floor keeps a vertex about every half refine_m_ (the finest edge the
  // mesh makes elsewhere, tin.refine_min_m's default), the resolution erosion would split it
  // back to as soon as sand slides in from the walls. Greedy in the list's order: the kept
  // ones end at least that far apart, and every removed one that close to one that stays.
  const double near = kRedundantSpacing * refine_m_, near2 = near * near;
  const std::uint32_t candidate = next_vertex_epoch();
  for (VertexHandle v : redundant) v->info().mark = candidate;
  // The kept candidates by cell of side `near`: any point within `near` of p lies in p's cell
  // or one of the 8 around it.
  std::unordered_map<std::uint64_t, std::vector<Vec2>> kept;
  const auto cell_of = [near](const Vec2& p) {
    return std::array<std::int64_t, 2>{static_cast<std::int64_t>(std::floor(p.x() / near)),
                                       static_cast<std::int64_t>(std::floor(p.y() / near))};
  };
  const auto key = [](std::int64_t i, std::int64_t j) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(i)) << 32) | static_cast<std::uint32_t>(j);
  };
  const auto stays = [&](VertexHandle v) {
    const Vec2 p = xy(v);
    // Other vertices that stay are in v's star (the contours, the mesh outside the floor).
    auto c = cdt_.incident_vertices(v), done = c;
    do {
      if (!cdt_.is_infinite(c) && c->info().mark != candidate && (xy(c) - p).squaredNorm() < near2) return false;
    } while (++c != done);
    const auto [i, j] = cell_of(p);
    for (std::int64_t di = -1; di <= 1; ++di)
      for (std::int64_t dj = -1; dj <= 1; ++dj) {
        const auto it = kept.find(key(i + di, j + dj));
        if (it == kept.end()) continue;
        for (const Vec2& q : it->second)
          if ((q - p).squaredNorm() < near2) return false;
      }
    kept[key(i, j)].push_back(p);
    return true;
  };
  std::erase_if(redundant, stays);
}

double TinTerrain::deposit_on_rim(StampWork& w, double deposit, StampReport& report) {
  if (w.tool.bulldozes() && deposit > 0.0 && deposit_front_pile(w, deposit, report)) return deposit;
  // Weighted by the common rule. The band's vertices first get short edges (refine_around),
  // so the sand stays in the band.
  // A weight costs O(footprint corners): each vertex's is computed once, kept by address for
  // the second collection (which adds the refinement's vertices), looked up, never iterated.
  const Aabb2 band_box = intersection(w.tool.influence_bounds(), box_);
  collect_vertices(band_box, vertex_scratch_);
  std::vector<VertexHandle> band_vertices;
  std::vector<std::pair<const void*, double>> known;
  known.reserve(vertex_scratch_.size());
  for (VertexHandle v : vertex_scratch_) {
    known.emplace_back(&*v, w.rim_weight(xy(v)));
    if (known.back().second > 0.0) band_vertices.push_back(v);
  }
  std::sort(known.begin(), known.end());
  for (VertexHandle v : band_vertices) report.vertices_inserted += refine_around(v);
  collect_vertices(band_box, vertex_scratch_);
  std::vector<std::pair<VertexHandle, double>> targets;
  double weight_sum = 0.0;
  for (VertexHandle v : vertex_scratch_) {
    const auto it = std::lower_bound(known.begin(), known.end(), std::pair<const void*, double>(&*v, -HUGE_VAL));
    const double weight = it != known.end() && it->first == &*v ? it->second : w.rim_weight(xy(v));
    if (weight <= 0.0) continue;
    // (The stamp forgot the region's cached areas before this, and the refinement its stars'.)
    const double wa = weight * cached_area(v);
    targets.emplace_back(v, wa);
    weight_sum += wa;
  }
  if (!(weight_sum > 0.0)) {  // the band is off the domain, has no area or no vertex: use O
    targets.clear();
    for (VertexHandle v : w.cut ? w.o_verts : nearest_outside(w)) {
      const double a = vertex_area(v);
      targets.emplace_back(v, a);
      weight_sum += a;
    }
  }
  if (!(weight_sum > 0.0) || deposit == 0.0) return 0.0;
  for (const auto& [v, wa] : targets) {
    const double a = cached_area(v);
    if (a <= 0.0) continue;
    shift_z(v, v->point().z() + deposit * (wa / weight_sum) / a, a);
    w.changed.push_back(v);
  }
  return deposit;
}

std::vector<VertexHandle> TinTerrain::nearest_outside(const StampWork& w) {
  // An uncut footprint is narrower than the mesh's edges, and its rim band (a fraction of its
  // size) often holds no vertex: the sand goes to the nearest ring of vertices outside the
  // footprint around the lowered ones (as the grid widens its band to the nearest nodes).
  std::vector<VertexHandle> frontier = w.changed, found;
  const std::uint32_t seen = next_vertex_epoch();
  if (frontier.empty()) {  // nothing lowered (the deposit gives back old flips): from the pose's face
    const FaceHandle f = locate(clamp_to_domain(w.tool.pose.xy)).face;
    for (int i = 0; i < 3; ++i) {
      const VertexHandle v = f->vertex(i);
      if (cdt_.is_infinite(v)) continue;
      v->info().mark = seen;
      (w.in_footprint(xy(v)) ? frontier : found).push_back(v);
    }
  }
  for (VertexHandle v : frontier) v->info().mark = seen;
  while (found.empty() && !frontier.empty()) {  // each round a ring further out: ends
    std::vector<VertexHandle> next;
    for (VertexHandle v : frontier) {
      auto c = cdt_.incident_vertices(v), done = c;
      do {
        if (cdt_.is_infinite(c) || c->info().mark == seen) continue;
        c->info().mark = seen;
        (w.in_footprint(xy(c)) ? next : found).push_back(c);
      } while (++c != done);
    }
    frontier.swap(next);
  }
  if (found.empty()) found = w.changed;  // no vertex outside the footprint: the sand stays
  std::sort(found.begin(), found.end(), by_position);
  return found;
}

bool TinTerrain::next_to_steep_face(VertexHandle v) const {
  // A face's gradient is |(n_x, n_y)| / |n_z| for its normal n = (b - a) x (c - a).
  const double tan2 = tan_critical_ * tan_critical_;
  auto f = cdt_.incident_faces(v), done = f;
  do {
    if (cdt_.is_infinite(f)) continue;
    const Point &a = f->vertex(0)->point(), &b = f->vertex(1)->point(), &c = f->vertex(2)->point();
    const double ux = b.x() - a.x(), uy = b.y() - a.y(), uz = b.z() - a.z();
    const double vx = c.x() - a.x(), vy = c.y() - a.y(), vz = c.z() - a.z();
    const double nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
    if (nx * nx + ny * ny > tan2 * nz * nz) return true;
  } while (++f != done);
  return false;
}

void TinTerrain::activate(const StampWork& w, const std::vector<VertexHandle>& region_vertices) {
  // A changed height changes the drops to all neighbours; elsewhere in the region only the
  // edges changed (flips, insertions, removals), which matters where a face is steep.
  for (VertexHandle v : w.changed) {
    touch_with_neighbours(v);
    add_to_simplify(v);
  }
  for (VertexHandle v : region_vertices)
    if (next_to_steep_face(v)) touch(v);
  for (VertexHandle v : w.fresh) add_to_simplify(v);
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
  std::vector<Pending> pending{{centre, surface_height(centre)}};
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
  volume_change_ += measured.delta();

  // The volume lands as a cone of the pour radius (weights 1 - d / r times vertex areas), on
  // vertices with short edges (refine_around), so the sand stays within the radius.
  const double volume = s.pour_volume_m3 - (spec_.conserve_volume ? measured.delta() : 0.0) - stale_delta_;
  const Aabb2 reach = intersection(Aabb2{centre, centre}.expanded(radius), box_);
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
    const double a = cached_area(v);
    if (a <= 0.0) continue;
    shift_z(v, v->point().z() + volume * (wa / weight_sum) / a, a);
    touch_with_neighbours(v);
    add_to_simplify(v);
  }
  for (VertexHandle v : region_vertices) touch(v);
  for (VertexHandle v : fresh) add_to_simplify(v);
  report.volume_deposited_m3 = weight_sum > 0.0 ? volume : 0.0;
  report.elements_touched = measured.faces_after;
  report.volume_change_m3 = volume_change_;
  return report;
}

}  // namespace sb::tin::detail
