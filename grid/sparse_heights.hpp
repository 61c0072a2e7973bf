#pragma once
// SparseHeights<Real>: the heights of a GridLayout's nodes in an OpenVDB tree, storing only
// the 8 x 8 blocks of nodes that differ from a uniform height. The same reads and writes as
// HeightGrid (z, set with the float rounding carry, height, volume), so the one stamp and
// erosion kernel run on either, and give the same heights bit for bit.
//
// Mapping 2-D nodes onto OpenVDB's 3-D voxels. The grid is cut into blocks of 8 x 8 nodes;
// one block is one LeafNode<Real, 2> (4 x 4 x 4 = 64 voxels, every voxel a node: a leaf
// wastes voxels only where a block overhangs the grid's last row or column). Node (x, y)
// of block (X, Y) = (x / 8, y / 8), with (a, b) = (x % 8, y % 8), is the voxel
//   leaf origin (4 X, 4 (Y / 4), 4 (Y % 4))  +  (b / 2, 2 (b % 2) + a / 4, a % 4),
// whose offset in the leaf's buffer (16 i + 4 j + k for voxel (i, j, k)) is 8 b + a: the
// block's nodes lie row by row in its buffer. A block's 8 x 8 nodes fill its leaf and the
// leaves of 4 consecutive block rows fill the
// z levels of their InternalNode<., 2> (4 x 4 x 4 leaves: 32 x 128 nodes per internal
// node). The tree is Root -> Internal(log2 2) -> Leaf(log2 2); OpenVDB's default 5-4-3
// configuration would spend 256 KiB on its top internal node before the first leaf.
//
// Uniform regions: the tree's background value is the height most blocks share at
// construction (a flat sand bed: every block); a block that is uniform at another height
// is a tile (no leaf, 8 bytes in its internal node); tools::prune merges equal tiles
// upwards. A write to a tile block creates its leaf (filled with the tile value) unless the
// value written equals it. prune() turns blocks written since the last call whose nodes are
// all equal (bit for bit) back into tiles; the terrain calls it when erosion settles.
//
// Access: a table with one pointer per block, as tools::LeafManager keeps leaf pointers --
// to its leaf's voxel buffer, or for a tile to a shared buffer of 64 copies of the tile's
// height -- makes z() O(1) without a tree descent or a branch (a few shifts, two loads),
// and set() one branch more. The table is rebuilt from the tree after construction and
// after a prune that changed something.
//
// Memory (stats().bytes counts exactly this, checked against the allocator in
// tests/unit/sparse_heights_test.cpp; OpenVDB's memUsage() is the tree part without the
// root map's node headers):
//   per node of a block with a leaf:  sizeof(Real) + 40/64 bytes
//                                     (double: 8.625, float: 4.625 bytes/node)
//   per node of a tile or background block:  0.14 bytes
//                                     (its table pointer and state byte, 9 bytes per 64 nodes)
//   per distinct tile height (the background included): 64 * sizeof(Real) bytes
//   per internal node (32 x 128 nodes) holding a leaf or a non-background tile: 544 bytes,
//   plus its root map entry (64 float, 72 double); the tree object 1232 bytes; the list of
//   blocks written since the last prune, 4 bytes each.
// Costs: construction O(nodes) evaluations of the initial surface; z, set O(1) (set creates
// a leaf O(64) the first time it writes a tile block with another value); height O(1);
// volume O(nodes); prune O(64 * blocks written since the last prune), plus O(leaves +
// blocks) when a block became uniform.
#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "grid/grid_layout.hpp"
#include "grid/height_queries.hpp"
#include "grid/rounding_carry.hpp"

namespace sb::grid {

struct SparseTreeCounts {
  std::size_t leaves = 0;        // blocks stored voxel by voxel
  std::size_t tile_blocks = 0;   // blocks without a leaf at a height other than the background
  std::size_t internal = 0;      // internal nodes
  std::size_t root_entries = 0;  // entries of the root node's map (children and tiles)
};

template <class Real>
class SparseHeights {
  static_assert(std::is_same_v<Real, float> || std::is_same_v<Real, double>);

