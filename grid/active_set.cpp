#include "grid/active_set.hpp"

#include <stdexcept>

#include "grid/sparse_idle_counts.hpp"

namespace sb::grid {

void DenseIdleCounts::check(const std::vector<std::uint64_t>& bits, std::size_t words_per_row,
                            std::uint16_t idle_passes, std::vector<std::string>& problems) const {
  for (std::size_t k = 0; k < counts_.size(); ++k) {
    const std::size_t ix = k % nx_, iy = k / nx_;
    const bool member = (bits[iy * words_per_row + ix / 64] >> (ix % 64)) & 1u;
    if (counts_[k] >= idle_passes || (!member && counts_[k] != 0))
      problems.push_back("active set: node " + std::to_string(k) + " idle count " + std::to_string(counts_[k]) +
                         (member ? " >= idle_passes" : " but not a member"));
  }
}

template <class Idle>
BasicActiveSet<Idle>::BasicActiveSet(std::size_t nx, std::size_t ny, int idle_passes)
    : nx_(nx),
      ny_(ny),
      words_per_row_((nx + 63) / 64),
      idle_passes_(static_cast<std::uint16_t>(idle_passes)),
      bits_(words_per_row_ * ny, 0),
      row_count_(ny, 0),
      idle_(nx, ny, words_per_row_, idle_passes_) {
  if (idle_passes < 1 || idle_passes > 32767)
    throw std::invalid_argument("ActiveSet: idle_passes must be in [1, 32767]");
}

template <class Idle>
std::size_t BasicActiveSet<Idle>::bytes() const {
  return bits_.capacity() * sizeof(std::uint64_t) + row_count_.capacity() * sizeof(std::uint32_t) + idle_.bytes();
}

template <class Idle>
void BasicActiveSet<Idle>::check(std::vector<std::string>& problems) const {
  std::size_t total = 0;
  for (std::size_t iy = 0; iy < ny_; ++iy) {
    std::size_t in_row = 0;
    for (std::size_t wi = 0; wi < words_per_row_; ++wi) {
      const std::uint64_t w = bits_[iy * words_per_row_ + wi];
      in_row += static_cast<std::size_t>(std::popcount(w));
      const std::size_t valid = std::min<std::size_t>(64, nx_ - wi * 64);
      if (valid < 64 && (w >> valid) != 0)
        problems.push_back("active set: padding bits set in row " + std::to_string(iy));
    }
    if (in_row != row_count_[iy])
      problems.push_back("active set: row " + std::to_string(iy) + " has " + std::to_string(in_row) +
                         " members but counts " + std::to_string(row_count_[iy]));
    total += in_row;
  }
  if (total != size_)
    problems.push_back("active set: " + std::to_string(total) + " members, size says " + std::to_string(size_));
  idle_.check(bits_, words_per_row_, idle_passes_, problems);
}

template class BasicActiveSet<DenseIdleCounts>;
template class BasicActiveSet<BitPlaneIdleCounts>;

}  // namespace sb::grid
