// The only translation unit that includes OpenVDB (its headers cost ~15 s to compile).
#include "grid/sparse_heights.hpp"

#include <openvdb/tools/Prune.h>
#include <openvdb/tree/Tree.h>
#include <openvdb/tree/ValueAccessor.h>

#include <algorithm>
#include <array>
#include <map>

namespace sb::grid {

template <class Real>
struct SparseHeights<Real>::Tree {
  using Leaf = openvdb::tree::LeafNode<Real, 2>;
  using Internal = openvdb::tree::InternalNode<Leaf, 2>;
  using Root = openvdb::tree::RootNode<Internal>;
  using Type = openvdb::tree::Tree<Root>;
  static_assert(Leaf::SIZE == kBlock * kBlock, "one leaf holds one block");

  // Bytes of one entry of the root node's std::map<Coord, NodeStruct>: a red-black tree
  // node's header (colour and three links) and the pair (Coord; child pointer and a tile
  // of value and active flag), each member padded to pointer alignment.
  static constexpr std::size_t kRootEntryBytes =
      4 * sizeof(void*) + 16 + sizeof(void*) + ((sizeof(Real) + 1 + sizeof(void*) - 1) / sizeof(void*)) * sizeof(void*);

  explicit Tree(Real background) : tree(background) {}

  // Origin of block (bx, by)'s leaf (see the mapping in the header).
  static openvdb::Coord origin(std::size_t bx, std::size_t by) {
    return {static_cast<openvdb::Int32>(4 * bx), static_cast<openvdb::Int32>(4 * (by >> 2)),
            static_cast<openvdb::Int32>(4 * (by & 3))};
  }
  // The voxel of node (ix, iy).
  static openvdb::Coord voxel(std::size_t ix, std::size_t iy) {
    const std::size_t a = ix & 7, b = iy & 7;
    return origin(ix >> 3, iy >> 3) + openvdb::Coord(static_cast<openvdb::Int32>(b >> 1),
                                                     static_cast<openvdb::Int32>(2 * (b & 1) + (a >> 2)),
                                                     static_cast<openvdb::Int32>(a & 3));
  }

