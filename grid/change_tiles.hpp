#pragma once
// ChangeTiles: which tiles of a grid's nodes were written since a given version
// (common/change_versions.hpp), for a display that keeps a copy of the heights.
//
// A tile is 64 x 64 nodes: one word of the active set's membership bitmap wide, so a word the
// active set touches names its tile directly. Every height a grid writes belongs to a node that
// then joins the active set (a stamp's changed nodes and their blocks, erosion's transferring
// nodes and their blocks, the cascade's changed fine nodes), so the active set marks the tile of
// every word it adds members to, and the marks cover every changed height.
// Memory once tracking: 8 bytes per tile (about 0.002 bytes per node).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "common/change_versions.hpp"

namespace sb::grid {

class ChangeTiles {
 public:
  static constexpr std::size_t kSide = 64;  // nodes per tile side

  ChangeTiles(std::size_t words_per_row, std::size_t ny)
      : cols_(words_per_row), rows_((ny + kSide - 1) / kSide), versions_(cols_ * rows_) {}

  // The word `word` of row y of the membership bitmap gained members: its tile changed.
  void mark(std::size_t y, std::size_t word) { versions_.mark((y / kSide) * cols_ + word); }
  void mark_all() { versions_.mark_all(); }  // every tile changed
  // The tiles (index row * cols() + column) marked after `after` (ChangeVersions::since).
  std::uint64_t since(std::uint64_t after, std::vector<std::uint32_t>& out) { return versions_.since(after, out); }
  std::size_t cols() const { return cols_; }
  std::size_t rows() const { return rows_; }
  std::size_t bytes() const { return versions_.bytes(); }

 private:
  std::size_t cols_, rows_;
  ChangeVersions versions_;
};

}  // namespace sb::grid
