#include "harness/interactive/display_feed.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sb {

namespace {

constexpr std::size_t kTile = 64;  // the feed's pending tiles: nodes per side

}  // namespace

DisplayFeed::DisplayFeed(Terrain& terrain, double z_ref, const Aabb2& domain, bool tiles)
    : lattice_(tiles ? terrain.lattice() : std::nullopt),
      z_ref_(z_ref),
      domain_(domain),
      origin_(0.5 * (domain.lo.x() + domain.hi.x()), 0.5 * (domain.lo.y() + domain.hi.y()), z_ref) {
  if (tiles && !lattice_) {
    // A mesh by tiles only from a back-end that tracks its changes (this call starts it).
    const SurfaceChanges c = terrain.changes_since(0);
    if (!c.tracked) return;
    version_ = c.version;
    const double w = domain.hi.x() - domain.lo.x(), h = domain.hi.y() - domain.lo.y();
    const auto side = [&](double l) {
      const double longest = std::max(w, h);
      return longest > 0.0
                 ? std::clamp<std::size_t>(static_cast<std::size_t>(std::ceil(kMeshTiles * l / longest)), 1, kMeshTiles)
                 : std::size_t{1};
    };
    mesh_cols_ = side(w);
    mesh_rows_ = side(h);
    mesh_tiles_.resize(mesh_cols_ * mesh_rows_);
    pending_.assign(mesh_tiles_.size(), 0);
    return;
  }
  if (!lattice_) return;
  heights_.assign(lattice_->nx * lattice_->ny, 0.0f);
  tile_cols_ = (lattice_->nx + kTile - 1) / kTile;
  pending_.assign(tile_cols_ * ((lattice_->ny + kTile - 1) / kTile), 0);
}

bool DisplayFeed::publish(Terrain& terrain, bool changed, std::vector<double>& stamp_times_s) {
  if (!mesh_tiles_.empty()) return publish_mesh_tiles(terrain, stamp_times_s);
  if (!lattice_) {
    if (!changed && !first_) return false;
    auto mesh = std::make_shared<DisplayMesh>();
    mesh->mesh = terrain.mesh();
    mesh->version = ++mesh_version_;
    std::lock_guard lock(mutex_);
    mesh_ = std::move(mesh);
    first_ = false;
    stamp_times_s_.insert(stamp_times_s_.end(), stamp_times_s.begin(), stamp_times_s.end());
    stamp_times_s.clear();
    return true;
  }
  const SurfaceChanges c = terrain.changes_since(first_ ? 0 : version_);
  std::vector<NodeRect> rects = c.rects;
  if (!c.tracked) rects.assign(1, NodeRect{0, 0, lattice_->nx, lattice_->ny});
  version_ = c.version;
  first_ = false;
  const std::size_t nx = lattice_->nx;
  std::lock_guard lock(mutex_);
  stamp_times_s_.insert(stamp_times_s_.end(), stamp_times_s.begin(), stamp_times_s.end());
  stamp_times_s.clear();
  for (const NodeRect& r : rects) {
    if (r.x1 <= r.x0 || r.y1 <= r.y0) continue;
    terrain.lattice_heights(r, z_ref_, heights_.data() + r.y0 * nx + r.x0, nx);
    for (std::size_t ty = r.y0 / kTile; ty <= (r.y1 - 1) / kTile; ++ty)
      for (std::size_t tx = r.x0 / kTile; tx <= (r.x1 - 1) / kTile; ++tx) {
        const std::size_t t = ty * tile_cols_ + tx;
        if (pending_[t]) continue;
        pending_[t] = 1;
        pending_list_.push_back(static_cast<std::uint32_t>(t));
      }
  }
  return !rects.empty();
}

bool DisplayFeed::take(LatticeUpdate& out) {
  out.clear();
  std::lock_guard lock(mutex_);
  out.stamp_times_s.swap(stamp_times_s_);
  if (!lattice_ || pending_list_.empty()) return false;
  const std::size_t nx = lattice_->nx, ny = lattice_->ny;
  std::sort(pending_list_.begin(), pending_list_.end());  // storage order: neighbours stay close
  for (const std::uint32_t t : pending_list_) {
    pending_[t] = 0;
    const std::size_t x0 = (t % tile_cols_) * kTile, y0 = (t / tile_cols_) * kTile;
    const NodeRect r{x0, y0, std::min(nx, x0 + kTile), std::min(ny, y0 + kTile)};
    out.rects.push_back(r);
    for (std::size_t y = r.y0; y < r.y1; ++y)
      out.heights.insert(out.heights.end(), heights_.begin() + static_cast<std::ptrdiff_t>(y * nx + r.x0),
                         heights_.begin() + static_cast<std::ptrdiff_t>(y * nx + r.x1));
  }
  pending_list_.clear();
  return true;
}

namespace {

// Edge k of n tiles along an axis from lo: the outer edges at infinity (the tiles share out
// every face, however near the border its centroid lies).
double tile_edge(std::size_t k, std::size_t n, double lo, double extent) {
  if (k == 0) return -std::numeric_limits<double>::infinity();
  if (k == n) return std::numeric_limits<double>::infinity();
  return lo + extent * static_cast<double>(k) / static_cast<double>(n);
}

}  // namespace

