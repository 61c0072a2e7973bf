#pragma once
// Tool stamps on a height grid (common/tool.hpp's rule): cut the nodes inside the footprint
// down to the tool bottom and put exactly that volume on the rim band; or pour.
//
// Cost: O(nodes in s.influence_bounds()) plus O(footprint vertices) for each node near the
// footprint's boundary or in the rim band; two circles about the footprint decide the
// other nodes in O(1). Only when the rim band holds no node (narrower than a cell, clipped
// by the domain) is the window widened, doubling the extra width each time:
// O(log(domain / cell)) rescans at worst. A carrying stamp also visits the pile the stamp
// before it heaped: O(its nodes). A pour lands as a cone of its radius, handed to the
// nodes by bilinear weights (centred on the pour point between nodes): O((radius / cell)^2 * 16)
// samples, at most 256^2.
#include <cstdint>
#include <utility>
#include <vector>

#include "common/front_pile.hpp"
#include "common/terrain.hpp"
#include "grid/height_grid.hpp"

namespace sb::grid {

// The pile a carrying stamp heaped (tool.displacement = "carry", common/front_pile.hpp), which
// the next stamp picks up: its nodes and their heights before the deposit.
struct CarriedNodes {
  CarriedPileOrigin origin;
  std::vector<std::pair<std::uint32_t, double>> base;
};

// Applies one stamp to a Store (stamp_kernel.hpp's concept; instantiated for HeightGrid<float>
// and HeightGrid<double>). Appends every node whose height changed to `changed`. `carried`:
// the pile the stamp before left, replaced by this stamp's (none: a pile is not carried on).
// Volume: removed == deposited (to rounding); a pour adds s.pour_volume_m3.
template <class Store>
StampReport stamp_grid(Store& grid, const ToolStamp& s, std::vector<std::uint32_t>& changed,
                       CarriedNodes* carried = nullptr);

}  // namespace sb::grid