 public:
  static constexpr std::size_t kBlock = 8;  // nodes per block side

  SparseHeights(const GridLayout& layout, const std::function<double(const Vec2&)>& initial);
  ~SparseHeights();
  SparseHeights(const SparseHeights&) = delete;
  SparseHeights& operator=(const SparseHeights&) = delete;

  const GridLayout& layout() const { return layout_; }
  double z(std::size_t ix, std::size_t iy) const {
    return static_cast<double>(data_[block_index(ix, iy)][voxel_offset(ix, iy)]);
  }

  // Stores `target` (m) at node k; with float storage the rounding error is carried on.
  void set(std::size_t k, double target) { set(k, target, layout_.area(static_cast<std::uint32_t>(k))); }
  // The same, for callers that know the node's area (layout().area(k)) already.
  void set(std::size_t k, double target, double area) {
    const auto [ix, iy] = split(k);
    store(ix, iy, carry_.round(target, area));
  }
  // Volume (m^3) owed to the surface by rounding: true volume = volume() + carry_m3().
  double carry_m3() const { return carry_.m3(); }

  // The erosion kernel's storage concept (erosion_kernel.hpp), as HeightGrid's: node k of
  // the layout, a plain rounded store that returns its rounding error (m), and the carry.
  static constexpr bool kRounds = !std::is_same_v<Real, double>;
  double z(std::size_t k) const {
    const auto [ix, iy] = split(k);
    return z(ix, iy);
  }
  double put(std::size_t k, double target) {
    const auto [ix, iy] = split(k);
    const Real stored = static_cast<Real>(target);
    store(ix, iy, stored);
    return rounding_error(target, stored);
  }
  double& carry() { return carry_.m3(); }
  // Heights of nodes x0..x1 of row iy, in order, at out[0..x1 - x0] (the kernel's dense pass
  // runs on such copies, grid/row_window.hpp). O(x1 - x0): a block's row of 8 nodes is
  // contiguous in its buffer.
  using value_type = Real;
  void read_row(std::size_t iy, std::size_t x0, std::size_t x1, Real* out) const {
    for (std::size_t x = x0; x <= x1;) {
      const std::size_t n = std::min(kBlock - (x & 7), x1 - x + 1);
      const Real* from = data_[block_index(x, iy)] + voxel_offset(x, iy);
      for (std::size_t i = 0; i < n; ++i) out[i] = from[i];
      out += n, x += n;
    }
  }
  // Stores values[0..x1 - x0] at nodes x0..x1 of row iy where they differ (in bits) from
  // before[...], the heights the store holds there, as put() would (the values are already
  // rounded: no carry). O(x1 - x0). A block's row of up to 8 nodes is compared at once, without
  // a branch per node, and written whole where one of them changed: the others get the bits they
  // hold (before), so the heights, leaves and dirty blocks are those of put() node by node.
  void write_changed(std::size_t iy, std::size_t x0, std::size_t x1, const Real* values, const Real* before) {
    for (std::size_t x = x0; x <= x1;) {
      const std::size_t n = std::min(kBlock - (x & 7), x1 - x + 1);
      if (!same_bits(values, before, n)) store(x, iy, values, n);
      values += n, before += n, x += n;
    }
  }

  double height(const Vec2& p) const { return bilinear_height(*this, p); }
  double volume() const { return trapezoid_volume(*this); }

  // Blocks written since the last call whose nodes now all hold one height become tiles
  // again. Returns how many did.
  std::size_t prune();

  Real background() const { return background_; }
  // Model bytes: the tree's nodes and map entries, the block table, the dirty list.
  std::size_t bytes() const;
  // The tree's part of bytes(): its nodes and root map entries.
  std::size_t tree_bytes() const;
  // OpenVDB's own estimate, Tree::memUsage().
  std::size_t tree_mem_usage() const;
  SparseTreeCounts counts() const;
  // The table agrees with the tree (every node's height read through OpenVDB's accessor),
  // no leaf is left for a block outside the grid. O(nodes).
  void check(std::vector<std::string>& problems) const;

