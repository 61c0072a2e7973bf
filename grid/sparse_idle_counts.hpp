#pragma once
// PagedIdleCounts: the active set's idle counts (active_set.hpp's Idle policy) for the
// sparse grid, held only for the 64-node words of the membership bitmap that have a member.
//
// A word's first member takes a page of 64 zeroed counts from a pool (a free list, so that
// a word that empties and fills again does not go back to the allocator); its last member
// leaving returns the page (all counts of non-members are zero, so it is clean). Memory:
// 4 bytes per bitmap word (64 nodes) for the page index, plus 128 bytes per page at the
// high-water mark of words with members, plus 4 bytes per free-list entry. All O(1).
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "grid/active_set.hpp"

namespace sb::grid {

class PagedIdleCounts {
 public:
  PagedIdleCounts(std::size_t /*nx*/, std::size_t ny, std::size_t words_per_row)
      : words_per_row_(words_per_row), page_of_word_(words_per_row * ny, kNone) {}

  std::uint16_t& at(std::size_t ix, std::size_t iy) {
    return pages_[page_of_word_[iy * words_per_row_ + ix / 64]][ix % 64];
  }
  // A word without a page has only zero counts.
  void reset(std::size_t ix, std::size_t iy) {
    const std::uint32_t page = page_of_word_[iy * words_per_row_ + ix / 64];
    if (page != kNone) pages_[page][ix % 64] = 0;
  }
  void word_filled(std::size_t word) {
    if (free_.empty()) {
      page_of_word_[word] = static_cast<std::uint32_t>(pages_.size());
      pages_.emplace_back();  // value-initialised: zeros
    } else {
      page_of_word_[word] = free_.back();
      free_.pop_back();
    }
  }
  void word_emptied(std::size_t word) {
    free_.push_back(page_of_word_[word]);
    page_of_word_[word] = kNone;
  }
  std::size_t bytes() const {
    return page_of_word_.capacity() * sizeof(std::uint32_t) + pages_.capacity() * sizeof(Page) +
           free_.capacity() * sizeof(std::uint32_t);
  }
  // Words with members have a page and the other words none; counts below idle_passes,
  // zero for non-members and in free pages.
  void check(const std::vector<std::uint64_t>& bits, std::size_t words_per_row, std::uint16_t idle_passes,
             std::vector<std::string>& problems) const {
    std::vector<std::uint8_t> used(pages_.size(), 0);
    for (std::size_t w = 0; w < bits.size(); ++w) {
      const std::uint32_t page = page_of_word_[w];
      if ((bits[w] != 0) != (page != kNone) || (page != kNone && page >= pages_.size())) {
        problems.push_back("active set: bitmap word " + std::to_string(w) +
                           (bits[w] ? " has members but no page" : " has a page but no members"));
        continue;
      }
      if (page == kNone) continue;
      if (used[page]++) problems.push_back("active set: page " + std::to_string(page) + " used twice");
      for (std::size_t b = 0; b < 64; ++b) {
        const std::uint16_t c = pages_[page][b];
        if (c >= idle_passes || (!((bits[w] >> b) & 1u) && c != 0))
          problems.push_back("active set: node " + std::to_string(b) + " of word " + std::to_string(w) + " (row " +
                             std::to_string(w / words_per_row) + ") has idle count " + std::to_string(c));
      }
    }
    for (std::uint32_t page : free_) {
      if (page >= pages_.size() || used[page]++) {
        problems.push_back("active set: free page " + std::to_string(page) + " out of range or in use");
        continue;
      }
      for (std::uint16_t c : pages_[page])
        if (c != 0) problems.push_back("active set: free page " + std::to_string(page) + " not clean");
    }
  }

 private:
  using Page = std::array<std::uint16_t, 64>;
  static constexpr std::uint32_t kNone = 0xffffffffu;
  std::size_t words_per_row_;
  std::vector<std::uint32_t> page_of_word_;  // kNone: no member in the word
  std::vector<Page> pages_;
  std::vector<std::uint32_t> free_;
};

// The sparse grid's active set: the same ordered sweeps, its counts paged.
using SparseActiveSet = BasicActiveSet<PagedIdleCounts>;
extern template class BasicActiveSet<PagedIdleCounts>;

}  // namespace sb::grid
