#pragma once
// Private to tin/*.cpp: the CGAL types and the TinTerrain class that implements Terrain.
// Including this header costs ~20 s of compile time per translation unit (it is the
// precompiled header of sb_tin), so only the handful of tin/*.cpp files include it.
#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Projection_traits_xy_3.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <cstdint>
#include <functional>
#include <span>
#include <unordered_map>
#include <vector>

#include "common/front_pile.hpp"
#include "common/height_field.hpp"
#include "common/scene.hpp"
#include "common/terrain.hpp"
#include "tin/detail/change_cells.hpp"

namespace sb::tin::detail {

inline constexpr std::uint32_t kNoSlot = 0xffffffffu;

// Per-vertex bookkeeping, 24 bytes.
struct VertexInfo {
  // Barycentric area (one third of the incident triangles' areas), cached for erosion, which
  // needs it for every neighbour of every vertex it visits; < 0 when the star changed since.
  double area = -1.0;
  std::uint32_t erosion_slot = kNoSlot;   // index in L_e, or kNoSlot
  std::uint32_t simplify_slot = kNoSlot;  // index in L_r, or kNoSlot
  std::uint32_t mark = 0;                 // traversal epoch (see TinTerrain::next_vertex_epoch)
  std::uint16_t idle = 0;                 // erosion visits without a transfer
  std::uint8_t border : 1 = 0;            // on the domain boundary: never removed
  std::uint8_t display_pending : 1 = 0;   // its height changed since a display last asked (TinTerrain::set_z)
  std::uint8_t short_edges = 0;           // 1: no edge longer than refine_m_ (valid with area)
};

// A face's traversal epoch (or, while building, its sample bucket + 1). A class so that new
// faces start at 0: CGAL default-initializes face info, which leaves a bare integer undefined.
struct FaceMark {
  std::uint32_t value = 0;
  FaceMark& operator=(std::uint32_t v) {
    value = v;
    return *this;
  }
  operator std::uint32_t() const { return value; }
};

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Traits = CGAL::Projection_traits_xy_3<Kernel>;
using VertexBase = CGAL::Triangulation_vertex_base_with_info_2<VertexInfo, Traits>;
// The face's mark goes last, into the padding after the constraint flags: 56 bytes a face
// (the other order pads to 64).
using FaceBase =
    CGAL::Triangulation_face_base_with_info_2<FaceMark, Traits, CGAL::Constrained_triangulation_face_base_2<Traits>>;
using Tds = CGAL::Triangulation_data_structure_2<VertexBase, FaceBase>;
// Constraints may pass through existing vertices but never cross each other: the stamp drops
// every old constraint near a new one first, so no intersection point is ever constructed
// (the input that trips CGAL issues 2999, 3263 and 5439 cannot arise).
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<Traits, Tds,
                                                       CGAL::No_constraint_intersection_requiring_constructions_tag>;
using Point = Kernel::Point_3;
using VertexHandle = Cdt::Vertex_handle;
using FaceHandle = Cdt::Face_handle;

// An entry of the erosion list L_e: the vertex, and where its ring is cached in
// TinTerrain::ring_pool_ (its neighbours in the order gather_neighbours walks them, infinite
// vertex left out). The ring is current while ring_size > 0: every change of v's star clears it
// (TinTerrain::forget_caches), its slot in the pool stays for the next fill. 16 bytes.
struct ErosionEntry {
  VertexHandle vertex;
  std::uint32_t ring = kNoSlot;  // offset in ring_pool_, or kNoSlot
  std::uint16_t ring_size = 0;   // 0: not current
  std::uint16_t ring_capacity = 0;
};

// An undirected edge by its two vertices (ordered by address).
struct EdgeKey {
  const void* a;
  const void* b;
  EdgeKey(VertexHandle u, VertexHandle v) {
    const void* pu = &*u;
    const void* pv = &*v;
    a = pu < pv ? pu : pv;
    b = pu < pv ? pv : pu;
  }
  bool operator==(const EdgeKey& o) const { return a == o.a && b == o.b; }
};
struct EdgeKeyHash {
  std::size_t operator()(const EdgeKey& k) const noexcept {
    const auto x = reinterpret_cast<std::uintptr_t>(k.a), y = reinterpret_cast<std::uintptr_t>(k.b);
    return static_cast<std::size_t>((x * 0x9E3779B97F4A7C15ull) ^ (y + 0x632BE59BD9B4E019ull + (x << 6) + (x >> 2)));
  }
};

struct Location {
  FaceHandle face;
  Cdt::Locate_type type = Cdt::FACE;
  int index = 0;  // vertex index for VERTEX, opposite vertex of the edge for EDGE
};

// The faces an operation may change, captured before it so that the volume change of the
// retriangulation can be measured after it. The region is every face whose circumcircle
// meets `box`; faces outside it are untouched by insertions, constraint changes and vertex
// removals inside `box` (the constrained Delaunay triangulation only changes where
// visibility or circumcircles change), so the region before and after covers the same area.
struct OuterFace {
  FaceHandle face;
  const void* vertices[3];  // to tell the face from a new one in its recycled slot
  int toward = 0;           // index of the neighbour inside the region
};
struct Capture {
  std::vector<OuterFace> outer;  // finite faces just outside the region, in discovery order
  double volume = 0.0;           // integral of z over the region before
  double area = 0.0;
  std::size_t faces = 0;
};
struct CaptureResult {
  double volume_before = 0.0, volume_after = 0.0;
  double area_before = 0.0, area_after = 0.0;
  std::size_t faces_after = 0;
  double delta() const { return volume_after - volume_before; }
};

struct StampWork;  // stamp_work.hpp

// What a TIN is built from: the scene's domain and [tin] section, and the few values of its
// other sections the model needs (tin_options picks them from a Scene), nothing else (no
// haptics, no output settings).
struct TinOptions {
  DomainSpec domain;
  TinSpec tin;
  int idle_passes = 1;                // [erosion] idle_passes
  double settle_tolerance_deg = 0.0;  // [erosion] settle_tolerance_deg
  Material material;
  double tool_radius_m = 0.0;  // the tool's characteristic radius (tool_radius)
  TerrainKind kind = TerrainKind::Flat;
  double base_height_m = 0.0;  // [terrain] height_m
};
TinOptions tin_options(const Scene& scene);  // build.cpp

// The edge length erosion refines to when tin.refine_m is 0: 4 tin.tolerance_m / tan(critical
// angle), at most 5 % of the domain (build.cpp).
double default_refine_m(const TinOptions& o);

class TinTerrain final : public Terrain {
 public:
  explicit TinTerrain(const TinOptions& o);
  void build_from_field(const HeightField& field);  // build.cpp
  // build.cpp; with `field`, the heights then become its projection (project_heights).
  void build_from_points(const std::vector<Vec3>& points, const HeightField* field = nullptr);
  // The vertices' heights become the L2 projection of `field` onto the mesh (project.cpp):
  // the terrain's volume, a plane exactly. O(faces) plus a few dozen O(vertices) iterations.
  void project_heights(const HeightField& field);

