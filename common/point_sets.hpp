#pragma once
// Point sets for building models of a given size: a jittered lattice over the domain, as the
// paper's experiments used TINs of N vertices. O(n).
#include <cstdint>
#include <vector>

#include "common/scene.hpp"

namespace sb {

// About n points on a lattice whose cells are as square as the domain allows, each moved by
// up to jitter/2 of a cell in x and y (jitter 0: an exact, co-circular lattice). The
// boundary rows stay on the boundary. Deterministic for a seed.
std::vector<Vec2> jittered_lattice(const DomainSpec& domain, std::size_t n, double jitter, std::uint64_t seed);

}  // namespace sb
