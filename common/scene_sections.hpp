#pragma once
// The scene's sections ([domain], [terrain], [material], [erosion], [tool], [stroke], [tin],
// [grid], [reference], [output], [haptics]), one reader each: every key read through `Fields`
// (typed, ranged, noted for the key catalogue) into the Scene. O(keys + stroke waypoints).
#include <filesystem>

#include "common/scene.hpp"
#include "common/scene_fields.hpp"

namespace sb::scene_detail {

// Reads every section of the scene in dependency order; InputError names the first bad key.
void read_scene_sections(Fields& f, Scene& s, const std::filesystem::path& base_dir);

}  // namespace sb::scene_detail