  // The voxel offset of node (ix, iy) inside its leaf (LeafNode::coordToOffset of the voxel
  // the mapping above assigns to it).
  static std::size_t voxel_offset(std::size_t ix, std::size_t iy) { return (iy & 7) << 3 | (ix & 7); }

 private:
  // Block state bits.
  static constexpr std::uint8_t kLeaf = 1;   // data_ points into the block's own leaf
  static constexpr std::uint8_t kDirty = 2;  // written since the last prune (listed in dirty_)

  struct Tree;  // the OpenVDB tree, kept out of this header (sparse_heights.cpp)

  static bool same_bits(Real a, Real b) {
    using Bits = std::conditional_t<sizeof(Real) == 8, std::uint64_t, std::uint32_t>;
    return std::bit_cast<Bits>(a) == std::bit_cast<Bits>(b);
  }
  // The same for a[0..n - 1] and b[0..n - 1].
  static bool same_bits(const Real* a, const Real* b, std::size_t n) {
    using Bits = std::conditional_t<sizeof(Real) == 8, std::uint64_t, std::uint32_t>;
    Bits differ = 0;
    for (std::size_t i = 0; i < n; ++i) differ |= std::bit_cast<Bits>(a[i]) ^ std::bit_cast<Bits>(b[i]);
    return differ == 0;
  }
  std::size_t block_index(std::size_t ix, std::size_t iy) const { return (iy >> 3) * blocks_x_ + (ix >> 3); }
  // (ix, iy) of node k without a division: k / nx as the high half of k * ceil(2^64 / nx),
  // exact for every k < 2^32 (erosion reads ~10 heights per visit by node index).
  std::pair<std::size_t, std::size_t> split(std::size_t k) const {
    __extension__ using Wide = unsigned __int128;
    const std::size_t iy = static_cast<std::size_t>((static_cast<Wide>(k) * row_reciprocal_) >> 64);
    return {k - iy * layout_.nx, iy};
  }
  void store(std::size_t ix, std::size_t iy, Real stored) {
    const std::size_t bi = block_index(ix, iy);
    std::uint8_t& state = state_[bi];
    if (!(state & kLeaf)) {
      if (same_bits(stored, data_[bi][0])) return;
      materialise(bi);
    }
    data_[bi][voxel_offset(ix, iy)] = stored;
    if (!(state & kDirty)) {
      state |= kDirty;
      dirty_.push_back(static_cast<std::uint32_t>(bi));
    }
  }
  // values[0..n - 1] at nodes ix..ix + n - 1 of row iy, all in one block, one of them other than
  // the height the block holds there (so a tile block gets its leaf, as store() would).
  void store(std::size_t ix, std::size_t iy, const Real* values, std::size_t n) {
    const std::size_t bi = block_index(ix, iy);
    std::uint8_t& state = state_[bi];
    if (!(state & kLeaf)) materialise(bi);
    std::copy(values, values + n, data_[bi] + voxel_offset(ix, iy));
    if (!(state & kDirty)) {
      state |= kDirty;
      dirty_.push_back(static_cast<std::uint32_t>(bi));
    }
  }
  Real* materialise(std::size_t block);
  void refresh_table();

  GridLayout layout_;
  std::uint64_t row_reciprocal_ = 0;  // ceil(2^64 / nx)
  std::size_t blocks_x_ = 0, blocks_y_ = 0;
  Real background_ = 0;
  std::unique_ptr<Tree> tree_;
  // Per block: its 64 heights in voxel order -- its leaf's buffer, or for a tile (or the
  // background) the buffer of 64 copies of its height shared by every block at that
  // height -- and its state bits.
  std::vector<Real*> data_;
  std::vector<std::uint8_t> state_;
  std::vector<std::unique_ptr<Real[]>> tile_buffers_;  // one per distinct tile height
  std::vector<std::uint32_t> dirty_;                   // blocks written since the last prune
  RoundingCarry<Real> carry_;
};

extern template class SparseHeights<float>;
extern template class SparseHeights<double>;

}  // namespace sb::grid
