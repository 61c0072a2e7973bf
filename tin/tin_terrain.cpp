#include "tin/tin_terrain.hpp"

#include <stdexcept>

namespace sb::tin {

std::unique_ptr<Terrain> make_tin_terrain(const Scene&, const HeightField&) {
  throw std::logic_error("the TIN back-end is not built yet");
}

}  // namespace sb::tin
