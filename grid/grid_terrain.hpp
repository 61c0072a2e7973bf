#pragma once
// GridTerrain: dense regular height grid (being written; see issue 2).
#include <memory>

#include "common/height_field.hpp"
#include "common/scene.hpp"
#include "common/terrain.hpp"

namespace sb::grid {

std::unique_ptr<Terrain> make_grid_terrain(const Scene& scene, const HeightField& initial);

}  // namespace sb::grid
