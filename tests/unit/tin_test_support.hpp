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
#include "tin/tin_terrain.hpp"

namespace sb::tin::test {

// 0.5 m of flat sand 0.1 m deep; a 2 cm disk cutting 1 cm deep along x.
inline const char* kFlatScene = R"(
[domain]
size_m = [0.5, 0.5]
[terrain]
kind = "flat"
height_m = 0.1
[material]
critical_angle_deg = 30.0
[tool]
shape = "disk"
radius_m = 0.02
depth_m = 0.01
[stroke]
path_m = [[0.15, 0.25], [0.35, 0.25]]
spacing_m = 0.005
)";

inline const char* kDunesScene = R"(
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

inline const char* kPileScene = R"(
[domain]
size_m = [0.3, 0.3]
[terrain]
kind = "flat"
height_m = 0.05
[material]
critical_angle_deg = 30.0
[erosion]
max_passes_per_step = 8
[tool]
shape = "pour"
radius_m = 0.004
volume_m3 = 1e-6
[stroke]
path_m = [[0.15, 0.15]]
repeat = 20
)";

inline Scene scene(const char* text = kFlatScene, const std::vector<std::string>& overrides = {}) {
  return parse_scene(text, "test", overrides);
}

inline std::unique_ptr<Terrain> make(const Scene& s) { return make_tin_terrain(s, HeightField::from_scene(s)); }

inline ErosionRule rule_of(const Scene& s) {
  return ErosionRule::from(s.material, s.erosion.settle_tolerance_deg, s.erosion.rule);
}

inline StampSchedule schedule_of(const Scene& s) {
  const HeightField field = HeightField::from_scene(s);
  return make_schedule(s.tool, s.stroke, [field](const Vec2& p) { return field(p); });
}

inline ToolStamp stamp_at(const Scene& s, Vec2 xy, double bottom_z, Vec2 motion = {1.0, 0.0},
                          std::uint32_t generation = 0) {
  ToolPose pose;
  pose.xy = xy;
  pose.bottom_z = bottom_z;
  pose.heading_rad = std::atan2(motion.y(), motion.x());
  return make_stamp(s.tool, pose, motion, generation);
}

// One simulation step as the runner does it.
inline void step(Terrain& t, const Scene& s, const ToolStamp& st) {
  t.stamp(st);
  t.erode(rule_of(s), ErosionBudget{s.erosion.max_passes_per_step});
  t.simplify(SimplifyParams{s.tin.alpha_flat_deg});
}

// Erodes until the active set is empty (or the pass limit); returns whether it settled.
inline bool relax(Terrain& t, const Scene& s, int max_passes = 200000) {
  const ErosionRule rule = rule_of(s);
  for (int done = 0; done < max_passes; done += 64) {
    t.erode(rule, ErosionBudget{.max_passes = 64, .settling = true});
    t.simplify(SimplifyParams{s.tin.alpha_flat_deg});
    if (t.stats().active == 0) return true;
  }
  return false;
}

#define SB_EXPECT_TIN_OK(terrain)                                                  \
  do {                                                                             \
    const ::sb::IntegrityReport integrity_ = (terrain).check();                    \
    EXPECT_TRUE(integrity_.ok()) << ::testing::PrintToString(integrity_.problems); \
  } while (0)

#define SB_ASSERT_TIN_OK(terrain)                                                  \
  do {                                                                             \
    const ::sb::IntegrityReport integrity_ = (terrain).check();                    \
    ASSERT_TRUE(integrity_.ok()) << ::testing::PrintToString(integrity_.problems); \
  } while (0)

}  // namespace sb::tin::test