  Type tree;
};

template <class Real>
SparseHeights<Real>::SparseHeights(const GridLayout& layout, const std::function<double(const Vec2&)>& initial)
    : layout_(layout),
      row_reciprocal_(~std::uint64_t{0} / layout.nx + 1),
      blocks_x_((layout.nx + kBlock - 1) / kBlock),
      blocks_y_((layout.ny + kBlock - 1) / kBlock) {
  const std::size_t block_count = blocks_x_ * blocks_y_;
  // Block (bx, by)'s heights, in voxel order; a block overhanging the grid repeats its first
  // node in the voxels outside it. Plain rounding: the initial volume is what is stored.
  // Returns whether every node has the first one's height. Evaluated block by block, twice
  // for a block that is not uniform, so that building holds one block's heights at a time
  // rather than the whole grid's (which a sparse grid exists to avoid).
  std::array<Real, kBlock * kBlock> v;
  const auto fill_block = [&](std::size_t bx, std::size_t by) {
    const Real first = static_cast<Real>(initial(layout_.position(bx * kBlock, by * kBlock)));
    v.fill(first);
    bool uniform = true;
    for (std::size_t iy = by * kBlock; iy < std::min(layout_.ny, (by + 1) * kBlock); ++iy)
      for (std::size_t ix = bx * kBlock; ix < std::min(layout_.nx, (bx + 1) * kBlock); ++ix) {
        const Real z = static_cast<Real>(initial(layout_.position(ix, iy)));
        v[voxel_offset(ix, iy)] = z;
        if (!same_bits(z, first)) uniform = false;
      }
    return uniform;
  };
  // First pass: each block's first height and whether it is uniform at it.
  std::vector<Real> first_height(block_count);
  std::vector<std::uint8_t> uniform(block_count);
  for (std::size_t by = 0; by < blocks_y_; ++by)
    for (std::size_t bx = 0; bx < blocks_x_; ++bx) {
      const std::size_t b = by * blocks_x_ + bx;
      uniform[b] = fill_block(bx, by);
      first_height[b] = v[0];
    }
  // The background: the height most uniform blocks share (ties: the first such block);
  // with no uniform block it does not matter.
  std::map<Real, std::size_t> uniform_heights;
  background_ = first_height[0];
  std::size_t most = 0;
  for (std::size_t b = 0; b < block_count; ++b) {
    if (!uniform[b]) continue;
    const std::size_t n = ++uniform_heights[first_height[b]];
    if (n > most) most = n, background_ = first_height[b];
  }

  tree_ = std::make_unique<Tree>(background_);
  for (std::size_t by = 0; by < blocks_y_; ++by)
    for (std::size_t bx = 0; bx < blocks_x_; ++bx) {
      const std::size_t b = by * blocks_x_ + bx;
      if (uniform[b]) {
        if (!same_bits(first_height[b], background_))
          tree_->tree.addTile(1, Tree::origin(bx, by), first_height[b], /*active=*/false);
      } else {
        fill_block(bx, by);
        std::copy(v.begin(), v.end(), tree_->tree.touchLeaf(Tree::origin(bx, by))->buffer().data());
      }
    }
  openvdb::tools::prune(tree_->tree, Real(0), /*threaded=*/false);
  data_.resize(block_count);
  state_.assign(block_count, 0);
  refresh_table();
}

template <class Real>
SparseHeights<Real>::~SparseHeights() = default;

template <class Real>
void SparseHeights<Real>::refresh_table() {
  openvdb::tree::ValueAccessor<const typename Tree::Type, /*IsSafe=*/false> acc(tree_->tree);
  // One shared buffer per distinct tile height, found by its bits.
  std::vector<std::unique_ptr<Real[]>> buffers;
  std::map<std::conditional_t<sizeof(Real) == 8, std::uint64_t, std::uint32_t>, Real*> by_height;
  const auto tile_buffer = [&](Real z) {
    Real*& buffer = by_height[std::bit_cast<typename decltype(by_height)::key_type>(z)];
    if (!buffer) {
      buffers.push_back(std::make_unique<Real[]>(kBlock * kBlock));
      buffer = buffers.back().get();
      std::fill(buffer, buffer + kBlock * kBlock, z);
    }
    return buffer;
  };
  for (std::size_t by = 0; by < blocks_y_; ++by)
    for (std::size_t bx = 0; bx < blocks_x_; ++bx) {
      const openvdb::Coord o = Tree::origin(bx, by);
      const std::size_t b = by * blocks_x_ + bx;
      // The table writes through the leaf's buffer; the const accessor only finds it.
      if (const auto* leaf = acc.probeConstLeaf(o)) {
        data_[b] = const_cast<Real*>(leaf->buffer().data());
        state_[b] |= kLeaf;
      } else {
        data_[b] = tile_buffer(acc.getValue(o));
        state_[b] &= static_cast<std::uint8_t>(~kLeaf);
      }
    }
  tile_buffers_ = std::move(buffers);
}

template <class Real>
Real* SparseHeights<Real>::materialise(std::size_t block) {
  const std::size_t bx = block % blocks_x_, by = block / blocks_x_;
  // touchLeaf fills the new leaf with the tile's value.
  Real* data = tree_->tree.touchLeaf(Tree::origin(bx, by))->buffer().data();
  data_[block] = data;
  state_[block] |= kLeaf;
  return data;
}

template <class Real>
std::size_t SparseHeights<Real>::prune() {
  std::size_t pruned = 0;
  for (std::uint32_t b : dirty_) {
    state_[b] &= static_cast<std::uint8_t>(~kDirty);
    if (!(state_[b] & kLeaf)) continue;
    Real* data = data_[b];
    const std::size_t bx = b % blocks_x_, by = b / blocks_x_;
    const Real first = data[0];  // node (8 bx, 8 by): always inside the grid
    bool uniform = true;
    for (std::size_t iy = by * kBlock; uniform && iy < std::min(layout_.ny, (by + 1) * kBlock); ++iy)
      for (std::size_t ix = bx * kBlock; ix < std::min(layout_.nx, (bx + 1) * kBlock); ++ix)
        if (!same_bits(data[voxel_offset(ix, iy)], first)) {
          uniform = false;
          break;
        }
    if (!uniform) continue;
    // Voxels outside the grid take the same value, so that OpenVDB sees a constant leaf.
    std::fill(data, data + kBlock * kBlock, first);
    ++pruned;
  }
  dirty_.clear();
  if (pruned > 0) {
    openvdb::tools::prune(tree_->tree, Real(0), /*threaded=*/false);
    refresh_table();
  }
  return pruned;
}

template <class Real>
SparseTreeCounts SparseHeights<Real>::counts() const {
  SparseTreeCounts c;
  c.leaves = tree_->tree.leafCount();
  c.internal = tree_->tree.nonLeafCount() - 1;  // without the root
  c.root_entries = tree_->tree.root().getTableSize();
  for (std::size_t b = 0; b < data_.size(); ++b)
    if (!(state_[b] & kLeaf) && !same_bits(data_[b][0], background_)) ++c.tile_blocks;
  return c;
}

template <class Real>
std::size_t SparseHeights<Real>::tree_bytes() const {
  const SparseTreeCounts c = counts();
  return sizeof(Tree) + c.leaves * (sizeof(typename Tree::Leaf) + kBlock * kBlock * sizeof(Real)) +
         c.internal * sizeof(typename Tree::Internal) + c.root_entries * Tree::kRootEntryBytes;
}

template <class Real>
std::size_t SparseHeights<Real>::bytes() const {
  const std::size_t tiles = tile_buffers_.capacity() * sizeof(std::unique_ptr<Real[]>) +
                            tile_buffers_.size() * kBlock * kBlock * sizeof(Real);
  return tree_bytes() + tiles + data_.capacity() * sizeof(Real*) + state_.capacity() +
         dirty_.capacity() * sizeof(std::uint32_t);
}

template <class Real>
std::size_t SparseHeights<Real>::tree_mem_usage() const {
  return static_cast<std::size_t>(tree_->tree.memUsage());
}

template <class Real>
void SparseHeights<Real>::check(std::vector<std::string>& problems) const {
  openvdb::tree::ValueAccessor<const typename Tree::Type, /*IsSafe=*/false> acc(tree_->tree);
  std::size_t wrong = 0;
  for (std::size_t iy = 0; iy < layout_.ny; ++iy)
    for (std::size_t ix = 0; ix < layout_.nx; ++ix) {
      const Real in_tree = acc.getValue(Tree::voxel(ix, iy));
      if (!same_bits(in_tree, static_cast<Real>(z(ix, iy))) && ++wrong <= 3)
        problems.push_back("sparse: node (" + std::to_string(ix) + ", " + std::to_string(iy) + ") reads " +
                           std::to_string(z(ix, iy)) + " from its table, " + std::to_string(in_tree) + " in the tree");
    }
  if (wrong > 3) problems.push_back("sparse: " + std::to_string(wrong) + " nodes disagree with the tree in all");
  std::size_t listed = 0;
  for (std::size_t b = 0; b < data_.size(); ++b) {
    const auto* leaf = acc.probeConstLeaf(Tree::origin(b % blocks_x_, b / blocks_x_));
    if (leaf ? (leaf->buffer().data() != data_[b] || !(state_[b] & kLeaf)) : (state_[b] & kLeaf) != 0)
      problems.push_back("sparse: block " + std::to_string(b) + " table entry does not match its leaf");
    if (!leaf)
      for (std::size_t v = 0; v < kBlock * kBlock; ++v)
        if (!same_bits(data_[b][v], data_[b][0]))
          problems.push_back("sparse: tile block " + std::to_string(b) + " reads a buffer that is not uniform");
    listed += leaf ? 1 : 0;
  }
  if (listed != tree_->tree.leafCount())
    problems.push_back("sparse: " + std::to_string(tree_->tree.leafCount()) + " leaves, " + std::to_string(listed) +
                       " inside the grid");
  std::vector<std::uint8_t> in_list(data_.size(), 0);
  for (std::uint32_t b : dirty_) {
    if (b >= data_.size() || in_list[b]++)
      problems.push_back("sparse: dirty list entry " + std::to_string(b) + " out of range or repeated");
  }
  for (std::size_t b = 0; b < data_.size(); ++b)
    if (((state_[b] & kDirty) != 0) != (in_list[b] != 0))
      problems.push_back("sparse: block " + std::to_string(b) + " dirty flag disagrees with the list");
}

template class SparseHeights<float>;
template class SparseHeights<double>;

}  // namespace sb::grid
