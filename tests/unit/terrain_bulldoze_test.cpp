// Bulldozing (tool.displacement = "bulldoze", common/front_pile.hpp), typed over the back-ends:
// a box blade dragged through flat sand on several headings carries its cut sand ahead as a pile
// at the angle of repose. Checked after every stamp, before erosion: volume to rounding, the
// mesh's integrity, the pile never steeper than the repose slope along the motion (it stood as a
// column many times the cut depth when the sand went to a band of fixed width), nothing raised
// behind the stroke's start; and the pile the same on every heading.
// Carrying (tool.displacement = "carry") on the same strokes: volume and integrity as above, the
// pile heaped around the blade's front carried to the stroke's end (a tool that sheds nothing
// arrives with the sand it cut, less what erosion spilled), the berms it leaves growing with
// what it sheds, and the same on every heading.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "common/height_field.hpp"
#include "common/scene.hpp"
#include "common/schedule.hpp"
#include "harness/run/backends.hpp"
#include "terrain_backends.hpp"
#include "terrain_test_support.hpp"

namespace sb {
namespace {

constexpr double kDepth = 0.015;  // the blade's cut, in 25 mm of sand
constexpr double kBed = 0.025;
constexpr double kLength = 0.12;  // of the stroke

// A 2 cm (along the motion) x 3 cm box dragged kLength from `start` toward `heading_deg`;
// `displacement`: the [tool] keys that choose where the cut sand goes.
std::string blade_scene(const Vec2& start, double heading_deg,
                        const std::string& displacement = "displacement = \"bulldoze\"\n",
                        const std::string& tool = "shape = \"box\"\nsize_m = [0.02, 0.03]\n") {
  const double a = heading_deg * std::numbers::pi / 180.0;
  const Vec2 end = start + kLength * Vec2(std::cos(a), std::sin(a));
  return test::flat_sand_scene("0.3", std::to_string(kBed),
                               tool + "depth_m = " + std::to_string(kDepth) + "\n" + displacement,
                               "[stroke]\npath_m = [[" + std::to_string(start.x()) + ", " + std::to_string(start.y()) +
                                   "], [" + std::to_string(end.x()) + ", " + std::to_string(end.y()) +
                                   "]]\nspacing_m = 0.002\n[grid]\ncell_m = 0.002\n[tin]\nrefine_m = 0.002\n");
}

template <class Backend>
class Bulldoze : public ::testing::Test {
 protected:
  struct Outcome {
    double pile_height_m = 0.0;   // highest point ahead of the blade at the end, above the bed
    double steepest_ahead = 0.0;  // steepest fall along the motion ahead of the blade, any stamp
    double pile_volume_m3 = 0.0;  // above the bed, ahead of the pose at the end
    double berm_m = 0.0;          // highest point beside the trench's middle third, above the bed
    double berm_m3 = 0.0;         // sand above the bed there, both sides
    double cut_m2 = 0.0;          // the trench's section below the bed there, averaged along it
  };

