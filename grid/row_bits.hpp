#pragma once
// Bit sets over one row of the grid, one bit per node (x at word x / 64, bit x % 64): the
// dense pass's flags (nodes to visit) and its record of the nodes that transferred
// (grid/erosion_kernel.hpp). Every function is O(1) or O(words of the range).
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>

namespace sb::grid {

// Bits of a row's flags, one per node (x at word x / 64, bit x % 64).
inline bool bit_at(const std::uint64_t* bits, std::size_t x) { return (bits[x / 64] >> (x % 64)) & 1u; }
// Ors the low bits of `m` (at most 8 set) in at bit x (may straddle two words: `bits` must
// hold the word after x's).
[[gnu::always_inline]] inline void or_bits(std::uint64_t* bits, std::size_t x, std::uint64_t m) {
  bits[x / 64] |= m << (x % 64);
  if (x % 64 > 56) bits[x / 64 + 1] |= m >> (64 - x % 64);
}
// Ors the low 32 bits of `m` in at bit x; writes the word after x's only where bits go there.
[[gnu::always_inline]] inline void or_bits32(std::uint64_t* bits, std::size_t x, std::uint64_t m) {
  bits[x / 64] |= m << (x % 64);
  if (x % 64 > 32)
    if (const std::uint64_t high = m >> (64 - x % 64)) bits[x / 64 + 1] |= high;
}
// Bit 3 l for each bit l of an 8-bit mask: lanes of a group of nodes three columns apart.
inline constexpr std::array<std::uint32_t, 256> kEveryThird = [] {
  std::array<std::uint32_t, 256> t{};
  for (unsigned m = 0; m < 256; ++m)
    for (unsigned l = 0; l < 8; ++l)
      if ((m >> l) & 1) t[m] |= std::uint32_t{1} << (3 * l);
  return t;
}();
// Sets bits [a, b].
inline void set_bits(std::uint64_t* bits, std::size_t a, std::size_t b) {
  for (std::size_t w = a / 64; w <= b / 64; ++w) {
    const unsigned lo = w == a / 64 ? a % 64 : 0, hi = w == b / 64 ? b % 64 : 63;
    bits[w] |= (hi == 63 ? ~std::uint64_t{0} : (std::uint64_t{1} << (hi + 1)) - 1) & (~std::uint64_t{0} << lo);
  }
}
// Sets bits ix - 2 .. ix + 2 (those below 0 dropped; `bits` must hold bit ix + 2).
[[gnu::always_inline]] inline void near_bits(std::uint64_t* bits, std::size_t ix) {
  const std::size_t lo = ix >= 2 ? ix - 2 : 0;
  const std::uint64_t m = ix >= 2 ? 0x1Fu : 0x1Fu >> (2 - ix);
  bits[lo / 64] |= m << (lo % 64);
  if (lo % 64 > 59) bits[lo / 64 + 1] |= m >> (64 - lo % 64);
}
// The bits of word w for nodes x in [x0, x1].
[[gnu::always_inline]] inline std::uint64_t word_range(std::size_t w, std::size_t x0, std::size_t x1) {
  const unsigned lo = w == x0 / 64 ? x0 % 64 : 0, hi = w == x1 / 64 ? x1 % 64 : 63;
  return (hi == 63 ? ~std::uint64_t{0} : (std::uint64_t{1} << (hi + 1)) - 1) & (~std::uint64_t{0} << lo);
}
// The bits of word w for nodes x with x % 3 == r (64 = 1 mod 3: the pattern shifts by one per word).
[[gnu::always_inline]] inline std::uint64_t columns_mod3(std::size_t r, std::size_t w) {
  constexpr std::uint64_t kEvery3 = 0x9249249249249249ull;  // bits 0, 3, ..., 63
  return kEvery3 << ((r + 3 - w % 3) % 3);
}
// The first node x in [from, to] with x % 3 == r and its bit set (false: none). O(words).
[[gnu::always_inline]] inline bool next_in_class(const std::uint64_t* bits, std::size_t r, std::size_t from,
                                                 std::size_t to, std::size_t& x) {
  if (from > to) return false;
  for (std::size_t w = from / 64; w <= to / 64; ++w)
    if (const std::uint64_t m = bits[w] & columns_mod3(r, w) & word_range(w, from, to)) {
      x = w * 64 + static_cast<std::size_t>(std::countr_zero(m));
      return true;
    }
  return false;
}
// The last such node in [from, to].
[[gnu::always_inline]] inline bool prev_in_class(const std::uint64_t* bits, std::size_t r, std::size_t from,
                                                 std::size_t to, std::size_t& x) {
  if (from > to) return false;
  for (std::size_t w = to / 64 + 1; w-- > from / 64;)
    if (const std::uint64_t m = bits[w] & columns_mod3(r, w) & word_range(w, from, to)) {
      x = w * 64 + 63 - static_cast<std::size_t>(std::countl_zero(m));
      return true;
    }
  return false;
}

}  // namespace sb::grid