  std::string_view name() const override { return "tin"; }
  double height(const Vec2& p) const override;                                         // mesh_ops.cpp
  StampReport stamp(const ToolStamp& s) override;                                      // stamp.cpp
  ErosionReport erode(const ErosionRule& rule, const ErosionBudget& budget) override;  // erosion.cpp
  SimplifyReport simplify(const SimplifyParams& params) override;                      // simplify.cpp
  double volume() const override;                                                      // stats_check.cpp
  ModelStats stats() const override;
  SurfaceMesh mesh() const override;
  void sample(Raster& out) const override;
  IntegrityReport check() const override;
  double max_slope_deg() const override;
  // display.cpp: the cells whose faces changed (ChangeCells), and the faces in a box.
  SurfaceChanges changes_since(std::uint64_t version) override;
  void surface_faces(const Aabb2& box, std::vector<Vec3>& out) const override;

 private:
  // mesh_ops.cpp: location, insertion, removal, constraints, lists, captures.
  // A walk's start and its random edge order (locate). Edits and queries keep apart ones: a
  // walk's end decides ties (a point on an edge, cocircular vertices), so with one walk the
  // runner's energy rasters, renders or haptic patches (height(), sample()) changed what the
  // next stamp built (pile.toml: RMSE 53.9 or 54.7 um with output.energy off or on).
  struct Walk {
    VertexHandle hint;
    std::uint32_t rng = 0x9E3779B9u;
  };
  FaceHandle start_face(const Walk& walk) const;
  Location locate(const Vec2& p, Walk& walk) const;
  // locate() and height() for the model's own edits (the stamp's contours, a split's middle):
  // the edits' walk. height() and sample() take query_walk_.
  Location locate(const Vec2& p) const { return locate(p, edit_walk_); }
  double surface_height(const Vec2& p) const { return height_by(p, edit_walk_); }
  double height_by(const Vec2& p, Walk& walk) const;
  double interpolate(FaceHandle f, const Vec2& p) const;
  Vec2 clamp_to_domain(const Vec2& p) const;
  bool on_border(const Vec2& p) const;
  // Inserts a vertex at p (snapped onto the border and onto vertices within tin.snap_m) with
  // height z, keeping generation records of a constrained edge it splits. `inserted` tells
  // whether a new vertex was made; `volume_change`, if given, receives the change of the
  // integral of z the insertion made (its Delaunay flips), measured over the faces it
  // replaced (conflict_region) and the new vertex's star: O(star), where a capture of the
  // surroundings costs O(region).
  VertexHandle insert_point(const Vec2& p, double z, bool* inserted = nullptr, double* volume_change = nullptr);
  // The finite faces an insertion of q (located at `loc`) replaces -- those whose circumcircle
  // contains q, reached without crossing a constrained edge (the faces on both sides of the
  // edge q lies on) -- with their integral of z, area, and squared bounding-box diagonal.
  // CGAL's flips after an insertion replace exactly these (its test_conflict, with the same
  // perturbed in-circle predicate). O(region).
  void conflict_region(const Point& q, const Location& loc, double& volume, double& area, double& extent2);
  // Removes an unconstrained, non-border vertex, keeping the lists and the hint valid.
  void remove_vertex(VertexHandle v);
  // remove_vertex for an interior vertex (link_scratch_: its neighbours, all finite): by
  // flips, with CGAL's removal finishing where its neighbours are collinear. O(degree^2).
  void remove_by_flips(VertexHandle v);
  void constrain(VertexHandle a, VertexHandle b, std::uint32_t generation);
  void unconstrain(VertexHandle a, VertexHandle b);
  // Gives every constrained edge without a generation record this generation. O(n).
  void record_unrecorded_constraints(std::uint32_t generation);
  bool has_constraints(VertexHandle v) const;
  double vertex_area(VertexHandle v) const;
  // A height write inside an open capture (begin_capture ... end_capture), which measures it.
  void set_z(VertexHandle v, double z);
  // A height write outside any capture: `area` is v's barycentric area now (the integral's
  // derivative in z_v), and area x (new - old z) joins volume_change_.
  void shift_z(VertexHandle v, double z, double area) {
    const double before = v->point().z();
    set_z(v, z);
    volume_change_ += area * (v->point().z() - before);
  }
  // The cached area (computed when stale); and forgetting the caches of v and its neighbours,
  // whose stars change when v's does. Every change of the triangulation goes through
  // insert_point, remove_vertex, or a stamp, which forget the caches of the region they touched.
  double cached_area(VertexHandle v) const {  // inline: erosion reads it for every neighbour
    VertexInfo& in = v->info();
    if (in.area < 0.0) in.area = vertex_area(v);
    return in.area;
  }
  void forget_star(VertexHandle v);
  // For a display (changes_): the faces in `box` changed; the faces around v changed (O(degree)
  // while a display tracks, else O(1)). Every edit of the triangulation or a height marks what
  // it changed: insert_point, remove_vertex (and its flips), end_capture (constraints), and
  // set_z, which only lists the vertex (display_pending_): erosion writes a vertex many times
  // between two display updates, and changes_since marks each listed vertex's star once.
  void mark_changed(const Aabb2& box) { changes_.mark(box); }
  void mark_star(VertexHandle v);
  void mark_pending_stars();
  // v's cached area, short-edge flag and ring forgotten: its star changed.
  void forget_caches(VertexHandle v) {
    VertexInfo& in = v->info();
    in.area = -1.0;
    in.short_edges = 0;
    if (in.erosion_slot != kNoSlot) erosion_list_[in.erosion_slot].ring_size = 0;
  }
  bool has_long_edges(VertexHandle v) const;
  Capture begin_capture(const Aabb2& box);
  CaptureResult end_capture(Capture& c, std::vector<VertexHandle>* region_vertices = nullptr);
  // Vertices inside `box` (a traversal of the faces overlapping it).
  void collect_vertices(const Aabb2& box, std::vector<VertexHandle>& out);
  // Calls visit(f) for every finite face overlapping `box` (closed), breadth first from the face
  // `walk` locates at `from` (a point in the box): the faces overlapping a convex box are
  // connected. `queue`: scratch. O(those faces).
  template <class Visit>
  void visit_faces_overlapping(const Aabb2& box, const Vec2& from, Walk& walk, std::vector<FaceHandle>& queue,
                               Visit&& visit) const;
  void touch(VertexHandle v) {  // joins L_e (idle count reset); inline: erosion's hottest call
    VertexInfo& in = v->info();
    in.idle = 0;
    if (in.erosion_slot != kNoSlot) return;
    in.erosion_slot = static_cast<std::uint32_t>(erosion_list_.size());
    erosion_list_.push_back(ErosionEntry{v});
  }
  void touch_with_neighbours(VertexHandle v) {  // v and its neighbours join L_e
    touch(v);
    for (VertexHandle w : ring_of(v)) touch(w);
  }
  // The finite neighbours of v, a vertex of L_e, counter-clockwise from v->face() (the order
  // of CGAL's vertex circulator): cached in ring_pool_ until v's star changes. O(1) amortized
  // when current, O(degree) to refill; the span lasts until the pool grows.
  std::span<const VertexHandle> ring_of(VertexHandle v) {
    const ErosionEntry& e = erosion_list_[v->info().erosion_slot];
    if (e.ring_size > 0) return {ring_pool_.data() + e.ring, e.ring_size};
    return fill_ring(v);
  }
  std::span<const VertexHandle> fill_ring(VertexHandle v);  // ring_of when not current
  // The live rings moved to a new pool of this capacity (at least what they need), the
  // garbage left behind. O(L_e + live rings).
  void compact_ring_pool(std::size_t capacity);
  void drop_from_erosion(VertexHandle v);
  void add_to_simplify(VertexHandle v);
  void drop_from_simplify(VertexHandle v);
  std::uint32_t next_face_epoch() const;
  std::uint32_t next_vertex_epoch();

