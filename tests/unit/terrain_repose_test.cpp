// The angle of repose at any orientation, typed over the back-ends: a plane tilted above the
// critical angle relaxes to within 0.3 degrees of it whatever its azimuth (the default,
// gradient rule), one below the critical angle does not move, and volume is conserved to
// rounding. The edge rule (the paper's) is shown to leave a plane between neighbour
// directions steeper, which is what the gradient rule corrects. A steep cone (cone.toml) relaxes
// to a round cone at the critical angle with each back-end's default settings.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "common/height_field.hpp"
#include "common/reference.hpp"
#include "common/scene.hpp"
#include "common/schedule.hpp"
#include "harness/run/backends.hpp"
#include "terrain_test_support.hpp"

namespace sb {
namespace {

struct Tin {
  static constexpr const char* kName = "tin";
  // A jittered lattice as dense as the grid; volume compensation on (tin.conserve_volume).
  static std::vector<std::string> overrides() {
    return {"tin.conserve_volume=true", "tin.initial_points=144", "tin.refine_m=0.004"};
  }
};
struct Grid {
  static constexpr const char* kName = "grid";
  static std::vector<std::string> overrides() { return {}; }
};
struct Sparse {
  static constexpr const char* kName = "sparse";
  static std::vector<std::string> overrides() { return {}; }
};

// A 0.04 m square plane tilted at `slope_deg` toward `azimuth_deg`, disturbed by a grain
// poured at its centre (the avalanche spreads from there).
std::string plane_scene(double slope_deg, double azimuth_deg) {
  return R"(
[domain]
size_m = [0.04, 0.04]
[terrain]
kind = "plane"
height_m = 0.1
slope_deg = )" +
         std::to_string(slope_deg) + "\nazimuth_deg = " + std::to_string(azimuth_deg) + R"(
[material]
critical_angle_deg = 30.0
[tool]
shape = "pour"
radius_m = 0.003
volume_m3 = 1e-9
[stroke]
path_m = [[0.02, 0.02]]
[grid]
cell_m = 0.004
[output]
raster_m = 0.001
[reference]
kind = "plane"
)";
}

template <class Backend>
class ReposeTyped : public ::testing::Test {
 protected:
  struct Outcome {
    PlaneShape before, after;
    double volume_error_rel = 0.0;  // |V - V0 - poured| / V0
    double moved_far_m = 0.0;       // largest height change outside the poured spot
    bool settled = false;
  };

  // Pours the grain, then erodes until settled.
  Outcome relax_plane(double slope_deg, double azimuth_deg, const std::string& rule_name = "gradient") const {
    std::vector<std::string> overrides = Backend::overrides();
    overrides.push_back("erosion.rule=\"" + rule_name + "\"");
    const Scene s = parse_scene(plane_scene(slope_deg, azimuth_deg), "plane", overrides);
    const HeightField field = HeightField::from_scene(s);
    std::unique_ptr<Terrain> t = make_terrain(Backend::kName, s, field);
    Raster before = Raster::covering(s.domain.box(), s.output.raster_m);
    t->sample(before);
    Outcome o;
    o.before = measure_plane(before);
    const double v0 = t->volume();
    const StampSchedule sch = test::schedule_of(s);
    const ErosionRule rule = test::rule_of(s);
    for (const ToolStamp& st : sch.stamps) t->stamp(st);
    for (int passes = 0; passes < 100000 && !o.settled; passes += 256) {
      t->erode(rule, ErosionBudget{256});
      t->simplify(SimplifyParams{s.tin.alpha_flat_deg});
      o.settled = t->stats().active == 0;
    }
    o.volume_error_rel = std::abs(t->volume() - v0 - sch.stamps.front().pour_volume_m3) / v0;
    Raster after = before;
    t->sample(after);
    o.after = measure_plane(after);
    for (std::size_t iy = 0; iy < after.ny; ++iy)
      for (std::size_t ix = 0; ix < after.nx; ++ix)
        if ((after.point(ix, iy) - Vec2(0.02, 0.02)).norm() > 0.01)
          o.moved_far_m = std::max(o.moved_far_m, std::abs(after.at(ix, iy) - before.at(ix, iy)));
    const IntegrityReport r = t->check();
    EXPECT_TRUE(r.ok()) << ::testing::PrintToString(r.problems);
    return o;
  }
};

struct BackendName {
  template <class T>
  static std::string GetName(int) {
    return T::kName;
  }
};
using Backends = ::testing::Types<Tin, Grid, Sparse>;
TYPED_TEST_SUITE(ReposeTyped, Backends, BackendName);

TYPED_TEST(ReposeTyped, PlaneSteeperThanCriticalRelaxesToItInEveryAzimuth) {
  // Along a neighbour direction, between two (10, 22.5, 30, 67.5 on the 8-neighbour grid),
  // and in another quadrant (120).
  for (double azimuth : {0.0, 10.0, 22.5, 30.0, 45.0, 67.5, 120.0}) {
    const auto o = this->relax_plane(34.0, azimuth);
    EXPECT_TRUE(o.settled) << "azimuth " << azimuth;
    EXPECT_NEAR(o.before.slope_deg, 34.0, 0.01);
    EXPECT_NEAR(o.after.slope_deg, 30.0, 0.3) << "azimuth " << azimuth;
    // The closed box turns the relaxed plane a little (sand piles against the lower walls).
    EXPECT_NEAR(o.after.azimuth_deg, azimuth > 180.0 ? azimuth - 360.0 : azimuth, 3.0);
    EXPECT_LT(o.volume_error_rel, 1e-12) << "azimuth " << azimuth;
  }
}

