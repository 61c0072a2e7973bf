#include "common/point_sets.hpp"

#include <algorithm>
#include <cmath>
#include <random>

namespace sb {

std::vector<Vec2> jittered_lattice(const DomainSpec& domain, std::size_t n, double jitter, std::uint64_t seed) {
  const double aspect = domain.size_m.x() / domain.size_m.y();
  const auto nx = std::max<std::size_t>(2, static_cast<std::size_t>(std::llround(std::sqrt(n * aspect))));
  const auto ny = std::max<std::size_t>(2, static_cast<std::size_t>(std::llround(static_cast<double>(n) / nx)));
  const Vec2 cell(domain.size_m.x() / static_cast<double>(nx - 1), domain.size_m.y() / static_cast<double>(ny - 1));
  std::mt19937_64 rng(seed);
  auto unit = [&] { return static_cast<double>(rng() >> 11) * 0x1.0p-53 - 0.5; };  // portable [-0.5, 0.5)
  std::vector<Vec2> points;
  points.reserve(nx * ny);
  for (std::size_t j = 0; j < ny; ++j)
    for (std::size_t i = 0; i < nx; ++i) {
      const double jx = unit() * jitter, jy = unit() * jitter;  // always drawn: same sequence for any jitter
      const bool edge_x = i == 0 || i == nx - 1, edge_y = j == 0 || j == ny - 1;
      Vec2 p = domain.origin_m + Vec2(static_cast<double>(i) * cell.x(), static_cast<double>(j) * cell.y());
      if (!edge_x) p.x() += jx * cell.x();
      if (!edge_y) p.y() += jy * cell.y();
      points.push_back(p.cwiseMax(domain.origin_m).cwiseMin(domain.origin_m + domain.size_m));  // rounding
    }
  return points;
}

}  // namespace sb