  // stamp.cpp: the paper's steps 1a-1f, in the order stamp() takes them.
  // The footprint made ready (checked, cut to what the mesh resolves), the contours O and I
  // clipped to the domain; false when O misses the domain.
  bool plan_stamp(const ToolStamp& s, StampWork& w);
  // Whether the mesh resolves a footprint (its width against refine_m_), so it is cut in. O(corners).
  bool resolves(const std::vector<Vec2>& footprint) const;
  // The vertices outside an uncut footprint nearest to the ones it lowered (ring by ring).
  std::vector<VertexHandle> nearest_outside(const StampWork& w);
  void contour_points(StampWork& w) const;                   // 1a: O's heights, I, interior and rim points
  int long_edge_pieces(const Vec2& a, const Vec2& b) const;  // pieces of a contour edge (1: whole)
  void find_constraints_near(StampWork& w);                  // old constraints within reach of O (w.dropped)
  // The stamp's vertices inserted; old ones between I and O (and just outside O) removed.
  void insert_stamp_vertices(StampWork& w, StampReport& report);
  void constrain_contours(const StampWork& w);               // 1b, 1c
  void lower_to_tool(StampWork& w);                          // 1d
  void remove_redundant(StampWork& w, StampReport& report);  // 1e
  // Of 1e's redundant vertices (in position order), those that resolve the floor at half
  // refine_m_ are taken out of the list (kept in the mesh). O(their stars).
  void keep_resolving_vertices(std::vector<VertexHandle>& redundant);
  // 1d (cont.): `deposit` spread over the rim band, or a bulldozing stamp's front pile;
  // returns what was deposited.
  double deposit_on_rim(StampWork& w, double deposit, StampReport& report);
  // front_pile.cpp: a bulldozing stamp's deposit heaped ahead of it (common/front_pile.hpp);
  // false, and nothing changed, when no vertex lies ahead. O(lattice points in the pile's
  // region, each located) per widening of the region; one or two widenings are usual.
  bool deposit_front_pile(StampWork& w, double deposit, StampReport& report);
  // front_pile.cpp: what a carrying stamp keeps of the pile the stamp before it heaped
  // (carried_), taken from its vertices outside the footprint that are still there, before the
  // stamp's retriangulation removes any (their positions into w.picked_up); the volume taken
  // (written outside any capture). O(that pile's vertices, each located).
  double pick_up_carried(StampWork& w, const CarriedPileOrigin& origin,
                         const std::vector<std::pair<Vec2, double>>& base);
  // Vertices on a lattice of refine_m_ (anchored at the domain's corner, so stamps share it)
  // where the pile's region within `reach` of the footprint has none nearby: the pile's slopes
  // resolved as erosion would resolve them, on a mesh that ahead of a tool is often coarse (off
  // the slump band beside the tool, front_pile.hpp, where no pile goes).
  void fill_pile_lattice(const StampWork& w, double reach, double band, StampReport& report);
  // 1f: the vertices whose heights changed join L_e with their neighbours, and L_r; of the
  // retriangulated region's other vertices only those next to a face steeper than critical.
  void activate(const StampWork& w, const std::vector<VertexHandle>& region_vertices);
  // Whether a finite face incident to v is steeper than the critical slope: if none is, no
  // edge of v's star is, nor the star's mean gradient, so erosion has nothing to move at v.
  bool next_to_steep_face(VertexHandle v) const;
  StampReport pour(const ToolStamp& s);
  // Unconstrains every edge of a generation older than `generation`, thins the passed
  // contours (tin.conserve_volume), and returns the volume change of the flips and removals
  // (the stamp's deposit gives it back), with the vertices of the faces they changed;
  // O(constrained edges + region).
  double drop_stale_constraints(std::uint32_t generation, std::vector<VertexHandle>& region_vertices);
  // Of the contour vertices of passed stamps (the ends of their `stale` constraints, all
  // unconstrained now), those with a lower one among them closer than a third of refine_m_
  // removed: the top of the wall between O and I. O(ends x degree) plus the removals.
  void thin_passed_contours(const std::vector<std::pair<VertexHandle, VertexHandle>>& stale);
  // Raises the vertices by one dz that adds `volume` (a stamp off the domain gives the flips'
  // change back so). O(vertices x degree).
  void spread_volume(const std::vector<VertexHandle>& vertices, double volume);
  // With no tool (a settling budget), every stamp has passed: its constraints dropped and its
  // contours thinned, the flips' volume change given back (tin.conserve_volume). O(as above).
  void release_passed_stamps();
  // Moves the points of a clipped contour that lie on the domain's border onto an existing
  // border vertex within `reach` on the same side, if there is one. O(points x vertices near).
  void snap_border_crossings(std::vector<Vec2>& contour, double reach);
  double stale_delta_ = 0.0;  // the current stamp's share of that change
  // The pile a carrying stamp heaped, for the next one: where its vertices are and their heights
  // before the deposit (positions, not handles: the next stamp's retriangulation may remove some).
  CarriedPileOrigin carried_origin_;
  std::vector<std::pair<Vec2, double>> carried_;
  // erosion.cpp: splits edge (a, b) at its middle (volume change measured, and compensated
  // under tin.conserve_volume); returns the vertex there.
  VertexHandle split_edge(VertexHandle a, VertexHandle b, bool* inserted);
  // Inserts a vertex at p on the surface (height interpolated), the flips' volume change
  // measured and compensated as for a split; the vertex and its neighbours join L_e.
  VertexHandle insert_on_surface(const Vec2& p, bool* inserted);
  // Whether m, the middle of edge (a, b), lies a hair beside a constrained edge or a border edge of
  // the two faces beside (a, b) (split_edge then refuses the split). O(1).
  bool beside_a_constraint(VertexHandle a, VertexHandle b, const Vec2& m) const;
  // v's neighbours (the first ring_n_ of vertex_scratch_) with heights, distances and areas
  // (of nbr_scratch_: nbrs()); returns v's area.
  double gather_neighbours(VertexHandle v);
  std::span<const ErosionNeighbour> nbrs() const { return {nbr_scratch_.data(), ring_n_}; }
  std::span<double> transfers() { return {transfer_scratch_.data(), ring_n_}; }
  // Splits v's edges longer than refine_m_ until none is left that may be split (a constrained
  // edge only where its middle is exactly on it, no edge whose middle a facing vertex crowds);
  // returns the number of splits. Inline: erosion asks for every transfer, and most stars are
  // known to be short (has_long_edges' cached answer), which the call would cost a twentieth of
  // a visit to find out.
  std::size_t refine_around(VertexHandle v) { return v->info().short_edges ? 0 : split_long_edges(v); }
  std::size_t split_long_edges(VertexHandle v);
  // Whether the middle of edge (v, w), as rounded, lies exactly on it (exact orientation): a
  // constrained edge is split only there, else the new vertex would sit beside the constraint,
  // in a sliver. O(1); locating the middle instead walked from the last edit, often far along
  // a long stamp's contour (a 0.2 m spike's run: 119,641 walk steps in all with it, 39,712 now).
  bool middle_on_edge(VertexHandle v, VertexHandle w) const;
  // settle_region.cpp: the coarse-to-fine cascade (tin/settle_cascade.hpp) over the region
  // around L_e, when the budget is a settling one (cascade_pays); the vertices it changes join
  // L_e with their neighbours, and L_r. Counted in `report` as one pass.
  void settle_with_cascade(const ErosionRule& rule, const ErosionBudget& budget, ErosionReport& report);
  // Curvature refinement: splits v's longest edge longer than fine_m_ that sand crosses (a
  // transfer in transfer_scratch_) and across which the gradients of its two facets jump by
  // more than 4 curvature_tolerance_m_ / length (linear interpolation along such a crease
  // errs by about length x jump / 4). Reads v's ring from gather_neighbours and the transfers
  // erosion computed on it; returns whether it split. O(ring).
  bool refine_crease(VertexHandle v);
  // simplify.cpp: whether a triangle incident to a vertex of `link` (only those of the
  // retriangulated hole with hole_only, else also the ring around it) is steeper than the
  // stable slope. O(|link|^2 * degree).
  bool has_steep_triangle(const std::vector<VertexHandle>& link, bool hole_only) const;
  // simplify.cpp: one detection (over L_r, or every vertex with scan_all) and removal;
  // `coarsen` allows the planar rule.
  void simplify_round(double tan_alpha, bool coarsen, bool scan_all, SimplifyReport& report);
  // After removing a vertex at height z_removed: its link (`link`, barycentric areas before the
  // removal in `area_before`) takes over its area at its height, which gives back the
  // retriangulation's measured volume change where it happened (simplify.cpp). O(link degree^2).
  void merge_removed_column(const std::vector<VertexHandle>& link, const std::vector<double>& area_before,
                            double z_removed, double measured_delta);
  // build.cpp
  void insert_corners(const std::function<double(const Vec2&)>& z);
  void finish_build();

