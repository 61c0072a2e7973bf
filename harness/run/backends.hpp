#pragma once
// The back-end registry: names and factories of every Terrain implementation.
#include <memory>
#include <string>
#include <vector>

#include "common/height_field.hpp"
#include "common/scene.hpp"
#include "common/terrain.hpp"

namespace sb {

std::vector<std::string> backend_names();  // {"tin", "grid", "sparse"}
// Throws InputError for an unknown name.
std::unique_ptr<Terrain> make_terrain(const std::string& backend, const Scene& scene, const HeightField& initial);

}  // namespace sb
