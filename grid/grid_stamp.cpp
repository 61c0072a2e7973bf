#include "grid/grid_stamp.hpp"

#include "grid/stamp_kernel.hpp"

namespace sb::grid {

template StampReport stamp_grid<HeightGrid<float>>(HeightGrid<float>&, const ToolStamp&, std::vector<std::uint32_t>&,
                                                   CarriedNodes*);
template StampReport stamp_grid<HeightGrid<double>>(HeightGrid<double>&, const ToolStamp&, std::vector<std::uint32_t>&,
                                                    CarriedNodes*);

}  // namespace sb::grid
