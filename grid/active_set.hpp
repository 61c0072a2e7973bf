#pragma once
// ActiveSet: the nodes erosion visits (the paper's list L_e), as a bitmap over the grid's
// rows, visited in storage order.
//
// Membership is one bit per node, rows padded to whole 64-bit words, plus a member count
// per row; each member also keeps a 16-bit count of consecutive idle visits (a non-member's
// count is 0), held by the Idle policy: DenseIdleCounts, 16 bits per node (the dense grid),
// or BitPlaneIdleCounts, as many bits per node as idle_passes needs (the sparse grid,
// sparse_idle_counts.hpp). The policy changes only where the counts live. A node that
// transferred, and its 3 x 3 block, become members with a fresh idle count; an idle node
// stays until it has been idle `idle_passes` times in a row.
//
// Sweeps are ordered and live (avalanche order): a sweep walks the rows and the words in a
// direction that alternates between sweeps (+y +x, -y -x, +y -x, -y +x), and a node that
// becomes a member ahead of the cursor is visited in the same sweep. A run of unstable
// nodes down a slope in the sweep's direction therefore moves in one pass, instead of one
// node per pass; this is what keeps the passes needed to settle from growing with the
// resolution (erosion_kernel.hpp). The order depends only on the heights and the pass
// number, so the same input gives the same sequence of visits.
//
// Memory: 1 bit per node and 4 bytes per row, plus the counts: 2 bytes per node (dense),
// or bit_width(idle_passes - 1) bits per node (bit planes; 1 bit for the default 2).
// activate_block / idle are O(1); a sweep is O(rows + words of rows with members + visits).
#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "grid/change_tiles.hpp"

namespace sb::grid {

// One idle count per node.
class DenseIdleCounts {
 public:
  DenseIdleCounts(std::size_t nx, std::size_t ny, std::size_t /*words_per_row*/, std::uint16_t /*idle_passes*/)
      : nx_(nx), counts_(nx * ny, 0) {}
  // One more idle visit; true (and the count back to 0) when it makes idle_passes.
  bool count_up(std::size_t ix, std::size_t iy, std::uint16_t idle_passes) {
    std::uint16_t& count = counts_[iy * nx_ + ix];
    if (++count < idle_passes) return false;
    count = 0;
    return true;
  }
  // count_up for each node 64 w + b of row y with bit b of `kept` set (members of word w);
  // returns the bits of those whose count made idle_passes. With AVX-512 the 64 counts of the
  // word at once (~10 instructions), else bit by bit. Same counts as count_up per bit.
  std::uint64_t count_up_word(std::size_t y, std::size_t w, std::uint64_t kept, std::uint16_t idle_passes);
  // Counts of nodes x0..x1 of row y back to 0.
  void reset(std::size_t y, std::size_t x0, std::size_t x1) {
    for (std::size_t x = x0; x <= x1; ++x) counts_[y * nx_ + x] = 0;
  }
  // Every count back to 0.
  void clear() { std::fill(counts_.begin(), counts_.end(), std::uint16_t{0}); }
  std::size_t bytes() const { return counts_.capacity() * sizeof(std::uint16_t); }
  // Counts below idle_passes, zero for non-members.
  void check(const std::vector<std::uint64_t>& bits, std::size_t words_per_row, std::uint16_t idle_passes,
             std::vector<std::string>& problems) const;

 private:
  std::size_t nx_;
  std::vector<std::uint16_t> counts_;
};

template <class Idle>
class BasicActiveSet {
 public:
  BasicActiveSet(std::size_t nx, std::size_t ny, int idle_passes);

