#pragma once
// Tool stamps on a height grid (common/tool.hpp's rule): cut the nodes inside the footprint
// down to the tool bottom and put exactly that volume on the rim band; or pour.
//
// Cost: O(nodes in s.influence_bounds()) plus O(footprint vertices) for each node near the
// footprint's boundary or in the rim band; two circles about the footprint decide the
// other nodes in O(1). Only when the rim band holds no node (narrower than a cell, clipped
// by the domain) is the window widened, doubling the extra width each time:
// O(log(domain / cell)) rescans at worst. A pour lands as a cone of its radius, handed to the
// nodes by bilinear weights (centred on the pour point between nodes): O((radius / cell)^2 * 16)
// samples, at most 256^2.
#include <cstdint>
#include <vector>

#include "common/terrain.hpp"
#include "grid/height_grid.hpp"

namespace sb::grid {

// Applies one stamp to a Store (stamp_kernel.hpp's concept; instantiated for HeightGrid<float>
// and HeightGrid<double>). Appends every node whose height changed to `changed`.
// Volume: removed == deposited (to rounding); a pour adds s.pour_volume_m3.
template <class Store>
StampReport stamp_grid(Store& grid, const ToolStamp& s, std::vector<std::uint32_t>& changed);

}  // namespace sb::grid
