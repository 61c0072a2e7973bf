#include "grid/active_set.hpp"

#include <immintrin.h>

#include <stdexcept>

#include "grid/sparse_idle_counts.hpp"

namespace sb::grid {

namespace {

// count_up_word's AVX-512 body: the word's 64 counts in two registers of 32, masked by `kept`
// (nodes past the row's end are never in `kept`: their lanes read and write nothing).
[[gnu::target("avx512f,avx512bw")]] std::uint64_t count_up_word_avx512(std::uint16_t* counts, std::uint64_t kept,
                                                                       std::uint16_t idle_passes) {
  const __m512i one = _mm512_set1_epi16(1), limit = _mm512_set1_epi16(static_cast<short>(idle_passes));
  std::uint64_t leaving = 0;
  for (int half = 0; half < 2; ++half) {
    const auto m = static_cast<__mmask32>(kept >> (32 * half));
    if (m == 0) continue;
    std::uint16_t* p = counts + 32 * half;
    const __m512i c = _mm512_add_epi16(_mm512_maskz_loadu_epi16(m, p), one);
    const __mmask32 done = _mm512_mask_cmpge_epu16_mask(m, c, limit);
    _mm512_mask_storeu_epi16(p, m, _mm512_maskz_mov_epi16(static_cast<__mmask32>(m & ~done), c));
    leaving |= static_cast<std::uint64_t>(done) << (32 * half);
  }
  return leaving;
}

bool has_avx512bw() {
  static const bool yes = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw");
  return yes;
}

}  // namespace

std::uint64_t DenseIdleCounts::count_up_word(std::size_t y, std::size_t w, std::uint64_t kept,
                                             std::uint16_t idle_passes) {
  std::uint16_t* counts = counts_.data() + y * nx_ + w * 64;
  if (has_avx512bw()) return count_up_word_avx512(counts, kept, idle_passes);
  std::uint64_t leaving = 0;
  for (std::uint64_t b = kept; b != 0; b &= b - 1) {
    const auto bit = static_cast<unsigned>(std::countr_zero(b));
    if (++counts[bit] >= idle_passes) counts[bit] = 0, leaving |= std::uint64_t{1} << bit;
  }
  return leaving;
}

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
      idle_(nx, ny, words_per_row_, idle_passes_),
      changes_(words_per_row_, ny) {
  if (idle_passes < 1 || idle_passes > 32767)
    throw std::invalid_argument("ActiveSet: idle_passes must be in [1, 32767]");
}

template <class Idle>
std::size_t BasicActiveSet<Idle>::bytes() const {
  return bits_.capacity() * sizeof(std::uint64_t) + row_count_.capacity() * sizeof(std::uint32_t) + idle_.bytes() +
         changes_.bytes();
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
