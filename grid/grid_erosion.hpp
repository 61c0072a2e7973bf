#pragma once
// Erosion on a height grid: sb::erosion_transfers (common/erosion.hpp) applied to the
// active set only, in place (each visit sees the heights left by the visits before it).
//
// Cost: O(visits * stencil size); a pass visits every active node once, and the set
// grows by at most one ring of neighbours per pass. Nothing outside the active set and
// its stencil neighbours is read or written.
#include "common/terrain.hpp"
#include "grid/active_set.hpp"
#include "grid/height_grid.hpp"
#include "grid/stencil.hpp"

namespace sb::grid {

// Runs passes over `active` until it is empty or the budget is spent.
template <class Real>
ErosionReport erode_grid(HeightGrid<Real>& grid, ActiveSet& active, const Stencil& stencil, const ErosionRule& rule,
                         const ErosionBudget& budget);

}  // namespace sb::grid
