#pragma once
// Helpers the tests of every back-end share (TIN, dense and sparse grid, the typed tests
// over all three, the TIN stress test): the flat-sand scene most of them start from, the
// erosion rule, schedule and single stamps of a scene, pours, relaxing a terrain to rest, and
// check() as an expectation.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>

#include "common/erosion.hpp"
#include "common/height_field.hpp"
#include "common/scene.hpp"
#include "common/schedule.hpp"
#include "common/terrain.hpp"
#include "common/tool.hpp"

namespace sb::test {

// The text of a scene on a square domain `size_m` on a side, of flat sand `height_m` deep at
// a 30-degree critical angle, worked by the tool whose [tool] keys are `tool`; `rest` holds
// the scene's other sections (stroke, erosion, grid, ...). Numbers are given as the scene
// file spells them, e.g. flat_sand_scene("0.3", "0.1", kDisk2cm, "[stroke]\n...").
inline std::string flat_sand_scene(std::string_view size_m, std::string_view height_m, std::string_view tool,
                                   std::string_view rest) {
  std::string text = "\n[domain]\nsize_m = [";
  text.append(size_m).append(", ").append(size_m).append("]\n");
  text.append("[terrain]\nkind = \"flat\"\nheight_m = ").append(height_m).append("\n");
  text.append("[material]\ncritical_angle_deg = 30.0\n");
  text.append("[tool]\n").append(tool).append("\n");
  return text.append(rest);
}

// A 2 cm disk cutting 1 cm deep ([tool] keys), putting the sand on its rim: the model most
// tests of the back-ends' mechanics were written to (bulldozing: terrain_bulldoze_test.cpp).
inline constexpr std::string_view kDisk2cm =
    "shape = \"disk\"\nradius_m = 0.02\ndepth_m = 0.01\ndisplacement = \"rim\"\n";

inline ErosionRule rule_of(const Scene& s) {
  return ErosionRule::from(s.material, s.erosion.settle_tolerance_deg, s.erosion.rule);
}

inline StampSchedule schedule_of(const Scene& s) {
  const HeightField field = HeightField::from_scene(s);
  return make_schedule(s.tool, s.stroke, [field](const Vec2& p) { return field(p); });
}

// A stamp of the scene's tool at one pose, heading along `motion`.
inline ToolStamp stamp_at(const Scene& s, Vec2 xy, double bottom_z, Vec2 motion = {1.0, 0.0},
                          std::uint32_t generation = 0) {
  ToolPose pose;
  pose.xy = xy;
  pose.bottom_z = bottom_z;
  pose.heading_rad = std::atan2(motion.y(), motion.x());
  return make_stamp(s.tool, pose, motion, generation);
}

// A pour of `volume_m3` spread over a disk of `radius_m` at `xy` (no motion, generation 0).
inline ToolStamp pour_at(Vec2 xy, double radius_m, double volume_m3) {
  ToolSpec spec;
  spec.shape = ToolShape::Pour;
  spec.radius_m = radius_m;
  spec.pour_volume_m3 = volume_m3;
  ToolPose pose;
  pose.xy = xy;
  return make_stamp(spec, pose, Vec2::Zero(), 0);
}

// Erodes (and simplifies) until the active set is empty or `max_passes` have run; returns
// whether it settled.
inline bool relax(Terrain& t, const Scene& s, int max_passes = 200000) {
  const ErosionRule rule = rule_of(s);
  for (int done = 0; done < max_passes; done += 64) {
    t.erode(rule, ErosionBudget{.max_passes = 64, .settling = true});
    t.simplify(SimplifyParams{s.tin.alpha_flat_deg});
    if (t.stats().active == 0) return true;
  }
  return false;
}

}  // namespace sb::test

// check() finds no problem (else the test fails, listing them).
#define SB_EXPECT_CHECK_OK(terrain)                                                \
  do {                                                                             \
    const ::sb::IntegrityReport integrity_ = (terrain).check();                    \
    EXPECT_TRUE(integrity_.ok()) << ::testing::PrintToString(integrity_.problems); \
  } while (0)

#define SB_ASSERT_CHECK_OK(terrain)                                                \
  do {                                                                             \
    const ::sb::IntegrityReport integrity_ = (terrain).check();                    \
    ASSERT_TRUE(integrity_.ok()) << ::testing::PrintToString(integrity_.problems); \
  } while (0)
