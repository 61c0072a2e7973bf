#pragma once
// Scenes and helpers shared by the grid back-end's unit tests.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "common/height_field.hpp"
#include "common/scene.hpp"
#include "common/schedule.hpp"
#include "grid/grid_terrain.hpp"
#include "terrain_test_support.hpp"

namespace sb::grid::test {

// A 0.5 m square of flat sand 0.1 m deep on a 5 mm grid (101 x 101 nodes) and a stroke
// along x through the middle; the tool section comes separately (keys differ per shape).
inline std::string flat_scene(const std::string& tool) {
  return sb::test::flat_sand_scene("0.5", "0.1", tool, R"(
[stroke]
path_m = [[0.1, 0.25], [0.4, 0.25]]
spacing_m = 0.005
[grid]
cell_m = 0.005
)");
}
// A 3 cm disk cutting 1 cm deep.
inline const char* kDisk = "shape = \"disk\"\nradius_m = 0.03\ndepth_m = 0.01\n";

inline Scene scene(const std::vector<std::string>& overrides = {}, const std::string& text = flat_scene(kDisk)) {
  return parse_scene(text, "test", overrides);
}

template <class Real>
std::unique_ptr<GridTerrain<Real>> make_grid(const Scene& s, const std::function<double(const Vec2&)>& initial) {
  return std::make_unique<GridTerrain<Real>>(GridLayout::covering(s.domain.box(), s.grid.cell_m), initial,
                                             s.grid.neighbours, s.erosion.idle_passes);
}

template <class Real>
std::unique_ptr<GridTerrain<Real>> make_grid(const Scene& s) {
  const HeightField field = HeightField::from_scene(s);
  return make_grid<Real>(s, [&field](const Vec2& p) { return field(p); });
}

using sb::test::rule_of;
using sb::test::schedule_of;
using sb::test::stamp_at;

// The flat scene's sand height as the storage type holds it.
template <class Real>
inline constexpr double kSand = static_cast<Real>(0.1);

// Relative tolerance of volume checks per storage type.
template <class Real>
constexpr double kVolumeTolerance = sizeof(Real) == 8 ? 1e-12 : 1e-9;

template <class Real>
bool same_bits(Real a, Real b) {
  return std::memcmp(&a, &b, sizeof(Real)) == 0;
}

using StorageTypes = ::testing::Types<float, double>;
struct StorageName {
  template <class T>
  static std::string GetName(int) {
    return sizeof(T) == 8 ? "double" : "float";
  }
};

}  // namespace sb::grid::test
