// Erosion on the TIN (the paper's step 2a-2e): the common rule over TIN edges conserves
// volume, relaxes slopes to the critical angle, refines where sand flows, and empties L_e.
#include <numbers>
#include <random>

#include "common/input_error.hpp"
#include "tests/unit/tin_test_support.hpp"

namespace sb::tin::test {
namespace {

// A TIN of jittered points with a steep bump in the middle (no long edges: no splits).
std::unique_ptr<Terrain> bump(const Scene& s, std::size_t n = 2500) {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(0.1, 0.9);
  const auto side = static_cast<std::size_t>(std::sqrt(static_cast<double>(n)));
  const double cell = 0.5 / static_cast<double>(side);
  std::vector<Vec3> pts;
  for (std::size_t i = 0; i < side * side; ++i) {
    const Vec2 p((static_cast<double>(i % side) + u(rng)) * cell, (static_cast<double>(i / side) + u(rng)) * cell);
    const double r = (p - Vec2(0.25, 0.25)).norm();
    pts.emplace_back(p.x(), p.y(), 0.1 + std::max(0.0, 0.08 - 0.8 * r));  // a 39-degree cone
  }
  return make_tin_terrain_from_points(s, pts);
}

// Every vertex joins L_e: a pour of nothing anywhere does not do it, so stamp the bump's
// top with a tool above it: its contours' vertices and their neighbours become active.
void activate(Terrain& t, const Scene& s) { t.stamp(stamp_at(s, {0.25, 0.25}, 0.5)); }

TEST(TinErosion, TransfersConserveVolumeExactly) {
  const Scene s = scene(kFlatScene, {"tin.refine_m=0.5"});  // no splits
  auto t = bump(s);
  activate(*t, s);
  const double v0 = t->volume();
  const ErosionRule rule = rule_of(s);
  double moved = 0.0;
  for (int k = 0; k < 50; ++k) {
    const ErosionReport r = t->erode(rule, ErosionBudget{4});
    moved += r.volume_moved_m3;
    EXPECT_NEAR(t->volume(), v0, 1e-14 * v0) << "pass block " << k;
  }
  EXPECT_GT(moved, 1e-6);
  SB_EXPECT_TIN_OK(*t);
}

TEST(TinErosion, RelaxesToTheCriticalAngleAndEmptiesTheActiveSet) {
  const Scene s = scene(kFlatScene, {"tin.refine_m=0.5"});
  auto t = bump(s);
  activate(*t, s);
  EXPECT_GT(t->max_slope_deg(), 35.0);
  ASSERT_TRUE(relax(*t, s));
  SB_EXPECT_TIN_OK(*t);
  EXPECT_EQ(t->stats().active, 0u);
  EXPECT_LE(t->max_slope_deg(), 30.0 + s.erosion.settle_tolerance_deg + 1e-9);
  // Settled means settled: one more pass moves nothing.
  const ErosionReport r = t->erode(rule_of(s), ErosionBudget{1});
  EXPECT_EQ(r.transfers, 0u);
}

TEST(TinErosion, BudgetLimitsTheWork) {
  const Scene s = scene(kFlatScene, {"tin.refine_m=0.5"});
  auto t = bump(s);
  activate(*t, s);
  const ErosionReport r = t->erode(rule_of(s), ErosionBudget{1000, 25});
  EXPECT_EQ(r.updates, 25u);
  const ErosionReport none = t->erode(rule_of(s), ErosionBudget{0});
  EXPECT_EQ(none.passes, 0);
  EXPECT_EQ(none.updates, 0u);
}

TEST(TinErosion, IdleVerticesLeaveTheActiveSet) {
  const Scene s = scene(kFlatScene, {"erosion.idle_passes=3"});
  auto t = make(s);
  t->stamp(stamp_at(s, {0.25, 0.25}, 0.2));  // no cut: new flat vertices join L_e, nothing moves
  ASSERT_GT(t->stats().active, 0u);
  t->erode(rule_of(s), ErosionBudget{2});
  EXPECT_GT(t->stats().active, 0u);
  const ErosionReport r = t->erode(rule_of(s), ErosionBudget{1});
  EXPECT_EQ(r.transfers, 0u);
  EXPECT_EQ(r.active, 0u);
  EXPECT_EQ(t->stats().active, 0u);
}

TEST(TinErosion, APileOnTwoTrianglesRefinesAndRelaxesToACone) {
  // pile.toml with a coarser refinement, to stay fast: 4 pours of 5e-6 m^3. The edge rule:
  // with the gradient rule this TIN rests with a flat shoulder beside the top (every edge and
  // fan gradient at or below critical, the top 5.8% low).
  const Scene s =
      scene(kPileScene, {"stroke.repeat=4", "tool.volume_m3=5e-6", "tin.refine_m=0.004", "erosion.rule=\"edge\""});
  auto t = make(s);
  ASSERT_EQ(t->stats().triangles, 2u);
  const double v0 = t->volume();
  for (const ToolStamp& st : schedule_of(s).stamps) {
    step(*t, s, st);
    SB_ASSERT_TIN_OK(*t);
  }
  ASSERT_TRUE(relax(*t, s));
  SB_EXPECT_TIN_OK(*t);
  EXPECT_GT(t->stats().vertices, 200u) << "the mesh refined where the sand went";
  EXPECT_LE(t->max_slope_deg(), 30.0 + s.erosion.settle_tolerance_deg + 1e-9);
  // The ideal cone of 2e-5 m^3 at 30 degrees: radius 32.1 mm, height 18.5 mm.
  const double volume = 2e-5;
  const double tan30 = std::tan(std::numbers::pi / 6.0);
  const double radius = std::cbrt(3.0 * volume / (std::numbers::pi * tan30));
  const double top = t->height({0.15, 0.15}) - 0.05;
  EXPECT_NEAR(top, radius * tan30, 0.05 * radius * tan30);
  // Round: the flank at half the radius is about the same in every direction.
  for (int k = 0; k < 8; ++k) {
    const double a = 2.0 * std::numbers::pi * k / 8.0;
    const double h = t->height(Vec2(0.15, 0.15) + 0.5 * radius * Vec2(std::cos(a), std::sin(a))) - 0.05;
    EXPECT_NEAR(h, 0.5 * radius * tan30, 0.15 * radius * tan30) << "direction " << k;
  }
  // Sand stayed in a disc somewhat larger than the ideal cone.
  EXPECT_NEAR(t->height({0.15 + 1.5 * radius, 0.15}), 0.05, 1e-3 * radius * tan30);
  // Volume: the Delaunay flips after each split change the surface a little (2% here with
  // 4 mm edges; tin.conserve_volume compensates it, see the next test).
  EXPECT_NEAR(t->volume() - v0, volume, 0.05 * volume);
}

// pile.toml's first pours (4 of 5e-6 m^3 unless `keys` say otherwise, the default gradient
// rule) with check() and the volume (exact: tin.conserve_volume) after every step, settled.
struct PileOutcome {
  std::size_t vertices = 0;
  std::size_t poured_vertices = 0;  // after the pours, before settling
  double spread = 0.0;              // std / mean of the half-height radius's heights over 32 directions
  double top = 0.0;
};
void pour_pile(const std::vector<std::string>& keys, PileOutcome& out) {
  std::vector<std::string> all = {"stroke.repeat=4", "tool.volume_m3=5e-6"};
  all.insert(all.end(), keys.begin(), keys.end());
  const Scene s = scene(kPileScene, all);
  auto t = make(s);
  const double v0 = t->volume();
  double added = 0.0;
  for (const ToolStamp& st : schedule_of(s).stamps) {
    step(*t, s, st);
    added += st.pour_volume_m3;
    SB_ASSERT_TIN_OK(*t);
    EXPECT_NEAR(t->volume(), v0 + added, 1e-13 * v0);
  }
  out.poured_vertices = t->stats().vertices;
  EXPECT_TRUE(relax(*t, s));
  SB_EXPECT_TIN_OK(*t);
  EXPECT_NEAR(t->volume(), v0 + added, 1e-13 * v0);
  out.vertices = t->stats().vertices;
  out.top = t->height({0.15, 0.15}) - 0.05;
  const double radius = std::cbrt(3.0 * added / (std::numbers::pi * std::tan(std::numbers::pi / 6.0)));
  double sum = 0.0, sum2 = 0.0;
  for (int k = 0; k < 32; ++k) {
    const double a = 2.0 * std::numbers::pi * k / 32.0;
    const double h = t->height(Vec2(0.15, 0.15) + 0.5 * radius * Vec2(std::cos(a), std::sin(a))) - 0.05;
    sum += h;
    sum2 += h * h;
  }
  const double mean = sum / 32.0;
  out.spread = std::sqrt(std::max(0.0, sum2 / 32.0 - mean * mean)) / mean;
}

TEST(TinErosion, ConserveVolumeMakesRefiningErosionExact) {
  PileOutcome out;  // pour_pile checks the volume after every step and after settling
  pour_pile({"stroke.repeat=2", "tin.refine_m=0.004", "tin.conserve_volume=true"}, out);
  EXPECT_GT(out.vertices, 100u) << "the mesh refined";
}

// Curvature refinement (tin.curvature_tolerance_m): creases that sand crosses are split down
// to half of tin.refine_m, the flanks stay coarse; the pile comes out rounder than without it,
// and as high as the ideal cone.
TEST(TinErosion, CurvatureRefinementSplitsCreasesWhereSandFlows) {
  PileOutcome off, on;
  pour_pile({}, off);
  pour_pile({"tin.curvature_tolerance_m=0.0003"}, on);
  // Measured: spread 0.025 and 0.018, top 18.0 mm and about the ideal 18.5 mm.
  EXPECT_GT(on.vertices, off.vertices);
  EXPECT_LT(on.vertices, 2 * off.vertices) << "planar flanks stay coarse";
  EXPECT_LT(on.spread, off.spread);
  EXPECT_LT(on.spread, 0.03);
  const double ideal_top =
      std::cbrt(3.0 * 2e-5 / (std::numbers::pi * std::tan(std::numbers::pi / 6.0))) * std::tan(std::numbers::pi / 6.0);
  EXPECT_NEAR(on.top, ideal_top, 0.05 * ideal_top);
  EXPECT_NEAR(off.top, ideal_top, 0.05 * ideal_top);
}

// tin.curvature_when = "settling": no crease is split while the tool pours (the steps run as
// without curvature refinement, vertex for vertex), and the creases of the settling pile are.
TEST(TinErosion, CurvatureRefinementWhileSettlingLeavesThePoursAlone) {
  PileOutcome off, always, settling;
  pour_pile({}, off);
  pour_pile({"tin.curvature_tolerance_m=0.0003"}, always);
  pour_pile({"tin.curvature_tolerance_m=0.0003", "tin.curvature_when=settling"}, settling);
  EXPECT_GT(always.poured_vertices, off.poured_vertices);
  EXPECT_EQ(settling.poured_vertices, off.poured_vertices);
  EXPECT_GT(settling.vertices, off.vertices);
  EXPECT_LT(settling.spread, 0.03);
  const double ideal_top =
      std::cbrt(3.0 * 2e-5 / (std::numbers::pi * std::tan(std::numbers::pi / 6.0))) * std::tan(std::numbers::pi / 6.0);
  EXPECT_NEAR(settling.top, ideal_top, 0.05 * ideal_top);
}

// A trench at 22.5 degrees with curvature refinement (trench_azimuth.toml's stroke): splits
// along the last stamp's contours once put vertices a hair beside a constraint, chains of
// slivers the constraints kept, and the run never settled (20000 passes; facets at 89.9 degrees).
TEST(TinErosion, CurvatureRefinedTrenchSettlesWithoutSlivers) {
  for (const char* rule : {"erosion.rule=edge", "erosion.rule=gradient"}) {
    const Scene s = scene(kFlatScene, {"domain.size_m=[0.3, 0.3]", "terrain.height_m=0.05", "tool.radius_m=0.015",
                                       "stroke.path_m=[[0.039134, 0.104078], [0.260866, 0.195922]]",
                                       "tin.curvature_tolerance_m=0.0003", rule});
    auto t = make(s);
    const double v0 = t->volume();
    for (const ToolStamp& st : schedule_of(s).stamps) step(*t, s, st);
    EXPECT_TRUE(relax(*t, s, 20000)) << rule;
    SB_EXPECT_TIN_OK(*t);
    // Settled: no facet steeper than critical + erosion.settle_tolerance_deg (0.1).
    EXPECT_LT(t->max_slope_deg(), 30.1 + 1e-6) << rule;
    EXPECT_NEAR(t->volume(), v0, 1e-12 * v0);
  }
}

TEST(TinErosion, CurvatureRefinementStopsAtAQuarterOfRefineM) {
  // A tolerance of a micrometre and a floor of a nanometre: the floor is clamped to a quarter
  // of tin.refine_m (3 mm here), so the mesh stays bounded (a 30 um floor ran for minutes).
  PileOutcome tiny, quarter;
  pour_pile({"stroke.repeat=2", "tin.refine_m=0.012", "tin.curvature_tolerance_m=1e-6", "tin.refine_min_m=1e-9"}, tiny);
  pour_pile({"stroke.repeat=2", "tin.refine_m=0.012", "tin.curvature_tolerance_m=1e-6", "tin.refine_min_m=0.003"},
            quarter);
  PileOutcome half;
  pour_pile({"stroke.repeat=2", "tin.refine_m=0.012", "tin.curvature_tolerance_m=1e-6"}, half);
  EXPECT_EQ(tiny.vertices, quarter.vertices);
  EXPECT_GT(quarter.vertices, half.vertices) << "the floor decides the size here";
  EXPECT_LT(tiny.vertices, 2000u);
}

TEST(TinErosion, SplitsBesideLongConstraintsDoNotWalk) {
  // A polygon with a 0.2 m spike cut along x leaves contours with long constrained edges; the
  // erosion after each stamp refines beside them, asking whether a constrained edge's middle
  // lies exactly on it. That answer is an orientation test: it once located the middle by a
  // walk from the last edit, often far along the spike (1.53 walk steps per erosion update
  // here; now 0.32, the walks of the splits' insertions).
  const Scene s =
      scene(sb::test::flat_sand_scene("0.5", "0.1",
                                      "shape = \"polygon\"\ndepth_m = 0.01\n"
                                      "polygon_m = [[-0.01, -0.01], [0.01, -0.01], [0.2, 0.0], "
                                      "[0.01, 0.01], [-0.01, 0.01]]\n",
                                      "[stroke]\npath_m = [[0.05, 0.25], [0.25, 0.25]]\nspacing_m = 0.01\n"));
  auto t = make(s);
  const double v0 = t->volume();
  std::uint64_t walked = 0, updates = 0;
  for (const ToolStamp& st : schedule_of(s).stamps) {
    t->stamp(st);
    const std::uint64_t before = t->stats().walk_steps;
    updates += t->erode(rule_of(s), ErosionBudget{s.erosion.max_passes_per_step}).updates;
    walked += t->stats().walk_steps - before;
    t->simplify(SimplifyParams{s.tin.alpha_flat_deg});
  }
  RecordProperty("walk_steps_per_update", std::to_string(static_cast<double>(walked) / updates));
  EXPECT_GT(updates, 1000u);
  EXPECT_LT(static_cast<double>(walked), 1.0 * static_cast<double>(updates));
  EXPECT_NEAR(t->volume(), v0, 1e-12 * v0);
  SB_EXPECT_TIN_OK(*t);
}

TEST(TinErosion, RefusesABadRule) {
  const Scene s = scene();
  auto t = make(s);
  ErosionRule rule = rule_of(s);
  rule.fraction = std::nan("");
  EXPECT_THROW(t->erode(rule, ErosionBudget{}), InputError);
}

}  // namespace
}  // namespace sb::tin::test
