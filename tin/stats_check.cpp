// Whole-model queries: volume, statistics and memory, mesh export, slopes, and the integrity
// check (raster sampling: sample.cpp). Each is O(n) except stats() (O(number of container blocks)).
#include <algorithm>
#include <cmath>
#include <sstream>
#include <unordered_map>

#include "tin/detail/tin_impl.hpp"

namespace sb::tin::detail {

// The sizes tin_terrain.hpp documents.
static_assert(sizeof(Tds::Vertex) == 56, "vertex: point 24 + face handle 8 + VertexInfo 24");
static_assert(sizeof(Tds::Face) == 56, "face: 3 vertices, 3 neighbours, TDS flag, 3 constraint flags, mark");

namespace {

// Bytes of a CGAL Compact_container from its capacity: blocks of 14, 30, 46, ... elements,
// each with 2 extra boundary elements, plus the vector of (block, size) pairs.
std::size_t compact_container_bytes(std::size_t capacity, std::size_t element_size) {
  std::size_t blocks = 0, covered = 0, block = 14;
  while (covered < capacity) {
    covered += block;
    block += 16;
    ++blocks;
  }
  std::size_t table = 1;
  while (table < blocks) table *= 2;
  return (capacity + 2 * blocks) * element_size + (blocks ? table * 2 * sizeof(void*) : 0);
}

template <class T>
std::size_t vector_bytes(const std::vector<T>& v) {
  return v.capacity() * sizeof(T);
}

}  // namespace

double TinTerrain::volume() const {
  double v = 0.0;
  for (auto f = cdt_.finite_faces_begin(); f != cdt_.finite_faces_end(); ++f) v += face_volume(f);
  return v;
}

ModelStats TinTerrain::stats() const {
  ModelStats st;
  st.vertices = cdt_.number_of_vertices();
  // Every border vertex is on the convex hull (the domain's sides are straight) and has one
  // infinite face: O(1) where number_of_faces() circulates the hull.
  st.triangles = cdt_.dimension() == 2 ? cdt_.tds().number_of_faces() - hull_vertices_ : cdt_.number_of_faces();
  st.constrained_edges = generations_.size();
  st.walk_steps = walk_steps_;
  st.active = erosion_list_.size();
  std::size_t bytes = sizeof(TinTerrain);
  bytes += compact_container_bytes(cdt_.tds().vertices().capacity(), sizeof(Tds::Vertex));
  bytes += compact_container_bytes(cdt_.tds().faces().capacity(), sizeof(Tds::Face));
  // libstdc++ unordered_map: a bucket array (when more than one bucket) and one node per
  // element: next pointer plus the (key, value) pair (no cached hash: the hash is noexcept).
  using Node = std::pair<const EdgeKey, std::uint32_t>;
  const std::size_t node = sizeof(void*) + ((sizeof(Node) + alignof(Node) - 1) / alignof(Node)) * alignof(Node);
  bytes +=
      (generations_.bucket_count() > 1 ? generations_.bucket_count() * sizeof(void*) : 0) + generations_.size() * node;
  bytes += vector_bytes(erosion_list_) + vector_bytes(simplify_list_) + vector_bytes(nbr_scratch_) +
           vector_bytes(transfer_scratch_) + vector_bytes(vertex_scratch_) + vector_bytes(face_scratch_) +
           vector_bytes(link_scratch_) + vector_bytes(work_scratch_) + vector_bytes(redundant_scratch_) +
           vector_bytes(link_hold_scratch_) + vector_bytes(ring_pool_) + vector_bytes(ring_scratch_) +
           vector_bytes(diagonal_scratch_) + vector_bytes(link_z_scratch_) + vector_bytes(link_area_scratch_) +
           vector_bytes(carried_) + changes_.bytes() + vector_bytes(display_pending_);
  st.bytes = bytes;
  return st;
}

SurfaceMesh TinTerrain::mesh() const {
  SurfaceMesh m;
  std::unordered_map<const void*, std::uint32_t> index;
  index.reserve(cdt_.number_of_vertices());
  m.vertices.reserve(cdt_.number_of_vertices());
  for (auto v = cdt_.finite_vertices_begin(); v != cdt_.finite_vertices_end(); ++v) {
    index.emplace(&*v, static_cast<std::uint32_t>(m.vertices.size()));
    m.vertices.emplace_back(v->point().x(), v->point().y(), v->point().z());
  }
  m.triangles.reserve(cdt_.number_of_faces());
  for (auto f = cdt_.finite_faces_begin(); f != cdt_.finite_faces_end(); ++f)
    m.triangles.push_back({index.at(&*f->vertex(0)), index.at(&*f->vertex(1)), index.at(&*f->vertex(2))});
  for (auto e = cdt_.finite_edges_begin(); e != cdt_.finite_edges_end(); ++e) {
    if (!e->first->is_constrained(e->second)) continue;
    m.constrained_edges.push_back(
        {index.at(&*e->first->vertex(Cdt::ccw(e->second))), index.at(&*e->first->vertex(Cdt::cw(e->second)))});
  }
  return m;
}

double TinTerrain::max_slope_deg() const {
  double steepest = 0.0;
  for (auto e = cdt_.finite_edges_begin(); e != cdt_.finite_edges_end(); ++e) {
    const Point& a = e->first->vertex(Cdt::ccw(e->second))->point();
    const Point& b = e->first->vertex(Cdt::cw(e->second))->point();
    const double d = std::hypot(a.x() - b.x(), a.y() - b.y());
    if (d > 0.0) steepest = std::max(steepest, std::abs(a.z() - b.z()) / d);
  }
  return rad_to_deg(std::atan(steepest));
}

IntegrityReport TinTerrain::check() const {
  IntegrityReport r;
  auto problem = [&r](const std::string& what) {
    if (r.problems.size() < 20) r.problems.push_back("tin: " + what);
  };
  if (cdt_.dimension() != 2) {
    problem("the triangulation is not 2-dimensional");
    return r;
  }
  if (!cdt_.is_valid()) problem("CGAL is_valid() failed (combinatorics, orientation or constrained Delaunay property)");

  std::size_t constrained = 0;
  for (auto e = cdt_.finite_edges_begin(); e != cdt_.finite_edges_end(); ++e) {
    if (!e->first->is_constrained(e->second)) continue;
    ++constrained;
    const VertexHandle a = e->first->vertex(Cdt::ccw(e->second)), b = e->first->vertex(Cdt::cw(e->second));
    if (!generations_.count(EdgeKey(a, b))) {
      std::ostringstream s;
      s << "constrained edge (" << a->point().x() << ", " << a->point().y() << ")-(" << b->point().x() << ", "
        << b->point().y() << ") has no generation record";
      problem(s.str());
    }
  }
  if (constrained != generations_.size())
    problem(std::to_string(generations_.size()) + " generation records for " + std::to_string(constrained) +
            " constrained edges");

  std::size_t in_erosion = 0, in_simplify = 0;
  for (auto v = cdt_.finite_vertices_begin(); v != cdt_.finite_vertices_end(); ++v) {
    const Point& p = v->point();
    if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || !std::isfinite(p.z())) {
      problem("a vertex has a non-finite coordinate");
      continue;
    }
    if (!box_.contains(xy(p))) problem("a vertex lies outside the domain");
    if ((v->info().border != 0) != on_border(xy(p))) problem("a vertex's border flag is wrong");
    const VertexInfo& in = v->info();
    if (in.area >= 0.0 && std::abs(in.area - vertex_area(v)) > 1e-12 * in.area)
      problem("a vertex's cached area is stale");
    if (in.short_edges) {
      auto c = cdt_.incident_vertices(v), done = c;
      do {
        if (!cdt_.is_infinite(c) && (xy(c) - xy(p)).norm() > refine_m_) problem("a vertex's short-edge flag is stale");
      } while (++c != done);
    }
    if (in.erosion_slot != kNoSlot) {
      ++in_erosion;
      if (in.erosion_slot >= erosion_list_.size() || erosion_list_[in.erosion_slot].vertex != VertexHandle(v)) {
        problem("erosion list slot mismatch");
      } else if (const ErosionEntry& e = erosion_list_[in.erosion_slot]; e.ring_size > 0) {
        // The cached ring: v's neighbours in the circulator's order, exactly.
        std::size_t k = 0;
        bool same = e.ring != kNoSlot && e.ring_size <= e.ring_capacity &&
                    std::size_t{e.ring} + e.ring_capacity <= ring_pool_.size();
        auto c = cdt_.incident_vertices(v), done = c;
        do {
          if (cdt_.is_infinite(c)) continue;
          same = same && k < e.ring_size && ring_pool_[e.ring + k] == VertexHandle(c);
          ++k;
        } while (same && ++c != done);
        if (!same || k != e.ring_size) problem("a vertex's cached ring is stale");
      }
    }
    if (in.simplify_slot != kNoSlot) {
      ++in_simplify;
      if (in.simplify_slot >= simplify_list_.size() || simplify_list_[in.simplify_slot] != VertexHandle(v))
        problem("simplification list slot mismatch");
    }
  }
  if (cdt_.tds().number_of_faces() - hull_vertices_ != cdt_.number_of_faces())
    problem("the hull vertex count is stale (" + std::to_string(hull_vertices_) + ")");
  if (in_erosion != erosion_list_.size()) problem("erosion list holds vertices that are not marked in it");
  if (in_simplify != simplify_list_.size()) problem("simplification list holds vertices that are not marked in it");

  const Vec2 corners[4] = {box_.lo, {box_.hi.x(), box_.lo.y()}, box_.hi, {box_.lo.x(), box_.hi.y()}};
  for (const Vec2& c : corners) {
    // CGAL's own location: check() leaves the walk statistics alone.
    Cdt::Locate_type type;
    int index = 0;
    cdt_.locate(Point(c.x(), c.y(), 0.0), type, index);
    if (type != Cdt::VERTEX) problem("a domain corner is not a vertex");
  }
  if (capture_mismatches_ > 0)
    problem(std::to_string(capture_mismatches_) + " retriangulations reached beyond their captured region");
  return r;
}

}  // namespace sb::tin::detail
