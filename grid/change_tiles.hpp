#pragma once
// ChangeTiles: which tiles of a grid's nodes were written since a given version, for a display
// that keeps a copy of the heights and brings it up to date by the tiles that changed.
//
// A tile is 64 x 64 nodes: one word of the active set's membership bitmap wide, so a word the
// active set touches names its tile directly. Every height a grid writes belongs to a node that
// then joins the active set (a stamp's changed nodes and their blocks, erosion's transferring
// nodes and their blocks, the cascade's changed fine nodes), so the active set marks the tile of
// every word it adds members to, and the marks cover every changed height.
//
// Tracking is off until the first call of since() (no memory, one predictable branch per mark):
// runs that have no display pay nothing. Once on, each tile holds the version in which it was
// last marked. Memory: 8 bytes per tile (about 0.002 bytes per node); mark O(1); since() O(tiles).
#include <cstddef>
#include <cstdint>
#include <vector>

namespace sb::grid {

class ChangeTiles {
 public:
  static constexpr std::size_t kSide = 64;  // nodes per tile side

  ChangeTiles(std::size_t words_per_row, std::size_t ny) : cols_(words_per_row), rows_((ny + kSide - 1) / kSide) {}

  // The word `word` of row y of the membership bitmap gained members: its tile changed.
  void mark(std::size_t y, std::size_t word) {
    if (!versions_.empty()) versions_[(y / kSide) * cols_ + word] = version_;
  }
  // Every tile changed.
  void mark_all() {
    for (std::uint64_t& v : versions_) v = version_;
  }
  // The tiles (index row * cols() + column) marked after `after`, a value this returned before
  // (0: the first call, which turns tracking on and reports every tile), appended to `out`;
  // returns the version to ask from next time. Marks made after the call count as later.
  std::uint64_t since(std::uint64_t after, std::vector<std::uint32_t>& out) {
    if (versions_.empty()) {
      versions_.assign(cols_ * rows_, 1);
      version_ = 1;
    }
    for (std::size_t t = 0; t < versions_.size(); ++t)
      if (versions_[t] > after) out.push_back(static_cast<std::uint32_t>(t));
    return version_++;
  }
  std::size_t cols() const { return cols_; }
  std::size_t rows() const { return rows_; }
  std::size_t bytes() const { return versions_.capacity() * sizeof(std::uint64_t); }

 private:
  std::size_t cols_, rows_;
  std::uint64_t version_ = 0;
  std::vector<std::uint64_t> versions_;  // per tile: the version of its last mark; empty: tracking off
};

}  // namespace sb::grid
