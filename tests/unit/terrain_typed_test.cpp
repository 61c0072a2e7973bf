// Properties every back-end shares, typed over the back-ends (each built through
// sb::make_terrain, as the runner builds them): volume bookkeeping, slopes after
// relaxation, the stamp's depth inside its footprint, height queries agreeing with sample(),
// and check() after every operation.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "common/height_field.hpp"
#include "common/scene.hpp"
#include "common/schedule.hpp"
#include "harness/run/backends.hpp"
#include "terrain_backends.hpp"
#include "terrain_test_support.hpp"

namespace sb {
namespace {

const std::string kFlat = test::flat_sand_scene("0.3", "0.1", test::kDisk2cm, R"(
[stroke]
path_m = [[0.1, 0.15], [0.2, 0.15]]
spacing_m = 0.005
[grid]
cell_m = 0.004
)");

const std::string kDunes = R"(
[domain]
size_m = [0.3, 0.3]
[terrain]
kind = "dunes"
height_m = 0.08
amplitude_m = 0.02
wavelength_m = 0.15
seed = 4
[material]
critical_angle_deg = 32.0
[tool]
shape = "box"
size_m = [0.03, 0.02]
depth_m = 0.006
[stroke]
path_m = [[0.08, 0.1], [0.2, 0.2]]
spacing_m = 0.006
[tin]
tolerance_m = 0.0005
[grid]
cell_m = 0.004
)";

const std::string kPile =
    test::flat_sand_scene("0.2", "0.05", "shape = \"pour\"\nradius_m = 0.006\nvolume_m3 = 2e-6\n", R"(
[erosion]
max_passes_per_step = 8
[stroke]
path_m = [[0.1, 0.1]]
repeat = 4
[tin]
refine_m = 0.004
[grid]
cell_m = 0.004
)");

template <class Backend>
class TerrainTyped : public ::testing::Test {
 protected:
  Scene scene(const std::string& text, std::vector<std::string> extra = {}) const {
    std::vector<std::string> overrides = Backend::overrides();
    overrides.insert(overrides.end(), extra.begin(), extra.end());
    return parse_scene(text, "typed", overrides);
  }
  std::unique_ptr<Terrain> make(const Scene& s) const {
    return make_terrain(Backend::kName, s, HeightField::from_scene(s));
  }
  static void expect_ok(const Terrain& t, const char* when) {
    const IntegrityReport r = t.check();
    EXPECT_TRUE(r.ok()) << when << ": " << ::testing::PrintToString(r.problems);
  }
};

TYPED_TEST_SUITE(TerrainTyped, test::Backends, test::BackendName);

TYPED_TEST(TerrainTyped, VolumeIsKeptByEveryPhase) {
  for (const std::string& text : {kFlat, kDunes}) {
    const Scene s = this->scene(text);
    auto t = this->make(s);
    const double v0 = t->volume();
    const double tol = TypeParam::kVolumeTolerance * v0;
    for (const ToolStamp& st : test::schedule_of(s).stamps) {
      const StampReport r = t->stamp(st);
      EXPECT_GE(r.volume_removed_m3, 0.0);
      EXPECT_GT(r.volume_deposited_m3, 0.0);
      EXPECT_NEAR(t->volume(), v0, tol) << "after stamp " << st.generation;
      t->erode(test::rule_of(s), ErosionBudget{s.erosion.max_passes_per_step});
      EXPECT_NEAR(t->volume(), v0, tol) << "after erosion " << st.generation;
      t->simplify(SimplifyParams{s.tin.alpha_flat_deg});
      EXPECT_NEAR(t->volume(), v0, tol) << "after simplification " << st.generation;
      this->expect_ok(*t, "after a step");
    }
  }
}

TYPED_TEST(TerrainTyped, PoursAddTheirVolume) {
  const Scene s = this->scene(kPile);
  auto t = this->make(s);
  const double v0 = t->volume();
  double added = 0.0;
  for (const ToolStamp& st : test::schedule_of(s).stamps) {
    t->stamp(st);
    added += st.pour_volume_m3;
    EXPECT_NEAR(t->volume(), v0 + added, TypeParam::kVolumeTolerance * v0);
    t->erode(test::rule_of(s), ErosionBudget{s.erosion.max_passes_per_step});
    EXPECT_NEAR(t->volume(), v0 + added, TypeParam::kVolumeTolerance * v0);
    this->expect_ok(*t, "after a pour");
  }
  EXPECT_GT(t->height({0.1, 0.1}), 0.05 + 1e-3);
}

TYPED_TEST(TerrainTyped, SlopesAfterRelaxationAreAtMostCritical) {
  for (const std::string& text : {kFlat, kPile}) {
    const Scene s = this->scene(text);
    auto t = this->make(s);
    for (const ToolStamp& st : test::schedule_of(s).stamps) {
      t->stamp(st);
      t->erode(test::rule_of(s), ErosionBudget{s.erosion.max_passes_per_step});
      t->simplify(SimplifyParams{s.tin.alpha_flat_deg});
    }
    EXPECT_GT(t->max_slope_deg(), s.material.critical_angle_deg + 1.0) << "the stroke left steep walls";
    ASSERT_TRUE(test::relax(*t, s));
    this->expect_ok(*t, "after relaxation");
    EXPECT_LE(t->max_slope_deg(), s.material.critical_angle_deg + s.erosion.settle_tolerance_deg + 1e-9);
  }
}

TYPED_TEST(TerrainTyped, StampReachesItsDepthInsideTheFootprint) {
  for (const std::string& text : {kFlat, kDunes}) {
    const Scene s = this->scene(text);
    auto t = this->make(s);
    const Vec2 c(0.15, 0.15);
    const double bottom = t->height(c) - 0.008;
    ToolPose pose;
    pose.xy = c;
    pose.bottom_z = bottom;
    pose.heading_rad = 0.3;
    const ToolStamp st = make_stamp(s.tool, pose, Vec2(std::cos(0.3), std::sin(0.3)), 0);
    t->stamp(st);
    this->expect_ok(*t, "after the stamp");
    // Points at least 1.5 grid cells inside the footprint are at (or below) the tool.
    const double margin = 1.5 * s.grid.cell_m;
    int tested = 0;
    for (double x = 0.1; x <= 0.2; x += 0.001)
      for (double y = 0.1; y <= 0.2; y += 0.001) {
        const Vec2 p(x, y);
        if (!st.contains(p) || distance_to_boundary(st.footprint, p) < margin) continue;
        EXPECT_LE(t->height(p), bottom + 1e-9) << "at " << p.transpose();
        ++tested;
      }
    EXPECT_GT(tested, 20);
  }
}

TYPED_TEST(TerrainTyped, HeightQueriesAgreeWithSample) {
  const Scene s = this->scene(kDunes);
  auto t = this->make(s);
  for (const ToolStamp& st : test::schedule_of(s).stamps) t->stamp(st);
  t->erode(test::rule_of(s), ErosionBudget{8});
  Raster r = Raster::covering(s.domain.box(), 0.0035);
  t->sample(r);
  ASSERT_EQ(r.values.size(), r.nx * r.ny);
  for (std::size_t iy = 0; iy < r.ny; ++iy)
    for (std::size_t ix = 0; ix < r.nx; ++ix) ASSERT_NEAR(r.at(ix, iy), t->height(r.point(ix, iy)), 1e-12);
}

TYPED_TEST(TerrainTyped, StatsAndMeshAreConsistent) {
  const Scene s = this->scene(kFlat);
  auto t = this->make(s);
  for (const ToolStamp& st : test::schedule_of(s).stamps) t->stamp(st);
  const ModelStats st = t->stats();
  const SurfaceMesh m = t->mesh();
  EXPECT_GT(st.bytes, 0u);
  EXPECT_EQ(m.triangles.empty(), false);
  double volume = 0.0;
  for (const auto& tri : m.triangles) {
    const Vec3 &a = m.vertices[tri[0]], &b = m.vertices[tri[1]], &c = m.vertices[tri[2]];
    volume += 0.5 * cross2((b - a).head<2>(), (c - a).head<2>()) * (a.z() + b.z() + c.z()) / 3.0;
  }
  // The mesh is the back-end's surface, or a triangulation of it (the grid's bilinear cells).
  EXPECT_NEAR(volume, t->volume(), 1e-3 * t->volume());
  EXPECT_EQ(std::string(t->name()), TypeParam::kName);
}

}  // namespace
}  // namespace sb