  DomainSpec domain_;
  Aabb2 box_;
  TinSpec spec_;
  int idle_passes_ = 2;
  double refine_m_ = 0.0;  // edge length above which erosion splits an edge it flows across
  // Curvature refinement (tin.curvature_tolerance_m; 0: off): edges between fine_m_ and
  // refine_m_ are split too where length x facet-gradient jump / 4 exceeds the tolerance.
  double fine_m_ = 0.0;
  double curvature_tolerance_m_ = 0.0;
  double tool_size_m_ = 0.0;       // characteristic radius of the scene's tool
  double settle_dz_ = 0.0;         // coarsening: removals may not make an edge steeper by this much
  double tan_critical_ = 0.0;      // the scene material's, for coarsening
  double tan_settle_ = 0.0;        // and the steepest stable slope (erosion.settle_tolerance_deg)
  bool rest_scan_pending_ = true;  // coarsening: scan every vertex at the next rest
  TerrainKind kind_ = TerrainKind::Flat;
  double base_height_m_ = 0.0;

  Cdt cdt_;
  ChangeCells changes_{box_};  // for displays (changes_since)
  // Vertices whose height changed since changes_since last ran (a removed one's slot may have
  // been freed or reused: checked when read).
  std::vector<VertexHandle> display_pending_;
  std::unordered_map<EdgeKey, std::uint32_t, EdgeKeyHash> generations_;  // constrained edges
  std::vector<ErosionEntry> erosion_list_;                               // L_e
  // The cached rings of L_e's vertices (ErosionEntry::ring), and how many of its slots belong
  // to a vertex still in L_e: the rest is garbage, compacted when it outgrows the live part.
  std::vector<VertexHandle> ring_pool_;
  std::size_t ring_pool_live_ = 0;
  std::vector<VertexHandle> simplify_list_;  // L_r

