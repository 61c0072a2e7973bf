// Initial construction of the TIN and the factories: the 4 domain corners, then greedy
// insertion (Garland-Heckbert) of the sample of largest error until tin.tolerance_m, or a
// given point set.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <queue>

#include "common/erosion.hpp"
#include "common/input_error.hpp"
#include "common/point_sets.hpp"
#include "tin/detail/tin_impl.hpp"
#include "tin/tin_terrain.hpp"

namespace sb::tin {

namespace detail {

namespace {

double tool_radius(const ToolSpec& t) {
  switch (t.shape) {
    case ToolShape::Disk:
    case ToolShape::Pour:
      return t.radius_m;
    case ToolShape::Box:
    case ToolShape::Ellipse:
      return t.half_size_m.minCoeff();
    case ToolShape::Polygon:
      return std::sqrt(std::abs(signed_area(t.polygon_m)) / std::numbers::pi);
  }
  return t.radius_m;
}

}  // namespace

TinOptions tin_options(const Scene& scene) {
  TinOptions o;
  o.domain = scene.domain;
  o.tin = scene.tin;
  o.idle_passes = scene.erosion.idle_passes;
  o.settle_tolerance_deg = scene.erosion.settle_tolerance_deg;
  o.material = scene.material;
  o.tool_radius_m = tool_radius(scene.tool);
  o.kind = scene.terrain.kind;
  o.base_height_m = scene.terrain.height_m;
  return o;
}

double default_refine_m(const TinOptions& o) {
  // Linear interpolation over an edge of length h across a slope break of tan(critical)
  // (a pile's toe and apex, a wall's foot) errs by at most h tan / 4: the edge length at
  // which the surface stays within tin.tolerance_m. Never finer than half the tool's radius
  // (what a stamp resolves anyway; finer, erosion over a whole dune field refines it all),
  // never coarser than 5 % of the domain.
  const double extent = std::max(o.domain.size_m.x(), o.domain.size_m.y());
  const double tan_c = o.material.tan_critical();
  const double h = tan_c > 0.0 ? 4.0 * o.tin.tolerance_m / tan_c : extent;
  return std::min(std::max(h, 0.5 * o.tool_radius_m), 0.05 * extent);
}

Refinement refinement_lengths(const TinOptions& o) {
  const TinSpec& spec = o.tin;
  const double extent = std::max(o.domain.size_m.x(), o.domain.size_m.y());
  Refinement r;
  r.refine_m = spec.refine_m > 0.0 ? spec.refine_m : default_refine_m(o);
  // Never split below what snapping could merge again, nor below a ten-thousandth of the
  // domain (a 0.4 mm tool must not refine a 30 cm domain to 0.1 mm).
  const double floor_m = std::max(64.0 * spec.snap_m, 1e-4 * extent);
  r.refine_m = std::max(r.refine_m, floor_m);
  // Curvature refinement goes down to refine_min_m (half of refine_m by default), never
  // below a quarter of refine_m: a tiny tolerance or refine_min_m cannot make the mesh
  // explode (a 30 um floor on pile.toml ran 4 pours for over 5 minutes).
  const double fine = spec.refine_min_m > 0.0 ? spec.refine_min_m : 0.5 * r.refine_m;
  r.fine_m = spec.curvature_tolerance_m > 0.0 ? std::clamp(fine, 0.25 * r.refine_m, r.refine_m) : r.refine_m;
  return r;
}

TinTerrain::TinTerrain(const TinOptions& o)
    : domain_(o.domain), box_(o.domain.box()), spec_(o.tin), idle_passes_(o.idle_passes) {
  const double extent = std::max(domain_.size_m.x(), domain_.size_m.y());
  if (!(domain_.size_m.minCoeff() > 0.0) || !std::isfinite(extent))
    throw InputError("scene: domain.size_m must be positive and finite for the TIN");
  tool_size_m_ = o.tool_radius_m;
  if (!(tool_size_m_ > 0.0) || !std::isfinite(tool_size_m_)) tool_size_m_ = 0.02 * extent;
  const Refinement refinement = refinement_lengths(o);
  refine_m_ = refinement.refine_m;
  fine_m_ = refinement.fine_m;
  curvature_tolerance_m_ = spec_.curvature_tolerance_m;
  // A thousandth of the TIN's accuracy: what coarsening may add to an edge's height drop.
  settle_dz_ = 1e-3 * spec_.tolerance_m;
  tan_critical_ = o.material.tan_critical();
  tan_settle_ = ErosionRule::from(o.material, o.settle_tolerance_deg).tan_settle;
  kind_ = o.kind;
  base_height_m_ = o.base_height_m;
}

void TinTerrain::insert_corners(const std::function<double(const Vec2&)>& z) {
  const Vec2 corners[4] = {box_.lo, {box_.hi.x(), box_.lo.y()}, box_.hi, {box_.lo.x(), box_.hi.y()}};
  for (const Vec2& c : corners) {
    const double h = z(c);
    if (!std::isfinite(h)) throw InputError("terrain: the initial height is not finite at a domain corner");
    const VertexHandle v = cdt_.insert(Point(c.x(), c.y(), h));
    v->info() = VertexInfo{};
    edit_walk_.hint = v;
  }
}

void TinTerrain::finish_build() {
  for (auto f = cdt_.all_faces_begin(); f != cdt_.all_faces_end(); ++f) f->info() = 0;
  face_epoch_ = 0;
  vertex_epoch_ = 0;
  hull_vertices_ = 0;
  for (auto v = cdt_.finite_vertices_begin(); v != cdt_.finite_vertices_end(); ++v) {
    v->info() = VertexInfo{};
    v->info().border = on_border(xy(v->point())) ? 1 : 0;
    hull_vertices_ += v->info().border;
  }
  edit_walk_.hint = query_walk_.hint = cdt_.finite_vertices_begin();
  changes_.mark_all();
}

namespace {

// Candidate samples of a face during greedy insertion.
struct Bucket {
  std::vector<std::uint32_t> samples;
  FaceHandle face;
  std::uint32_t version = 0;
};

struct HeapEntry {
  double error;
  std::uint32_t bucket;
  std::uint32_t version;
  std::uint32_t sample;
  bool operator<(const HeapEntry& o) const { return error < o.error; }
};

}  // namespace

// Greedy insertion: every face owns the samples inside it and knows the worst one; the face
// with the worst sample gets it inserted; the samples of the faces the insertion destroys
// (its conflict zone) move to the new faces around the new vertex. O(m log m) for m samples.
void TinTerrain::build_from_field(const HeightField& field) {
  insert_corners([&field](const Vec2& p) { return field(p); });
  if (kind_ == TerrainKind::Flat) {
    finish_build();
    return;
  }
  // Samples on a lattice fine enough for the field's detail (at most ~4M).
  double spacing = kind_ == TerrainKind::Heightmap ? field.feature_m() : 0.5 * field.feature_m();
  const double area = domain_.size_m.x() * domain_.size_m.y();
  spacing = std::max(spacing, std::sqrt(area / 4.0e6));
  const std::size_t nx = static_cast<std::size_t>(std::ceil(domain_.size_m.x() / spacing)) + 1;
  const std::size_t ny = static_cast<std::size_t>(std::ceil(domain_.size_m.y() / spacing)) + 1;
  const double sx = domain_.size_m.x() / static_cast<double>(nx - 1);
  const double sy = domain_.size_m.y() / static_cast<double>(ny - 1);
  auto sample_xy = [&](std::uint32_t i) {
    const std::size_t ix = i % nx, iy = i / nx;
    return Vec2(ix + 1 == nx ? box_.hi.x() : box_.lo.x() + static_cast<double>(ix) * sx,
                iy + 1 == ny ? box_.hi.y() : box_.lo.y() + static_cast<double>(iy) * sy);
  };
  std::vector<double> sample_z(nx * ny);
  std::vector<std::uint32_t> all;
  all.reserve(nx * ny);
  for (std::uint32_t i = 0; i < nx * ny; ++i) {
    sample_z[i] = field(sample_xy(i));
    if (!std::isfinite(sample_z[i])) throw InputError("terrain: the initial height is not finite inside the domain");
    const std::size_t ix = i % nx, iy = i / nx;
    const bool corner = (ix == 0 || ix + 1 == nx) && (iy == 0 || iy + 1 == ny);
    if (!corner) all.push_back(i);
  }

  const auto orient = cdt_.geom_traits().orientation_2_object();
  auto contains = [&](FaceHandle f, const Vec2& p) {
    const Point q(p.x(), p.y(), 0.0);
    for (int i = 0; i < 3; ++i)
      if (orient(f->vertex(Cdt::ccw(i))->point(), f->vertex(Cdt::cw(i))->point(), q) == CGAL::RIGHT_TURN) return false;
    return true;
  };

  std::vector<Bucket> buckets;
  std::vector<std::uint32_t> free_buckets;
  std::priority_queue<HeapEntry> heap;
  auto make_bucket = [&](FaceHandle f, std::vector<std::uint32_t>&& samples) {
    std::uint32_t id;
    if (!free_buckets.empty()) {
      id = free_buckets.back();
      free_buckets.pop_back();
    } else {
      id = static_cast<std::uint32_t>(buckets.size());
      buckets.emplace_back();
    }
    Bucket& b = buckets[id];
    b.samples = std::move(samples);
    b.face = f;
    f->info() = id + 1;
    double worst = -1.0;
    std::uint32_t worst_sample = 0;
    for (std::uint32_t s : b.samples) {
      const double e = std::abs(sample_z[s] - interpolate(f, sample_xy(s)));
      if (e > worst) {
        worst = e;
        worst_sample = s;
      }
    }
    if (!b.samples.empty()) heap.push({worst, id, b.version, worst_sample});
  };
  // Hands samples to the faces that contain them (first match on shared edges).
  std::vector<std::vector<std::uint32_t>> parts;
  auto distribute = [&](const std::vector<FaceHandle>& faces, const std::vector<std::uint32_t>& samples) {
    parts.assign(faces.size(), {});
    for (std::uint32_t s : samples) {
      const Vec2 p = sample_xy(s);
      for (std::size_t k = 0; k < faces.size(); ++k) {
        if (contains(faces[k], p)) {
          parts[k].push_back(s);
          break;
        }
      }
    }
    for (std::size_t k = 0; k < faces.size(); ++k) make_bucket(faces[k], std::move(parts[k]));
  };

  std::vector<FaceHandle> faces;
  for (auto f = cdt_.finite_faces_begin(); f != cdt_.finite_faces_end(); ++f) faces.push_back(f);
  distribute(faces, all);
  all = {};

  std::vector<FaceHandle> conflicts;
  std::vector<std::uint32_t> pool;
  while (!heap.empty()) {
    const HeapEntry top = heap.top();
    heap.pop();
    if (buckets[top.bucket].version != top.version) continue;
    if (top.error <= spec_.tolerance_m) break;
    const FaceHandle face = buckets[top.bucket].face;
    const Vec2 p = sample_xy(top.sample);
    const Point point(p.x(), p.y(), sample_z[top.sample]);
    conflicts.clear();
    cdt_.get_conflicts(point, std::back_inserter(conflicts), face);
    pool.clear();
    for (FaceHandle f : conflicts) {
      if (f->info() == 0) continue;
      Bucket& b = buckets[f->info() - 1];
      for (std::uint32_t s : b.samples)
        if (s != top.sample) pool.push_back(s);
      b.samples = {};
      ++b.version;
      free_buckets.push_back(f->info() - 1);
      f->info() = 0;
    }
    const VertexHandle v = cdt_.insert(point, face);
    faces.clear();
    auto c = cdt_.incident_faces(v), done = c;
    do {
      if (!cdt_.is_infinite(c)) {
        c->info() = 0;
        faces.push_back(c);
      }
    } while (++c != done);
    distribute(faces, pool);
  }
  if (kind_ != TerrainKind::Plane) project_heights(field);  // a plane is exact already
  finish_build();
}

void TinTerrain::build_from_points(const std::vector<Vec3>& points, const HeightField* field) {
  std::vector<Point> pts;
  pts.reserve(points.size());
  for (const Vec3& p : points) {
    if (!p.allFinite()) throw InputError("tin points: every point must be finite");
    if (!box_.contains(p.head<2>()))
      throw InputError("tin points: (" + std::to_string(p.x()) + ", " + std::to_string(p.y()) +
                       ") is outside the scene's domain");
    pts.emplace_back(p.x(), p.y(), p.z());
  }
  insert_corners([&](const Vec2& c) {
    double best = std::numeric_limits<double>::infinity();
    double z = base_height_m_;
    for (const Vec3& p : points) {
      const double d = (p.head<2>() - c).squaredNorm();
      if (d < best) {
        best = d;
        z = p.z();
      }
    }
    return z;
  });
  cdt_.insert(pts.begin(), pts.end());
  // A flat bed or a plane is exact already.
  if (field != nullptr && kind_ != TerrainKind::Flat && kind_ != TerrainKind::Plane) project_heights(*field);
  finish_build();
}

}  // namespace detail

Refinement refinement_of(const Scene& scene) { return detail::refinement_lengths(detail::tin_options(scene)); }

std::unique_ptr<Terrain> make_tin_terrain(const Scene& scene, const HeightField& initial) {
  if (scene.tin.initial_points > 0) {
    // The paper's experiments: a TIN of N vertices from the start.
    std::vector<Vec3> points;
    for (const Vec2& p : jittered_lattice(scene.domain, static_cast<std::size_t>(scene.tin.initial_points),
                                          scene.tin.initial_jitter, static_cast<std::uint64_t>(scene.terrain.seed)))
      points.emplace_back(p.x(), p.y(), initial(p));
    auto t = std::make_unique<detail::TinTerrain>(detail::tin_options(scene));
    t->build_from_points(points, &initial);
    return t;
  }
  auto t = std::make_unique<detail::TinTerrain>(detail::tin_options(scene));
  t->build_from_field(initial);
  return t;
}

std::unique_ptr<Terrain> make_tin_terrain_from_points(const Scene& scene, const std::vector<Vec3>& points) {
  auto t = std::make_unique<detail::TinTerrain>(detail::tin_options(scene));
  t->build_from_points(points);
  return t;
}

}  // namespace sb::tin
