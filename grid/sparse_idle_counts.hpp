#pragma once
// BitPlaneIdleCounts: the active set's idle counts (active_set.hpp's Idle policy) for the
// sparse grid, as bit planes beside the membership bitmap: a count below idle_passes needs
// P = bit_width(idle_passes - 1) bits, so each 64-node word of the bitmap has P words of
// counts, bit p of node b's count in bit b of plane p. The default idle_passes = 2 needs one
// bit per node (the dense policy: 16); idle_passes = 1 none.
//
// Memory: P / 8 bytes per node (rows padded to 64 nodes). count_up O(P); count_up_word O(P)
// for a word's 64 nodes; reset O(P) per bitmap word it touches (a run of nodes is cleared with
// one mask per word and plane).
#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "grid/active_set.hpp"

namespace sb::grid {

class BitPlaneIdleCounts {
 public:
  BitPlaneIdleCounts(std::size_t /*nx*/, std::size_t ny, std::size_t words_per_row, std::uint16_t idle_passes)
      : words_per_row_(words_per_row),
        planes_(idle_passes > 1 ? std::bit_width(static_cast<unsigned>(idle_passes - 1)) : 0),
        bits_(words_per_row * ny * planes_, 0) {}

  // One more idle visit; true (and the count back to 0) when it makes idle_passes.
  bool count_up(std::size_t ix, std::size_t iy, std::uint16_t idle_passes) {
    std::uint64_t* w = bits_.data() + (iy * words_per_row_ + ix / 64) * planes_;
    const unsigned b = ix % 64;
    unsigned count = 0;
    for (unsigned p = 0; p < planes_; ++p) count |= static_cast<unsigned>((w[p] >> b) & 1u) << p;
    if (++count >= idle_passes) count = 0;
    for (unsigned p = 0; p < planes_; ++p)
      w[p] = (w[p] & ~(std::uint64_t{1} << b)) | (static_cast<std::uint64_t>((count >> p) & 1u) << b);
    return count == 0;
  }
  // count_up for each node 64 w + b of row y with bit b of `kept` set; returns the bits of those
  // whose count made idle_passes. The 64 counts at once, as bit-sliced arithmetic: a ripple
  // carry through the planes, a compare with idle_passes, a clear. O(P) word operations. Same
  // counts as count_up per bit (a count reaching idle_passes = 2^P carries out of the planes,
  // leaving them 0, which the compare with idle_passes' low P bits, all 0, finds).
  std::uint64_t count_up_word(std::size_t y, std::size_t w, std::uint64_t kept, std::uint16_t idle_passes) {
    std::uint64_t* plane = bits_.data() + (y * words_per_row_ + w) * planes_;
    std::uint64_t carry = kept;
    for (unsigned p = 0; p < planes_ && carry != 0; ++p) {
      const std::uint64_t next = plane[p] & carry;
      plane[p] ^= carry;
      carry = next;
    }
    std::uint64_t reached = kept;
    for (unsigned p = 0; p < planes_; ++p) reached &= (idle_passes >> p) & 1u ? plane[p] : ~plane[p];
    for (unsigned p = 0; p < planes_; ++p) plane[p] &= ~reached;
    return reached;
  }
  // Counts of nodes x0..x1 of row y back to 0.
  void reset(std::size_t y, std::size_t x0, std::size_t x1) {
    for (std::size_t x = x0; x <= x1;) {
      const std::size_t lo = x % 64, hi = std::min<std::size_t>(63, lo + (x1 - x));
      const std::uint64_t keep =
          ~((hi == 63 ? ~std::uint64_t{0} : (std::uint64_t{1} << (hi + 1)) - 1) & ~((std::uint64_t{1} << lo) - 1));
      std::uint64_t* w = bits_.data() + (y * words_per_row_ + x / 64) * planes_;
      for (unsigned p = 0; p < planes_; ++p) w[p] &= keep;
      x += hi - lo + 1;
    }
  }
  // Every count back to 0.
  void clear() { std::fill(bits_.begin(), bits_.end(), std::uint64_t{0}); }
  std::size_t bytes() const { return bits_.capacity() * sizeof(std::uint64_t); }
  // Counts below idle_passes, zero for non-members. O(nodes * P).
  void check(const std::vector<std::uint64_t>& members, std::size_t words_per_row, std::uint16_t idle_passes,
             std::vector<std::string>& problems) const {
    for (std::size_t word = 0; word < members.size(); ++word)
      for (unsigned b = 0; b < 64; ++b) {
        unsigned count = 0;
        for (unsigned p = 0; p < planes_; ++p)
          count |= static_cast<unsigned>((bits_[word * planes_ + p] >> b) & 1u) << p;
        const bool member = (members[word] >> b) & 1u;
        if (count >= idle_passes || (!member && count != 0))
          problems.push_back("active set: node " + std::to_string(b + 64 * (word % words_per_row)) + " of row " +
                             std::to_string(word / words_per_row) + " idle count " + std::to_string(count) +
                             (member ? " >= idle_passes" : " but not a member"));
      }
  }

 private:
  std::size_t words_per_row_;
  unsigned planes_;
  std::vector<std::uint64_t> bits_;  // word-major: the planes of bitmap word w at [w * planes_, ...)
};

// The sparse grid's active set: the same ordered sweeps, its counts in bit planes.
using SparseActiveSet = BasicActiveSet<BitPlaneIdleCounts>;
extern template class BasicActiveSet<BitPlaneIdleCounts>;

}  // namespace sb::grid