  Outcome drag(const Vec2& start, double heading_deg, const std::string& displacement = "displacement = \"bulldoze\"\n",
               const std::string& tool = "shape = \"box\"\nsize_m = [0.02, 0.03]\n", bool nothing_behind = true) const {
    std::vector<std::string> overrides = Backend::overrides();
    const Scene s = parse_scene(blade_scene(start, heading_deg, displacement, tool), "bulldoze", overrides);
    auto t = make_terrain(Backend::kName, s, HeightField::from_scene(s));
    const double v0 = t->volume();
    const double a = heading_deg * std::numbers::pi / 180.0;
    const Vec2 dir(std::cos(a), std::sin(a)), across(-dir.y(), dir.x());
    Outcome out;
    const StampSchedule schedule = test::schedule_of(s);
    for (const ToolStamp& st : schedule.stamps) {
      t->stamp(st);
      EXPECT_NEAR(t->volume(), v0, Backend::kVolumeTolerance * v0) << "after stamp " << st.generation;
      const IntegrityReport r = t->check();
      EXPECT_TRUE(r.ok()) << ::testing::PrintToString(r.problems);
      // Along lines parallel to the motion inside the corridor the blade sweeps (its half width
      // is 15 mm), from 4 mm ahead of the front face (the first cells next to the blade hold its
      // cut edge) to 8 cm ahead: a fall per 4 mm.
      for (double side = -0.01; side <= 0.01; side += 0.005) {
        for (double ahead = 0.014; ahead < 0.09; ahead += 0.004) {
          const Vec2 p = st.pose.xy + ahead * dir + side * across;
          const double fall = (t->height(p) - t->height(p + 0.004 * dir)) / 0.004;
          out.steepest_ahead = std::max(out.steepest_ahead, fall);
        }
      }
      t->erode(test::rule_of(s), ErosionBudget{s.erosion.max_passes_per_step});
    }
    const ToolStamp& last = schedule.stamps.back();
    for (double side = -0.03; side <= 0.03; side += 0.002)
      for (double ahead = 0.011; ahead < 0.1; ahead += 0.002)
        out.pile_height_m = std::max(out.pile_height_m, t->height(last.pose.xy + ahead * dir + side * across) - kBed);
    constexpr double kStep = 0.001;
    for (double side = -0.08; side <= 0.08; side += kStep)
      for (double ahead = 0.5 * kStep; ahead < 0.12; ahead += kStep)
        out.pile_volume_m3 +=
            kStep * kStep * std::max(0.0, t->height(last.pose.xy + ahead * dir + side * across) - kBed);
    for (double along = kLength / 3; along <= 2 * kLength / 3; along += 0.002)
      for (double side = 0.016; side <= 0.04; side += 0.001)
        for (double sign : {-1.0, 1.0}) {
          const double above = t->height(start + along * dir + sign * side * across) - kBed;
          out.berm_m = std::max(out.berm_m, above);
          out.berm_m3 += 0.002 * 0.001 * std::max(0.0, above);
        }
    int sections = 0;
    for (double along = kLength / 3; along <= 2 * kLength / 3; along += 0.002, ++sections)
      for (double side = -0.06; side <= 0.06; side += 0.0005)
        out.cut_m2 += 0.0005 * std::max(0.0, kBed - t->height(start + along * dir + side * across));
    out.cut_m2 /= sections;
    if (!nothing_behind) return out;
    // Behind the start (beyond the rim's reach too): no sand put there. (The TIN's large flat
    // triangles there lean toward the vertices of the trench and its berms by some microns.)
    for (double side = -0.03; side <= 0.03; side += 0.005)
      EXPECT_LE(t->height(start - 0.03 * dir + side * across), kBed + 1e-4) << "raised behind the start";
    return out;
  }
};
TYPED_TEST_SUITE(Bulldoze, test::Backends, test::BackendName);

TYPED_TEST(Bulldoze, CarriesAPileAtReposeOnEveryHeading) {
  std::vector<double> heights;
  for (const auto& [start, heading] :
       {std::pair{Vec2(0.08, 0.15), 0.0}, std::pair{Vec2(0.09, 0.09), 35.0}, std::pair{Vec2(0.22, 0.17), 200.0}}) {
    const auto out = this->drag(start, heading);
    // The fall ahead of the blade: the repose slope (to a degree), after every stamp.
    EXPECT_LE(out.steepest_ahead, std::tan(31.0 * std::numbers::pi / 180.0)) << heading;
    // The pile: taller than the cut is deep (sand is carried), far below the former column.
    EXPECT_GT(out.pile_height_m, 2.0 * kDepth) << heading;
    EXPECT_LT(out.pile_height_m, 4.0 * kDepth) << heading;
    heights.push_back(out.pile_height_m);
  }
  const auto [lo, hi] = std::minmax_element(heights.begin(), heights.end());
  EXPECT_LT(*hi - *lo, 0.15 * *hi) << "the pile depends on the heading";
}

}  // namespace
}  // namespace sb

