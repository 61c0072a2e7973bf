// --unset overrides, the scene-key catalogue, the stamp-cost limit and the lazy schedule.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "common/input_error.hpp"
#include "common/scene.hpp"
#include "common/schedule.hpp"

namespace sb {
namespace {

const char* kDisk = R"(
[domain]
size_m = [1.0, 1.0]
[tool]
shape = "disk"
radius_m = 0.03
sides = 24
[stroke]
path_m = [[0.2, 0.2], [0.4, 0.4]]
)";

std::string error_of(const std::vector<std::string>& overrides) {
  try {
    parse_scene(kDisk, "test", overrides);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(SceneUnset, SwitchesAToolShapeThatSetAloneCannot) {
  EXPECT_NE(error_of({"tool.shape=box", "tool.size_m=[0.04, 0.02]"}).find("tool.radius_m"), std::string::npos);
  const Scene s = parse_scene(
      kDisk, "test",
      {unset_override("tool.radius_m"), unset_override("tool.sides"), "tool.shape=box", "tool.size_m=[0.04, 0.02]"});
  EXPECT_EQ(s.tool.shape, ToolShape::Box);
  EXPECT_DOUBLE_EQ(s.tool.half_size_m.x(), 0.02);
  // Unsetting a key restores its default; unsetting an absent key is harmless.
  EXPECT_DOUBLE_EQ(parse_scene(kDisk, "test", {unset_override("tool.radius_m")}).tool.radius_m, 0.02);
  EXPECT_NO_THROW(parse_scene(kDisk, "test", {unset_override("tin.nothing.here")}));
  // A whole table can go.
  EXPECT_EQ(parse_scene(kDisk, "test", {unset_override("tool")}).tool.sides, 32);
  EXPECT_NE(error_of({unset_override("")}).find("--unset"), std::string::npos);
}

TEST(SceneKeys, CatalogueHoldsEveryConditionalKeyOnceWithRangesAndMeanings) {
  const std::vector<SceneKey> keys = scene_keys();
  std::set<std::string> names;
  for (const SceneKey& k : keys) {
    EXPECT_TRUE(names.insert(k.key).second) << k.key << " listed twice";
    EXPECT_FALSE(k.allowed.empty()) << k.key;
    EXPECT_FALSE(k.meaning.empty()) << k.key;
  }
  for (const char* k : {"domain.size_m", "domain.crs", "terrain.amplitude_m", "terrain.path", "tool.size_m",
                        "tool.polygon_m", "tool.volume_m3", "tool.sphere_radius_m", "reference.kind"})
    EXPECT_TRUE(names.count(k)) << k;
  // Ranges that scale with the domain say so; fixed ones do not.
  for (const SceneKey& k : keys) {
    if (k.key == "tool.radius_m") {
      EXPECT_NE(k.allowed.find("domain extent"), std::string::npos) << k.allowed;
    }
    if (k.key == "material.critical_angle_deg") {
      EXPECT_EQ(k.allowed, "(0, 90)");
    }
  }
  // File order: domain first, and the dune keys right after terrain.height_m.
  EXPECT_EQ(keys.front().key, "domain.origin_m");
  for (std::size_t i = 0; i + 1 < keys.size(); ++i)
    if (keys[i].key == "terrain.height_m") {
      EXPECT_EQ(keys[i + 1].key, "terrain.amplitude_m");
    }
}

TEST(SceneKeys, DomainCrsIsReadAndFoundInResolvedText) {
  const Scene s = parse_scene(kDisk, "test", {"domain.crs=\"EPSG:32633\""});
  EXPECT_EQ(s.crs, "EPSG:32633");
  EXPECT_EQ(scene_crs(s.resolved), "EPSG:32633");
  EXPECT_EQ(scene_crs(parse_scene(kDisk, "test").resolved), "");
  EXPECT_EQ(scene_crs("not [ toml"), "");
}

TEST(SceneStampCost, ManyStampsOfManySidesAreRefusedNamingTheKeys) {
  // 2e6 stamps of a 4096-gon: 8e9 corners.
  const std::string e = error_of({"tool.sides=4096", "stroke.spacing_m=1.4142e-7"});
  EXPECT_NE(e.find("stroke.spacing_m"), std::string::npos) << e;
  EXPECT_NE(e.find("tool.sides"), std::string::npos) << e;
  EXPECT_NO_THROW(parse_scene(kDisk, "test", {"tool.sides=4096", "stroke.repeat=1000"}));
}

TEST(SceneFootprint, ToolsTooSmallForEveryBackEndAreRefusedAlike) {
  EXPECT_NE(error_of({"tool.radius_m=1e-12"}).find("tool.radius_m"), std::string::npos);
  EXPECT_NE(error_of({unset_override("tool"), "tool.shape=box", "tool.size_m=[1e-12, 0.01]"}).find("tool.size_m"),
            std::string::npos);
  EXPECT_NO_THROW(parse_scene(kDisk, "test", {"tool.radius_m=1e-4"}));  // smaller than a grid cell is fine
}

TEST(LazySchedule, MillionsOfStampsCostNothingUntilAskedFor) {
  ToolSpec tool;
  tool.sides = 4096;
  Stroke stroke;
  stroke.path_m = {{0.0, 0.0}, {0.1, 0.0}, {0.1, 0.1}};
  stroke.spacing_m = 1e-7;
  stroke.repeat = 5;
  const StampSchedule s = make_schedule(tool, stroke, [](const Vec2&) { return 0.1; });
  const std::size_t per_trace = stamp_arc_count(0.2, 1e-7);
  ASSERT_NEAR(static_cast<double>(per_trace), 2000001.0, 1.0);
  ASSERT_EQ(s.stamps.size(), 5u * per_trace);
  // Any stamp on demand, equal to what a sequential walk gives.
  const ToolStamp last = s.stamps.back();
  EXPECT_EQ(last.generation, s.stamps.size() - 1);
  EXPECT_NEAR(last.pose.xy.y(), 0.1, 1e-12);
  EXPECT_EQ(last.footprint.size(), 4096u);
  const ToolStamp corner = s.stamps[1000000];  // exactly at the bend
  EXPECT_NEAR(corner.pose.xy.x(), 0.1, 1e-12);
  EXPECT_NEAR(corner.pose.xy.y(), 0.0, 1e-12);
  const ToolStamp second_trace = s.stamps[per_trace + 5];
  EXPECT_NEAR(second_trace.pose.xy.x(), 5e-7, 1e-15);
  // Copies share the generator and give the same stamps.
  const StampSchedule copy = s;
  EXPECT_EQ(copy.stamps[123456].pose.xy, s.stamps[123456].pose.xy);
}

TEST(LazySchedule, ArcPositionsOneByOneMatchTheList) {
  for (double length : {0.0, 1e-12, 0.1, 0.1 + 1e-13, 0.37}) {
    const std::vector<double> all = stamp_arc_positions(length, 0.03);
    ASSERT_EQ(all.size(), stamp_arc_count(length, 0.03));
    EXPECT_EQ(all.front(), length > 0.0 && all.size() == 1 ? length : 0.0);
    EXPECT_EQ(all.back(), length);
  }
}

}  // namespace
}  // namespace sb