  std::size_t hull_vertices_ = 0;        // border vertices (all on the convex hull)
  mutable Walk edit_walk_, query_walk_;  // (see Walk)
  mutable std::uint64_t walk_steps_ = 0;
  mutable std::uint32_t face_epoch_ = 0;  // (surface_faces, a query, walks by face marks too)
  std::uint32_t vertex_epoch_ = 0;
  std::size_t capture_mismatches_ = 0;  // regions whose area changed: a broken assumption
  // The volume change of the current phase (stamp, erode, simplify) from the edits' own
  // bookkeeping: shift_z's A dz, and the measured change of every retriangulation (captures,
  // split_edge's flips). Each phase starts it at 0 and reports it as volume_change_m3, so the
  // runner integrates the surface (volume(), O(n)) only at the start and the end of a run.
  double volume_change_ = 0.0;

  // Scratch reused across calls (counted in stats().bytes).
  std::vector<ErosionNeighbour> nbr_scratch_;
  std::vector<double> transfer_scratch_;
  std::size_t ring_n_ = 0;  // entries of the three scratch vectors that are the visited vertex's
  std::vector<VertexHandle> vertex_scratch_;
  std::vector<FaceHandle> face_scratch_;
  std::vector<VertexHandle> link_scratch_;
  std::vector<std::pair<VertexHandle, VertexHandle>> diagonal_scratch_;  // remove_by_flips
  std::vector<VertexHandle> work_scratch_;                               // erosion: the pass's copy of L_e
  std::vector<VertexHandle> redundant_scratch_;                          // simplify: vertices to remove
  std::vector<VertexHandle> link_hold_scratch_;                          // simplify: the removed vertex's link
  std::vector<double> link_z_scratch_;      // simplify: the link's heights before the give-back
  std::vector<double> link_area_scratch_;   // simplify: the link's areas before the removal
  std::vector<VertexHandle> ring_scratch_;  // ring_of: the walk before it is cached
};

// Area of a finite face projected on the xy plane (positive: faces are counter-clockwise).
inline double face_area(FaceHandle f) {
  const Point &a = f->vertex(0)->point(), &b = f->vertex(1)->point(), &c = f->vertex(2)->point();
  return 0.5 * ((b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x()));
}
inline double face_volume(FaceHandle f) {
  return face_area(f) * (f->vertex(0)->point().z() + f->vertex(1)->point().z() + f->vertex(2)->point().z()) / 3.0;
}
// Whether a finite face's bounding box meets the box (the test of the region walks).
inline bool face_overlaps(FaceHandle f, const Aabb2& box) {
  const Point &a = f->vertex(0)->point(), &b = f->vertex(1)->point(), &c = f->vertex(2)->point();
  return std::max({a.x(), b.x(), c.x()}) >= box.lo.x() && std::min({a.x(), b.x(), c.x()}) <= box.hi.x() &&
         std::max({a.y(), b.y(), c.y()}) >= box.lo.y() && std::min({a.y(), b.y(), c.y()}) <= box.hi.y();
}
inline Vec2 xy(const Point& p) { return {p.x(), p.y()}; }
inline Vec2 xy(VertexHandle v) { return xy(v->point()); }
inline Aabb2 box_of(VertexHandle v) { return {xy(v), xy(v)}; }

template <class Visit>
void TinTerrain::visit_faces_overlapping(const Aabb2& box, const Vec2& from, Walk& walk, std::vector<FaceHandle>& queue,
                                         Visit&& visit) const {
  const std::uint32_t visited = next_face_epoch();
  FaceHandle start = locate(from, walk).face;  // (a point on the hull may locate in an infinite face)
  if (cdt_.is_infinite(start)) start = start->neighbor(start->index(cdt_.infinite_vertex()));
  queue.assign(1, start);
  start->info() = visited;
  for (std::size_t k = 0; k < queue.size(); ++k) {
    const FaceHandle f = queue[k];
    visit(f);
    for (int i = 0; i < 3; ++i) {
      const FaceHandle n = f->neighbor(i);
      if (cdt_.is_infinite(n) || n->info() == visited || !face_overlaps(n, box)) continue;
      n->info() = visited;
      queue.push_back(n);
    }
  }
}

}  // namespace sb::tin::detail
