#include "harness/interactive/display_feed.hpp"

#include <algorithm>
#include <limits>

namespace sb {

namespace {

constexpr std::size_t kTile = 64;  // the feed's pending tiles: nodes per side

}  // namespace

DisplayFeed::DisplayFeed(Terrain& terrain, double z_ref, const Aabb2& domain, bool tiles)
    : lattice_(tiles ? terrain.lattice() : std::nullopt),
      z_ref_(z_ref),
      origin_(0.5 * (domain.lo.x() + domain.hi.x()), 0.5 * (domain.lo.y() + domain.hi.y()), z_ref),
      mesh_grid_(domain, kMeshTiles) {
  if (tiles && !lattice_) {
    // A mesh by tiles only from a back-end that tracks its changes (this call starts it).
    const SurfaceChanges c = terrain.changes_since(0);
    if (!c.tracked) return;
    version_ = c.version;
    mesh_tiles_.resize(mesh_grid_.size());
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

Aabb2 DisplayFeed::mesh_tile_box(std::size_t tile) const {
  // The border tiles reach to infinity: together the tiles share out every face, however near
  // the domain's side its centroid lies.
  constexpr double inf = std::numeric_limits<double>::infinity();
  const DomainTiles& g = mesh_grid_;
  const std::size_t i = tile % g.cols(), j = tile / g.cols();
  return {{i == 0 ? -inf : g.x_edge(i), j == 0 ? -inf : g.y_edge(j)},
          {i + 1 == g.cols() ? inf : g.x_edge(i + 1), j + 1 == g.rows() ? inf : g.y_edge(j + 1)}};
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
    const DomainTiles& g = mesh_grid_;
    for (const Aabb2& r : c.regions) {
      const std::size_t x0 = g.col(r.lo.x()), x1 = g.col(r.hi.x());
      for (std::size_t y = g.row(r.lo.y()); y <= g.row(r.hi.y()); ++y)
        for (std::size_t x = x0; x <= x1; ++x) hit[y * g.cols() + x] = 1;
    }
    for (std::size_t t = 0; t < hit.size(); ++t)
      if (hit[t]) dirty.push_back(static_cast<std::uint32_t>(t));
  }
  first_ = false;
  // Each run of neighbouring dirty tiles in a row read in one walk, its faces dealt out to the
  // tiles by their centroids' column (a large face is visited once, not once per tile it spans).
  std::vector<std::vector<float>> faces(dirty.size());
  const std::size_t cols = mesh_grid_.cols();
  for (std::size_t first = 0; first < dirty.size();) {
    std::size_t last = first;
    while (last + 1 < dirty.size() && dirty[last + 1] == dirty[last] + 1 && dirty[last + 1] % cols != 0) ++last;
    const Aabb2 box{mesh_tile_box(dirty[first]).lo, mesh_tile_box(dirty[last]).hi};
    const std::size_t col0 = dirty[first] % cols;
    faces_scratch_.clear();
    terrain.surface_faces(box, faces_scratch_);
    for (std::size_t f = 0; f + 3 <= faces_scratch_.size(); f += 3) {
      // The tile whose columns hold the centroid, as surface_faces decided by the same edges.
      const double x = (faces_scratch_[f].x() + faces_scratch_[f + 1].x() + faces_scratch_[f + 2].x()) / 3.0;
      const std::size_t k = first + std::clamp(mesh_grid_.col(x), col0, col0 + (last - first)) - col0;
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
