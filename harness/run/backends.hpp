#pragma once
// The back-end registry: one row per Terrain implementation, its name and its factory. A new
// back-end is one row in backends.cpp; the names in help texts and error messages come from
// the table.
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "common/height_field.hpp"
#include "common/scene.hpp"
#include "common/terrain.hpp"

namespace sb {

using TerrainFactory = std::unique_ptr<Terrain> (*)(const Scene& scene, const HeightField& initial);

struct Backend {
  std::string_view name;  // as given to --backend, and Terrain::name()
  TerrainFactory make;
};

std::span<const Backend> backends();
std::vector<std::string> backend_names();  // {"tin", "grid"}
// The names joined: "tin | grid" (the default), or with another separator.
std::string backend_list(std::string_view separator = " | ");
// Throws InputError for an unknown name.
std::unique_ptr<Terrain> make_terrain(const std::string& backend, const Scene& scene, const HeightField& initial);

}  // namespace sb