namespace sb {
namespace {

template <class Backend>
class Carry : public Bulldoze<Backend> {};
TYPED_TEST_SUITE(Carry, test::Backends, test::BackendName);

std::string carry_keys(double shed) {
  return "displacement = \"carry\"\ncarry_shed_fraction = " + std::to_string(shed) + "\n";
}

TYPED_TEST(Carry, CarriesItsPileAndShedsItsBerms) {
  const double cut = kLength * 0.03 * kDepth;  // the blade's width times its depth along the stroke
  const auto keeps_all = this->drag(Vec2(0.08, 0.15), 0.0, carry_keys(0.0));
  const auto sheds = this->drag(Vec2(0.08, 0.15), 0.0, carry_keys(0.35));
  const auto turned = this->drag(Vec2(0.22, 0.17), 200.0, carry_keys(0.35));
  // Shedding nothing, the tool arrives with most of what it cut (erosion spills some beside it:
  // a pile left where it lies would hold a third, the last stamp's); shedding a third per blade
  // length, with less (what it sheds ahead of itself, the blade cuts again).
  EXPECT_GT(keeps_all.pile_volume_m3, 0.65 * cut);
  EXPECT_LT(sheds.pile_volume_m3, 0.9 * keeps_all.pile_volume_m3);
  EXPECT_GT(sheds.pile_volume_m3, 0.4 * cut);
  // What it sheds beside the trench is the berm.
  EXPECT_GT(sheds.berm_m, keeps_all.berm_m + 0.001);
  // The pile stands at the repose slope and is the same on another heading.
  for (const auto* out : {&keeps_all, &sheds, &turned})
    EXPECT_LE(out->steepest_ahead, std::tan(31.0 * std::numbers::pi / 180.0));
  // The trench stays open as the grains' does (their section holds about the blade's width times
  // its depth): the pile beside the blade starts beyond the band its walls take as they slump.
  // Put on that band, the flanks slid into the trench with the walls and filled up to a fifth of it.
  EXPECT_GT(keeps_all.cut_m2, 0.93 * 0.03 * kDepth);
  EXPECT_NEAR(turned.pile_height_m, sheds.pile_height_m, 0.15 * sheds.pile_height_m);
  EXPECT_NEAR(turned.pile_volume_m3, sheds.pile_volume_m3, 0.1 * sheds.pile_volume_m3);
}

// A carrying stamp picks up the whole pile the stamp before it heaped (a square blade that sheds
// nothing keeps all of it), with no erosion between them: each stamp removes what the one before
// deposited plus the bed its advance newly cuts, the blade's width times its depth times the
// spacing. On the TIN the stamp's retriangulation removes old vertices just outside the
// footprint, so the pile is picked up before it.
TYPED_TEST(Carry, PicksUpThePileItCarriesWhole) {
  std::vector<std::string> overrides = TypeParam::overrides();
  const Scene s = parse_scene(blade_scene(Vec2(0.08, 0.15), 0.0, carry_keys(0.0)), "carry", overrides);
  auto t = make_terrain(TypeParam::kName, s, HeightField::from_scene(s));
  const StampSchedule schedule = test::schedule_of(s);
  const double new_cut = 0.002 * 0.03 * kDepth;
  double deposited = 0.0, picked_sum = 0.0;
  int stamps = 0;
  for (const ToolStamp& st : schedule.stamps) {
    const StampReport r = t->stamp(st);
    if (st.generation > schedule.stamps.front().generation + 1) {  // past the plunge and the first advance
      picked_sum += r.volume_removed_m3 - deposited;
      ++stamps;
    }
    deposited = r.volume_deposited_m3;
  }
  ASSERT_GT(stamps, 40);
  // The grids' cut leaves the nodes outside the footprint alone (their footprint holds 15 or 16
  // node columns of the 3 cm). The TIN's retriangulation also lowers the pile's surface around
  // the footprint, a volume its deposit gives back rather than its pick-up: a wider tolerance.
  const double tolerance = std::string(TypeParam::kName) == "tin" ? 0.25 : 0.05;
  EXPECT_NEAR(picked_sum / stamps, new_cut, tolerance * new_cut);
}

// A disk's curved front sends sand round it (front_deflection): with the particles' face
// friction it arrives with less pile and leaves more sand in its berms than the same disk whose
// faces hold the sand (the default, infinite friction: nothing slides), volume exact either way
// (drag checks it every stamp). (Its plunge's spoil, 15 mm deep all round, slumps behind the start.)
TYPED_TEST(Carry, ADisksCurvedFrontSendsSandIntoItsBerms) {
  const std::string disk = "shape = \"disk\"\nradius_m = 0.015\n";
  const auto holds = this->drag(Vec2(0.08, 0.15), 0.0, carry_keys(0.0), disk, false);
  const auto slides = this->drag(Vec2(0.08, 0.15), 0.0, carry_keys(0.0) + "face_friction = 0.5\n", disk, false);
  EXPECT_LT(slides.pile_volume_m3, 0.99 * holds.pile_volume_m3);
  EXPECT_GT(slides.berm_m3, holds.berm_m3);  // measured beside the middle third of the stroke
}

}  // namespace
}  // namespace sb