  // Node (ix, iy) changed: it and its 3 x 3 block (clipped to the grid) become members
  // with a fresh idle count.
  void activate_block(std::size_t ix, std::size_t iy) {
    const std::size_t y0 = iy > 0 ? iy - 1 : 0, y1 = iy + 1 < ny_ ? iy + 1 : iy;
    const std::size_t x0 = ix > 0 ? ix - 1 : 0, x1 = ix + 1 < nx_ ? ix + 1 : ix;
    for (std::size_t y = y0; y <= y1; ++y) {
      set_bits(y, x0, x1);
      idle_.reset(y, x0, x1);
    }
  }
  // Node (ix, iy) alone becomes a member with a fresh idle count.
  void activate(std::size_t ix, std::size_t iy) {
    set_bits(iy, ix, ix);
    idle_.reset(iy, ix, ix);
  }
  // Node (ix, iy) was visited and stayed put: it leaves after idle_passes such visits in a row.
  void idle(std::size_t ix, std::size_t iy) {
    if (!idle_.count_up(ix, iy, idle_passes_)) return;
    std::uint64_t& w = bits_[iy * words_per_row_ + ix / 64];
    w &= ~(std::uint64_t{1} << (ix % 64));
    --row_count_[iy];
    --size_;
  }

  // The first and last member of row y (false: none). O(words of the row).
  bool row_span(std::size_t y, std::size_t& x0, std::size_t& x1) const {
    if (row_count_[y] == 0) return false;
    const std::uint64_t* row = bits_.data() + y * words_per_row_;
    std::size_t a = 0, b = words_per_row_ - 1;
    while (row[a] == 0) ++a;
    while (row[b] == 0) --b;
    x0 = a * 64 + static_cast<std::size_t>(std::countr_zero(row[a]));
    x1 = b * 64 + 63 - static_cast<std::size_t>(std::countl_zero(row[b]));
    return true;
  }
  // The rows holding members (y0..y1, meaningless when empty()) and the nodes between the
  // first and last member of each row, summed. O(rows + words of the rows with members).
  struct Spans {
    std::size_t y0, y1, nodes;
  };
  Spans spans() const {
    Spans r{ny_, 0, 0};
    for (std::size_t y = 0; y < ny_; ++y) {
      if (y % 8 == 0 && y + 8 <= ny_) {  // eight rows without members at once (most rows, as a rule)
        std::uint32_t any = 0;
        for (std::size_t i = 0; i < 8; ++i) any |= row_count_[y + i];
        if (any == 0) {
          y += 7;
          continue;
        }
      }
      std::size_t x0, x1;
      if (!row_span(y, x0, x1)) continue;
      r.y0 = std::min(r.y0, y);
      r.y1 = y;
      r.nodes += x1 - x0 + 1;
    }
    return r;
  }