TYPED_TEST(ReposeTyped, PlaneBelowCriticalDoesNotMove) {
  for (double azimuth : {0.0, 10.0, 22.5, 30.0, 45.0, 67.5}) {
    const auto o = this->relax_plane(28.0, azimuth);
    EXPECT_TRUE(o.settled);
    EXPECT_EQ(o.moved_far_m, 0.0) << "azimuth " << azimuth;
    EXPECT_NEAR(o.after.slope_deg, 28.0, 0.01);
    EXPECT_LT(o.volume_error_rel, 1e-12);
  }
}

// The paper's edge rule rests a plane between two neighbour directions steeper than the
// critical angle (by up to 2 degrees on the 8-neighbour grid); the gradient rule does not.
TYPED_TEST(ReposeTyped, EdgeRuleLeavesOffAxisPlanesSteeper) {
  const auto edge = this->relax_plane(34.0, 22.5, "edge");
  const auto gradient = this->relax_plane(34.0, 22.5, "gradient");
  EXPECT_GT(edge.after.slope_deg, gradient.after.slope_deg + 0.5);
  EXPECT_LT(edge.volume_error_rel, 1e-12);
}

// The shipped steep cone (cone.toml, 2e-5 m^3 at 35 degrees on a 0.3 m square), each back-end
// with its default settings, relaxed after the disturbance. Measured: flank 29.47 deg, roundness
// 0.025, RMSE 67 um on the TIN (283 vertices); 30.02 deg, 0.007, 20 um on the grids.
TYPED_TEST(ReposeTyped, SteepConeRelaxesToARoundConeAtCritical) {
  const Scene s = load_scene(std::filesystem::path(SB_SOURCE_DIR) / "experiments/scenes/cone.toml");
  const HeightField field = HeightField::from_scene(s);
  std::unique_ptr<Terrain> t = make_terrain(TypeParam::kName, s, field);
  Raster before = Raster::covering(s.domain.box(), s.output.raster_m);
  t->sample(before);
  const double v0 = t->volume();
  const StampSchedule sch = test::schedule_of(s);
  const ErosionRule rule = test::rule_of(s);
  for (const ToolStamp& st : sch.stamps) t->stamp(st);
  bool settled = false;
  for (int passes = 0; passes < 100000 && !settled; passes += 256) {
    t->erode(rule, ErosionBudget{256});
    t->simplify(SimplifyParams{s.tin.alpha_flat_deg});
    settled = t->stats().active == 0;
  }
  EXPECT_TRUE(settled);
  EXPECT_LT(std::abs(t->volume() - v0 - sch.stamps.front().pour_volume_m3) / v0, 1e-12);
  Raster after = before;
  t->sample(after);
  const auto m = accuracy_metrics(s, sch, field, before, after);
  EXPECT_NEAR(m["pile.flank_angle_deg"].get<double>(), 30.0, 0.8);
  EXPECT_LT(m["pile.roundness"].get<double>(), 0.04);
  EXPECT_LT(m["reference.rmse_m"].get<double>(), 100e-6);
  const IntegrityReport r = t->check();
  EXPECT_TRUE(r.ok()) << ::testing::PrintToString(r.problems);
}

// The poured pile (pile.toml) on a fine model, where the sand spreads over many elements: with
// the fine rule alone (erosion.cascade = false, as pile.toml sets it) it rests as the critical
// cone. With the settling cascade it ends flatter (recorded, not asserted; results/cascade.md).
// Measured (flank, RMSE): grid and sparse grid at 1 mm 30.00 deg, 28 um (cascade: 29.04, 107);
// TIN of 5e4 initial points 30.01 deg, 15 um (cascade: 28.17, 174).
TYPED_TEST(ReposeTyped, APouredPileOnAFineModelRestsAtCriticalWithoutTheCascade) {
  const std::string fine = std::string(TypeParam::kName) == "tin" ? "tin.initial_points=50000" : "grid.cell_m=0.001";
  for (const char* cascade : {"false", "true"}) {
    const Scene s = load_scene(std::filesystem::path(SB_SOURCE_DIR) / "experiments/scenes/pile.toml",
                               {fine, std::string("erosion.cascade=") + cascade});
    const HeightField field = HeightField::from_scene(s);
    std::unique_ptr<Terrain> t = make_terrain(TypeParam::kName, s, field);
    Raster before = Raster::covering(s.domain.box(), s.output.raster_m);
    t->sample(before);
    const StampSchedule sch = test::schedule_of(s);
    const ErosionRule rule = test::rule_of(s);
    for (const ToolStamp& st : sch.stamps) {
      t->stamp(st);
      t->erode(rule, ErosionBudget{s.erosion.max_passes_per_step});
      t->simplify(SimplifyParams{s.tin.alpha_flat_deg});
    }
    for (int passes = 0; passes < 200000 && t->stats().active > 0; passes += 64) {
      t->erode(rule, ErosionBudget{.max_passes = 64, .settling = true, .cascade = s.erosion.cascade});
      t->simplify(SimplifyParams{s.tin.alpha_flat_deg});
    }
    ASSERT_EQ(t->stats().active, 0u);
    Raster after = before;
    t->sample(after);
    const auto m = accuracy_metrics(s, sch, field, before, after);
    const double flank = m["pile.flank_angle_deg"].get<double>(), rmse = m["reference.rmse_m"].get<double>();
    this->RecordProperty(std::string("flank_deg_cascade_") + cascade, std::to_string(flank));
    this->RecordProperty(std::string("rmse_um_cascade_") + cascade, std::to_string(rmse * 1e6));
    if (std::string(cascade) == "true") continue;
    EXPECT_NEAR(flank, 30.0, 0.3);
    EXPECT_LT(rmse, 40e-6);
    EXPECT_LT(m["pile.roundness"].get<double>(), 0.03);
  }
}

}  // namespace
}  // namespace sb
