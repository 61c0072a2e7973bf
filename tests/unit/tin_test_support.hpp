#pragma once
// Scenes and helpers shared by the TIN back-end's tests (unit and stress).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "common/erosion.hpp"
#include "common/height_field.hpp"
#include "common/scene.hpp"
#include "common/schedule.hpp"
#include "terrain_test_support.hpp"
#include "tin/tin_terrain.hpp"

namespace sb::tin::test {

// 0.5 m of flat sand 0.1 m deep; a 2 cm disk cutting 1 cm deep along x.
inline const std::string kFlatScene = sb::test::flat_sand_scene("0.5", "0.1", sb::test::kDisk2cm, R"(
[stroke]
path_m = [[0.15, 0.25], [0.35, 0.25]]
spacing_m = 0.005
)");

inline const std::string kDunesScene = R"(
[domain]
size_m = [0.5, 0.5]
[terrain]
kind = "dunes"
height_m = 0.08
amplitude_m = 0.03
wavelength_m = 0.2
components = 4
seed = 7
[material]
critical_angle_deg = 32.0
[tool]
shape = "disk"
radius_m = 0.015
depth_m = 0.008
[stroke]
path_m = [[0.25, 0.10], [0.2449, 0.1388], [0.2299, 0.1750], [0.2061, 0.2061]]
spacing_m = 0.005
[tin]
tolerance_m = 0.0005
)";

// 20 pours of 1 cm^3 at the middle of 0.3 m of flat sand 5 cm deep, 8 erosion passes a step.
inline const std::string kPileScene =
    sb::test::flat_sand_scene("0.3", "0.05", "shape = \"pour\"\nradius_m = 0.004\nvolume_m3 = 1e-6\n", R"(
[erosion]
max_passes_per_step = 8
[stroke]
path_m = [[0.15, 0.15]]
repeat = 20
)");

inline Scene scene(const std::string& text = kFlatScene, const std::vector<std::string>& overrides = {}) {
  return parse_scene(text, "test", overrides);
}

inline std::unique_ptr<Terrain> make(const Scene& s) { return make_tin_terrain(s, HeightField::from_scene(s)); }

using sb::test::relax;
using sb::test::rule_of;
using sb::test::schedule_of;
using sb::test::stamp_at;

// One simulation step as the runner does it.
inline void step(Terrain& t, const Scene& s, const ToolStamp& st) {
  t.stamp(st);
  t.erode(rule_of(s), ErosionBudget{s.erosion.max_passes_per_step});
  t.simplify(SimplifyParams{s.tin.alpha_flat_deg});
}

// The TIN tests' names for SB_EXPECT_CHECK_OK and SB_ASSERT_CHECK_OK (terrain_test_support.hpp).
#define SB_EXPECT_TIN_OK(terrain) SB_EXPECT_CHECK_OK(terrain)
#define SB_ASSERT_TIN_OK(terrain) SB_ASSERT_CHECK_OK(terrain)

}  // namespace sb::tin::test