  // The bookkeeping of a pass that visited every node of rows y0..y1 once, as a sweep would
  // leave it: the nodes of the 3 x 3 blocks around the nodes set in `centres` (those that
  // transferred) become members with a fresh idle count; every other member counts one idle
  // visit and leaves after idle_passes in a row. `centres` holds rows y0..y1 (words_per_row()
  // words each, padding clear), and every member lies in rows y0..y1 before the call. (A
  // sweep differs only for a node activated before its own idle visit: it starts at 1, here
  // at 0.) The dense erosion pass keeps the set this way. `x0`..`x1`: columns that hold every
  // member and every centre of those rows (the words outside them, widened by the blocks'
  // column, are left alone: nothing changes there). O(words of columns x0 - 1..x1 + 1 of rows
  // y0 - 1..y1 + 1 + members).
  void assign_blocks(const std::vector<std::uint64_t>& centres, std::size_t y0, std::size_t y1, std::size_t x0 = 0,
                     std::size_t x1 = ~std::size_t{0}) {
    const std::size_t W = words_per_row_;
    const unsigned tail = static_cast<unsigned>(nx_ % 64);
    const std::uint64_t last_mask = tail == 0 ? ~std::uint64_t{0} : (std::uint64_t{1} << tail) - 1;
    const std::size_t ya = y0 > 0 ? y0 - 1 : 0, yb = y1 + 1 < ny_ ? y1 + 1 : y1;
    const std::size_t wa = x0 > 0 ? (x0 - 1) / 64 : 0, wb = (x1 < nx_ - 1 ? x1 + 1 : nx_ - 1) / 64;
    const auto centre = [&](std::size_t y, std::size_t w) {
      return y >= y0 && y <= y1 ? centres[(y - y0) * W + w] : std::uint64_t{0};
    };
    std::vector<std::uint64_t> rows(W + 2, 0);  // centres of rows y - 1..y + 1, ored; a clear word each side
    for (std::size_t y = ya; y <= yb; ++y) {
      std::uint32_t count = row_count_[y];
      for (std::size_t w = wa; w <= wb; ++w) {
        rows[w + 1] = centre(y, w) | (y > 0 ? centre(y - 1, w) : 0) | (y + 1 < ny_ ? centre(y + 1, w) : 0);
        count -= static_cast<std::uint32_t>(bits_in_word(bits_[y * W + w]));
      }
      for (std::size_t w = wa; w <= wb; ++w) {
        // Rows y - 1, y, y + 1, then one column each way (bits carried across words).
        const std::uint64_t m = rows[w + 1];
        std::uint64_t d = m | (m << 1) | (rows[w] >> 63) | (m >> 1) | (rows[w + 2] << 63);
        if (w + 1 == W) d &= last_mask;
        if (d == 0 && bits_[y * W + w] == 0) continue;
        std::uint64_t& word = bits_[y * W + w];
        std::uint64_t kept = word & ~d;  // members not in a block: one more idle visit
        if constexpr (requires { idle_.count_up_word(y, w, kept, idle_passes_); }) {
          if (kept != 0) kept &= ~idle_.count_up_word(y, w, kept, idle_passes_);
        } else {
          for (std::uint64_t b = kept; b != 0; b &= b - 1) {
            const auto bit = static_cast<unsigned>(std::countr_zero(b));
            if (idle_.count_up(w * 64 + bit, y, idle_passes_)) kept &= ~(std::uint64_t{1} << bit);
          }
        }
        for (std::uint64_t b = d; b != 0;) {  // fresh counts, a run of bits at a time
          const auto lo_bit = static_cast<unsigned>(std::countr_zero(b));
          const std::uint64_t from = b >> lo_bit;
          const unsigned run =
              from == ~std::uint64_t{0} >> lo_bit ? 64 - lo_bit : static_cast<unsigned>(std::countr_one(from));
          idle_.reset(y, w * 64 + lo_bit, w * 64 + lo_bit + run - 1);
          b = lo_bit + run >= 64 ? 0 : b & (~std::uint64_t{0} << (lo_bit + run));
        }
        word = d | kept;
        if (d != 0) changes_.mark(y, w);
        count += static_cast<std::uint32_t>(bits_in_word(word));
      }
      size_ = size_ - row_count_[y] + count;
      row_count_[y] = count;
    }
  }
  std::size_t words_per_row() const { return words_per_row_; }
  // Every node a member with a fresh idle count (tests and benchmarks). O(nodes).
  void activate_all() {
    for (std::size_t iy = 0; iy < ny_; ++iy) {
      set_bits(iy, 0, nx_ - 1);
      idle_.reset(iy, 0, nx_ - 1);
    }
  }
  // The number of the next sweep (it chooses the sweep's direction, see above), counted up.
  // Shared by the active set's sweeps and the dense erosion pass (erosion_kernel.hpp).
  unsigned next_sweep() { return sweeps_++; }

  // One ordered, live sweep (see above); direction from the pass number. Calls
  // visit(ix, iy), which returns true when the node transferred (the caller then activates
  // its block) -- the set marks idle nodes itself. Stops after max_visits visits; the
  // nodes not reached stay members. Returns the number of visits.
  template <class Visit>
  std::size_t sweep(std::size_t max_visits, Visit&& visit);

  // The tiles of the nodes that became members (with a fresh count) since a version: every
  // height a grid writes is at such a node (change_tiles.hpp).
  ChangeTiles& changes() { return changes_; }

