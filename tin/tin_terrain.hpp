#pragma once
// TinTerrain: Purchart's TIN on CGAL's constrained Delaunay triangulation.
// (Being written; see issue 3.)
#include <memory>

#include "common/height_field.hpp"
#include "common/scene.hpp"
#include "common/terrain.hpp"

namespace sb::tin {

std::unique_ptr<Terrain> make_tin_terrain(const Scene& scene, const HeightField& initial);

}  // namespace sb::tin
