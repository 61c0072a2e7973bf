#include "harness/interactive/display_feed.hpp"

#include <algorithm>

namespace sb {

namespace {

constexpr std::size_t kTile = 64;  // the feed's pending tiles: nodes per side

}  // namespace

DisplayFeed::DisplayFeed(const Terrain& terrain, double z_ref, bool tiles)
    : lattice_(tiles ? terrain.lattice() : std::nullopt), z_ref_(z_ref) {
  if (!lattice_) return;
  heights_.assign(lattice_->nx * lattice_->ny, 0.0f);
  tile_cols_ = (lattice_->nx + kTile - 1) / kTile;
  pending_.assign(tile_cols_ * ((lattice_->ny + kTile - 1) / kTile), 0);
}

bool DisplayFeed::publish(Terrain& terrain, bool changed, std::vector<double>& stamp_times_s) {
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

std::shared_ptr<const DisplayMesh> DisplayFeed::mesh() const {
  std::lock_guard lock(mutex_);
  return mesh_;
}

}  // namespace sb