  bool empty() const { return size_ == 0; }
  std::size_t size() const { return size_; }
  bool contains(std::size_t ix, std::size_t iy) const {
    return (bits_[iy * words_per_row_ + ix / 64] >> (ix % 64)) & 1u;
  }
  bool contains(std::uint32_t k) const { return contains(k % nx_, k / nx_); }
  std::size_t bytes() const;
  // Bookkeeping invariants: row counts and the total match the bits, padding bits clear,
  // idle counts below idle_passes. O(nodes).
  void check(std::vector<std::string>& problems) const;

 private:
  // Set bits in a word (no popcnt instruction on baseline x86-64: std::popcount is a
  // library call there). bits_in loops per bit (activate_block adds at most 3 per word);
  // bits_in_word is the branch-free SWAR count.
  static int bits_in(std::uint64_t w) {
    int n = 0;
    for (; w != 0; w &= w - 1) ++n;
    return n;
  }
  static int bits_in_word(std::uint64_t w) {
    w = w - ((w >> 1) & 0x5555555555555555ull);
    w = (w & 0x3333333333333333ull) + ((w >> 2) & 0x3333333333333333ull);
    w = (w + (w >> 4)) & 0x0F0F0F0F0F0F0F0Full;
    return static_cast<int>((w * 0x0101010101010101ull) >> 56);
  }
  void set_bits(std::size_t y, std::size_t x0, std::size_t x1) {
    std::uint64_t* row = bits_.data() + y * words_per_row_;
    for (std::size_t x = x0; x <= x1;) {
      const std::size_t wi = x / 64, lo = x % 64, hi = std::min<std::size_t>(63, lo + (x1 - x));
      const std::uint64_t mask =
          (hi == 63 ? ~std::uint64_t{0} : (std::uint64_t{1} << (hi + 1)) - 1) & ~((std::uint64_t{1} << lo) - 1);
      const int added = bits_in(mask & ~row[wi]);
      row[wi] |= mask;
      changes_.mark(y, wi);
      row_count_[y] += static_cast<std::uint32_t>(added);
      size_ += static_cast<std::size_t>(added);
      x += hi - lo + 1;
    }
  }

  std::size_t nx_, ny_, words_per_row_;
  std::uint16_t idle_passes_;
  std::size_t size_ = 0;
  unsigned sweeps_ = 0;                   // sweeps so far: chooses the next sweep's direction
  std::vector<std::uint64_t> bits_;       // membership, row-major, rows padded to words
  std::vector<std::uint32_t> row_count_;  // members per row
  Idle idle_;                             // consecutive idle visits of the members
  ChangeTiles changes_;                   // tiles that gained members, for displays
};

template <class Idle>
template <class Visit>
std::size_t BasicActiveSet<Idle>::sweep(std::size_t max_visits, Visit&& visit) {
  const unsigned pass = next_sweep();
  const bool y_up = pass % 2 == 0;
  const bool x_up = (pass / 2) % 2 == 0;
  std::size_t visits = 0;
  for (std::size_t r = 0; r < ny_; ++r) {
    const std::size_t iy = y_up ? r : ny_ - 1 - r;
    // Live: a node activated in this row (or the next ones) ahead of the cursor is seen.
    if (row_count_[iy] == 0) continue;
    const std::uint64_t* row = bits_.data() + iy * words_per_row_;
    for (std::size_t c = 0; c < words_per_row_; ++c) {
      const std::size_t wi = x_up ? c : words_per_row_ - 1 - c;
      // Bits of this word still ahead of the cursor.
      std::uint64_t ahead = ~std::uint64_t{0};
      while (const std::uint64_t live = row[wi] & ahead) {
        if (visits == max_visits) return visits;
        const int b = x_up ? std::countr_zero(live) : 63 - std::countl_zero(live);
        ahead = x_up ? (b == 63 ? 0 : ~std::uint64_t{0} << (b + 1)) : ((std::uint64_t{1} << b) - 1);
        const std::size_t ix = wi * 64 + static_cast<std::size_t>(b);
        ++visits;
        if (!visit(ix, iy)) idle(ix, iy);
      }
    }
  }
  return visits;
}

using ActiveSet = BasicActiveSet<DenseIdleCounts>;
extern template class BasicActiveSet<DenseIdleCounts>;

}  // namespace sb::grid
