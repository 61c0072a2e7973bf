#pragma once
// ChangeVersions: which cells of a back-end's surface changed since a given version, for a
// display that keeps a copy of the surface and brings it up to date by the cells that changed.
// The back-end decides what a cell is (the grids: 64 x 64 nodes, grid/change_tiles.hpp; the
// TIN: a box of its domain, tin/detail/tin_impl.hpp) and marks every cell a write touches.
//
// Tracking is off until the first call of since() (no memory, one predictable branch per mark):
// runs that have no display pay nothing. Once on, each cell holds the version in which it was
// last marked. Memory: 8 bytes per cell; mark O(1); since() O(cells).
#include <cstddef>
#include <cstdint>
#include <vector>

namespace sb {

class ChangeVersions {
 public:
  explicit ChangeVersions(std::size_t cells) : cells_(cells) {}

  bool tracking() const { return !versions_.empty(); }
  void mark(std::size_t cell) {
    if (tracking()) versions_[cell] = version_;
  }
  void mark_all() {
    for (std::uint64_t& v : versions_) v = version_;
  }
  // The cells marked after `after`, a value this returned before (0: the first call, which turns
  // tracking on and reports every cell), appended to `out`; returns the version to ask from
  // next time. Marks made after the call count as later.
  std::uint64_t since(std::uint64_t after, std::vector<std::uint32_t>& out) {
    if (!tracking()) {
      versions_.assign(cells_, 1);
      version_ = 1;
    }
    for (std::size_t c = 0; c < versions_.size(); ++c)
      if (versions_[c] > after) out.push_back(static_cast<std::uint32_t>(c));
    return version_++;
  }
  std::size_t bytes() const { return versions_.capacity() * sizeof(std::uint64_t); }

 private:
  std::size_t cells_;
  std::uint64_t version_ = 0;
  std::vector<std::uint64_t> versions_;  // per cell: the version of its last mark; empty: tracking off
};

}  // namespace sb
