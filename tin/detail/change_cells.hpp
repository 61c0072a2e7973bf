#pragma once
// ChangeCells: which boxes of the TIN's domain hold faces that changed since a given version,
// for a display that keeps the mesh's faces by tile (Terrain::changes_since, surface_faces).
//
// The domain is cut into at most kMaxSide x kMaxSide cells of about equal sides. An edit marks
// the cells its changed faces' bounding boxes overlap (TinTerrain::mark_changed), so the centroid
// of every face it added lies in a marked cell; a face it removed had its centroid under a face
// it added (the triangulation covers the domain once before and after), which is marked too.
// Versions and their cost: common/change_versions.hpp; mark O(cells the box overlaps), one
// branch while no display tracks.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "common/change_versions.hpp"
#include "common/geometry.hpp"

namespace sb::tin::detail {

class ChangeCells {
 public:
  static constexpr std::size_t kMaxSide = 64;

  explicit ChangeCells(const Aabb2& domain)
      : domain_(domain),
        cols_(side_cells(domain, 0)),
        rows_(side_cells(domain, 1)),
        cell_(domain.hi - domain.lo),
        versions_(cols_ * rows_) {
    cell_.x() /= static_cast<double>(cols_);
    cell_.y() /= static_cast<double>(rows_);
  }

  bool tracking() const { return versions_.tracking(); }
  void mark(const Aabb2& box) {
    if (!tracking()) return;
    const std::size_t x0 = col(box.lo.x()), x1 = col(box.hi.x()), y0 = row(box.lo.y()), y1 = row(box.hi.y());
    for (std::size_t y = y0; y <= y1; ++y)
      for (std::size_t x = x0; x <= x1; ++x) versions_.mark(y * cols_ + x);
  }
  void mark_all() { versions_.mark_all(); }
  // The boxes of the cells marked after `after` (runs along a row merged), appended to `out`;
  // ChangeVersions::since's versions. Border cells reach a cell beyond the domain.
  std::uint64_t since(std::uint64_t after, std::vector<Aabb2>& out) {
    cells_scratch_.clear();
    const std::uint64_t next = versions_.since(after, cells_scratch_);
    for (std::size_t k = 0; k < cells_scratch_.size();) {
      const std::size_t first = cells_scratch_[k];
      std::size_t last = first;
      while (k + 1 < cells_scratch_.size() && cells_scratch_[k + 1] == last + 1 && (last + 1) % cols_ != 0)
        last = cells_scratch_[++k];
      ++k;
      out.push_back({corner(first % cols_, first / cols_), corner(last % cols_ + 1, first / cols_ + 1)});
    }
    return next;
  }
  std::size_t bytes() const { return versions_.bytes() + cells_scratch_.capacity() * sizeof(std::uint32_t); }

 private:
  static std::size_t side_cells(const Aabb2& d, int axis) {
    const double w = d.hi.x() - d.lo.x(), h = d.hi.y() - d.lo.y();
    const double longest = std::max(w, h), side = axis == 0 ? w : h;
    if (!(longest > 0.0)) return 1;
    return std::clamp<std::size_t>(static_cast<std::size_t>(std::ceil(kMaxSide * side / longest)), 1, kMaxSide);
  }
  std::size_t col(double x) const { return index((x - domain_.lo.x()) / cell_.x(), cols_); }
  std::size_t row(double y) const { return index((y - domain_.lo.y()) / cell_.y(), rows_); }
  static std::size_t index(double u, std::size_t n) {
    if (!(u > 0.0)) return 0;  // (NaN too)
    return std::min(static_cast<std::size_t>(u), n - 1);
  }
  // Cell corner (i, j); the border's corners one cell outside the domain.
  Vec2 corner(std::size_t i, std::size_t j) const {
    const auto at = [](std::size_t k, std::size_t n, double lo, double step) {
      const double u = k == 0 ? -1.0 : k == n ? static_cast<double>(n) + 1.0 : static_cast<double>(k);
      return lo + u * step;
    };
    return {at(i, cols_, domain_.lo.x(), cell_.x()), at(j, rows_, domain_.lo.y(), cell_.y())};
  }

  Aabb2 domain_;
  std::size_t cols_, rows_;
  Vec2 cell_;
  ChangeVersions versions_;
  std::vector<std::uint32_t> cells_scratch_;
};

}  // namespace sb::tin::detail