Aabb2 DisplayFeed::mesh_tile_box(std::size_t tile) const {
  const std::size_t i = tile % mesh_cols_, j = tile / mesh_cols_;
  const Vec2 size = domain_.hi - domain_.lo;
  return {
      {tile_edge(i, mesh_cols_, domain_.lo.x(), size.x()), tile_edge(j, mesh_rows_, domain_.lo.y(), size.y())},
      {tile_edge(i + 1, mesh_cols_, domain_.lo.x(), size.x()), tile_edge(j + 1, mesh_rows_, domain_.lo.y(), size.y())}};
}

bool DisplayFeed::publish_mesh_tiles(Terrain& terrain, std::vector<double>& stamp_times_s) {
  // The tiles the changed boxes meet (all of them the first time), then their faces read again.
  std::vector<std::uint32_t> dirty;
  if (first_) {
    for (std::size_t t = 0; t < mesh_tiles_.size(); ++t) dirty.push_back(static_cast<std::uint32_t>(t));
  } else {
    const SurfaceChanges c = terrain.changes_since(version_);
    version_ = c.version;
    std::vector<std::uint8_t> hit(mesh_tiles_.size(), 0);
    const Vec2 size = domain_.hi - domain_.lo;
    const auto index = [](double u, std::size_t n) {
      return u > 0.0 ? std::min(static_cast<std::size_t>(u * static_cast<double>(n)), n - 1) : std::size_t{0};
    };
    for (const Aabb2& r : c.regions) {
      const std::size_t x0 = index((r.lo.x() - domain_.lo.x()) / size.x(), mesh_cols_);
      const std::size_t x1 = index((r.hi.x() - domain_.lo.x()) / size.x(), mesh_cols_);
      const std::size_t y0 = index((r.lo.y() - domain_.lo.y()) / size.y(), mesh_rows_);
      const std::size_t y1 = index((r.hi.y() - domain_.lo.y()) / size.y(), mesh_rows_);
      for (std::size_t y = y0; y <= y1; ++y)
        for (std::size_t x = x0; x <= x1; ++x) hit[y * mesh_cols_ + x] = 1;
    }
    for (std::size_t t = 0; t < hit.size(); ++t)
      if (hit[t]) dirty.push_back(static_cast<std::uint32_t>(t));
  }
  first_ = false;
  // Each run of neighbouring dirty tiles in a row read in one walk, its faces dealt out to the
  // tiles by their centroids' column (a large face is visited once, not once per tile it spans).
  std::vector<std::vector<float>> faces(dirty.size());
  const double lo_x = domain_.lo.x(), extent_x = domain_.hi.x() - domain_.lo.x();
  for (std::size_t first = 0; first < dirty.size();) {
    std::size_t last = first;
    while (last + 1 < dirty.size() && dirty[last + 1] == dirty[last] + 1 && dirty[last + 1] % mesh_cols_ != 0) ++last;
    const Aabb2 box{mesh_tile_box(dirty[first]).lo, mesh_tile_box(dirty[last]).hi};
    const std::size_t col0 = dirty[first] % mesh_cols_;
    faces_scratch_.clear();
    terrain.surface_faces(box, faces_scratch_);
    for (std::size_t f = 0; f + 3 <= faces_scratch_.size(); f += 3) {
      const double x = (faces_scratch_[f].x() + faces_scratch_[f + 1].x() + faces_scratch_[f + 2].x()) / 3.0;
      std::size_t k = first;  // the tile whose [edge, next edge) holds x, as surface_faces decided
      while (k < last && x >= tile_edge(col0 + (k - first) + 1, mesh_cols_, lo_x, extent_x)) ++k;
      for (std::size_t c = f; c < f + 3; ++c) {
        const Vec3 q = faces_scratch_[c] - origin_;
        faces[k].insert(faces[k].end(),
                        {static_cast<float>(q.x()), static_cast<float>(q.y()), static_cast<float>(q.z())});
      }
    }
    first = last + 1;
  }
  std::lock_guard lock(mutex_);
  stamp_times_s_.insert(stamp_times_s_.end(), stamp_times_s.begin(), stamp_times_s.end());
  stamp_times_s.clear();
  for (std::size_t k = 0; k < dirty.size(); ++k) {
    const std::uint32_t t = dirty[k];
    mesh_tiles_[t].swap(faces[k]);
    if (pending_[t]) continue;
    pending_[t] = 1;
    pending_list_.push_back(t);
  }
  return !dirty.empty();
}

bool DisplayFeed::take(MeshTileUpdate& out) {
  out.clear();
  std::lock_guard lock(mutex_);
  out.stamp_times_s.swap(stamp_times_s_);
  if (mesh_tiles_.empty() || pending_list_.empty()) return false;
  std::sort(pending_list_.begin(), pending_list_.end());
  for (const std::uint32_t t : pending_list_) {
    pending_[t] = 0;
    out.tiles.push_back(t);
    out.xyz.insert(out.xyz.end(), mesh_tiles_[t].begin(), mesh_tiles_[t].end());
    out.offsets.push_back(out.xyz.size());
  }
  pending_list_.clear();
  return true;
}

std::shared_ptr<const DisplayMesh> DisplayFeed::mesh() const {
  std::lock_guard lock(mutex_);
  return mesh_;
}

}  // namespace sb
