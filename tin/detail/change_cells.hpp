#pragma once
// ChangeCells: which boxes of the TIN's domain hold faces that changed since a given version,
// for a display that keeps the mesh's faces by tile (Terrain::changes_since, surface_faces).
//
// The domain is cut into at most kMaxSide x kMaxSide cells (common/domain_tiles.hpp). An edit
// marks the cells its changed faces' bounding boxes overlap (TinTerrain::mark_changed), so the
// centroid of every face it added lies in a marked cell; a face it removed had its centroid under
// a face it added (the triangulation covers the domain once before and after), which is marked
// too. Versions and their cost: common/change_versions.hpp; mark O(cells the box overlaps), one
// branch while no display tracks.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "common/change_versions.hpp"
#include "common/domain_tiles.hpp"

namespace sb::tin::detail {

class ChangeCells {
 public:
  static constexpr std::size_t kMaxSide = 64;

  explicit ChangeCells(const Aabb2& domain) : cells_(domain, kMaxSide), versions_(cells_.size()) {}

  bool tracking() const { return versions_.tracking(); }
  void mark(const Aabb2& box) {
    if (!tracking()) return;
    const std::size_t x0 = cells_.col(box.lo.x()), x1 = cells_.col(box.hi.x());
    for (std::size_t y = cells_.row(box.lo.y()); y <= cells_.row(box.hi.y()); ++y)
      for (std::size_t x = x0; x <= x1; ++x) versions_.mark(y * cells_.cols() + x);
  }
  void mark_all() { versions_.mark_all(); }
  // The boxes of the cells marked after `after` (runs along a row merged), appended to `out`;
  // ChangeVersions::since's versions.
  std::uint64_t since(std::uint64_t after, std::vector<Aabb2>& out) {
    marked_scratch_.clear();
    const std::uint64_t next = versions_.since(after, marked_scratch_);
    const std::size_t cols = cells_.cols();
    for (std::size_t k = 0; k < marked_scratch_.size();) {
      const std::size_t first = marked_scratch_[k];
      std::size_t last = first;
      while (k + 1 < marked_scratch_.size() && marked_scratch_[k + 1] == last + 1 && (last + 1) % cols != 0)
        last = marked_scratch_[++k];
      ++k;
      const std::size_t row = first / cols;
      out.push_back({{cells_.x_edge(first % cols), cells_.y_edge(row)},
                     {cells_.x_edge(last % cols + 1), cells_.y_edge(row + 1)}});
    }
    return next;
  }
  std::size_t bytes() const { return versions_.bytes() + marked_scratch_.capacity() * sizeof(std::uint32_t); }

 private:
  DomainTiles cells_;
  ChangeVersions versions_;
  std::vector<std::uint32_t> marked_scratch_;
};

}  // namespace sb::tin::detail
