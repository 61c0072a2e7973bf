#pragma once
// Rough states and the rule/stencil/storage cases shared by the grid erosion kernel's tests
// (grid_dense_pass_test.cpp, grid_multires_test.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>

#include "common/erosion.hpp"
#include "common/geometry.hpp"
#include "common/material.hpp"

namespace sb::grid::test {

// 0.1 m of sand with a random height per node of up to +-1.5 cells: a hash of the position
// (to 0.1 mm) and the seed, so every grid storage sees the same state.
inline double rough_height(const Vec2& p, std::uint64_t seed, double cell) {
  std::uint64_t h = seed * 0x9E3779B97F4A7C15ull ^
                    static_cast<std::uint64_t>(std::llround(p.x() * 1e4)) * 0xBF58476D1CE4E5B9ull ^
                    static_cast<std::uint64_t>(std::llround(p.y() * 1e4)) * 0x94D049BB133111EBull;
  h ^= h >> 31;
  h *= 0xD6E8FEB86639EB69ull;
  h ^= h >> 29;
  const double u = static_cast<double>(h >> 11) / 9007199254740992.0;  // [0, 1)
  return 0.1 + (u - 0.5) * 3.0 * cell;
}

// One erosion configuration: rule, stencil, storage.
struct ErosionCase {
  ErosionRuleKind rule;
  int neighbours;
  bool is_float;
};

inline std::string name(const ErosionCase& c) {
  return std::string(to_string(c.rule)) + "_" + std::to_string(c.neighbours) + (c.is_float ? "_float" : "_double");
}

// Both rules, 4 and 8 neighbours, double; float for three of them.
inline auto erosion_cases() {
  return ::testing::Values(ErosionCase{ErosionRuleKind::Edge, 8, false}, ErosionCase{ErosionRuleKind::Edge, 4, false},
                           ErosionCase{ErosionRuleKind::Gradient, 8, false},
                           ErosionCase{ErosionRuleKind::Gradient, 4, false},
                           ErosionCase{ErosionRuleKind::Edge, 8, true}, ErosionCase{ErosionRuleKind::Gradient, 8, true},
                           ErosionCase{ErosionRuleKind::Gradient, 4, true});
}

// The default material (30 degrees, fraction 0.5) with a 0.1 degree settle tolerance.
inline ErosionRule rule_for(ErosionRuleKind kind) {
  Material m;
  return ErosionRule::from(m, 0.1, kind);
}

}  // namespace sb::grid::test
