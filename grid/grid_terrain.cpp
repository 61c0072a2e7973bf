#include "grid/grid_terrain.hpp"

#include <stdexcept>

namespace sb::grid {

std::unique_ptr<Terrain> make_grid_terrain(const Scene&, const HeightField&) {
  throw std::logic_error("the grid back-end is not built yet");
}

}  // namespace sb::grid
