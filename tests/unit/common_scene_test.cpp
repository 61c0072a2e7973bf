#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "common/height_field.hpp"
#include "common/input_error.hpp"
#include "common/png_io.hpp"
#include "common/scene.hpp"

namespace sb {
namespace {

const char* kMinimal = R"(
[domain]
size_m = [1.0, 1.0]
[stroke]
path_m = [[0.2, 0.2], [0.4, 0.4]]
)";

std::string error_of(const std::string& text, const std::vector<std::string>& overrides = {}) {
  try {
    parse_scene(text, "test", overrides);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Scene, MinimalSceneGetsDefaults) {
  const Scene s = parse_scene(kMinimal, "test");
  EXPECT_EQ(s.terrain.kind, TerrainKind::Flat);
  EXPECT_DOUBLE_EQ(s.material.critical_angle_deg, 30.0);
  EXPECT_DOUBLE_EQ(s.tin.alpha_flat_deg, 0.4);
  EXPECT_EQ(s.grid.neighbours, 8);
  EXPECT_EQ(s.grid.threads, 1);
  EXPECT_EQ(s.stroke.path_m.size(), 2u);
}

TEST(Scene, ShippedScenesLoad) {
  for (const char* name : {"flat_stroke", "pile", "dunes", "cone"}) {
    const auto path = std::filesystem::path(SB_SOURCE_DIR) / "experiments/scenes" / (std::string(name) + ".toml");
    EXPECT_NO_THROW(load_scene(path)) << name;
  }
}

TEST(Scene, OverridesReplaceAndAddKeys) {
  const Scene s = parse_scene(
      kMinimal, "test",
      {"tool.radius_m=0.05", "grid.storage=float", "tin.conserve_volume=true", "stroke.path_m=[[0.1, 0.1]]"});
  EXPECT_DOUBLE_EQ(s.tool.radius_m, 0.05);
  EXPECT_EQ(s.grid.storage, GridStorage::Float);
  EXPECT_TRUE(s.tin.conserve_volume);
  EXPECT_EQ(s.stroke.path_m.size(), 1u);
  EXPECT_NE(s.resolved.find("radius_m = 0.05"), std::string::npos);
}

struct BadField {
  std::vector<std::string> overrides;
  std::string key;   // must appear in the message
  std::string what;  // and this too
};

class SceneRejects : public ::testing::TestWithParam<BadField> {};

TEST_P(SceneRejects, WithAMessageNamingTheField) {
  const BadField& b = GetParam();
  const std::string msg = error_of(kMinimal, b.overrides);
  ASSERT_FALSE(msg.empty()) << "accepted: " << b.key;
  EXPECT_NE(msg.find(b.key), std::string::npos) << msg;
  EXPECT_NE(msg.find(b.what), std::string::npos) << msg;
}

INSTANTIATE_TEST_SUITE_P(
    Fields, SceneRejects,
    ::testing::Values(
        // out of range
        BadField{{"tool.radius_m=-0.01"}, "tool.radius_m", "out of range"},
        BadField{{"tool.radius_m=0"}, "tool.radius_m", "(0,"},
        BadField{{"material.critical_angle_deg=90"}, "material.critical_angle_deg", "(0, 90)"},
        BadField{{"material.transfer_fraction=2.5"}, "material.transfer_fraction", "out of range"},
        BadField{{"grid.cell_m=-1"}, "grid.cell_m", "out of range"},
        BadField{{"grid.neighbours=6"}, "grid.neighbours", "4 or 8"},
        BadField{{"grid.threads=3"}, "grid.threads", "[1, 2]"},
        BadField{{"stroke.spacing_m=0"}, "stroke.spacing_m", "out of range"},
        BadField{{"stroke.repeat=0"}, "stroke.repeat", "out of range"},
        BadField{{"tin.alpha_flat_deg=50"}, "tin.alpha_flat_deg", "[0, 45]"},
        BadField{{"domain.size_m=[1.0, -1.0]"}, "domain.size_m[1]", "finite number in"},
        BadField{{"tool.sides=2"}, "tool.sides", "integer in [3, 4096]"},
        // a cone larger than the domain's inscribed circle can hold
        BadField{{"terrain.kind=\"cone\"", "terrain.volume_m3=1"}, "terrain.volume_m3", "out of range"},
        BadField{{"terrain.kind=\"cone\"", "terrain.slope_deg=90"}, "terrain.slope_deg", "[1, 89]"},
        // NaN and infinity
        BadField{{"tool.radius_m=nan"}, "tool.radius_m", "finite"},
        BadField{{"terrain.height_m=inf"}, "terrain.height_m", "finite"},
        BadField{{"stroke.path_m=[[0.1, nan]]"}, "stroke.path_m[0]", "finite"},
        // wrong type
        BadField{{"tool.radius_m=\"big\""}, "tool.radius_m", "must be a number"},
        BadField{{"tool.shape=3"}, "tool.shape", "one of disk"},
        BadField{{"tool.shape=spoon"}, "tool.shape", "one of disk"},
        BadField{{"erosion.relax_at_end=1"}, "erosion.relax_at_end", "true or false"},
        BadField{{"grid.neighbours=8.5"}, "grid.neighbours", "integer"},
        BadField{{"stroke.path_m=[1, 2]"}, "stroke.path_m[0]", "[x, y]"},
        BadField{{"domain.size_m=[1.0]"}, "domain.size_m", "2 numbers"},
        // missing
        BadField{{"tool.shape=pour"}, "tool.volume_m3", "missing"},
        BadField{{"tool.shape=box"}, "tool.size_m", "missing"},
        BadField{{"terrain.kind=heightmap"}, "terrain.path", "missing"},
        // unknown keys and tables
        BadField{{"tool.radius=0.02"}, "tool.radius", "not a known key"},
        BadField{{"toool.radius_m=0.02"}, "toool.radius_m", "not a known key"},
        BadField{{"tin.cell_m=0.01"}, "tin.cell_m", "not a known key"},
        // keys of the format that these settings do not read
        BadField{{"tool.shape=pour", "tool.volume_m3=1e-6", "tool.profile=sphere_cap"},
                 "tool.profile",
                 "does not apply with this scene's terrain.kind, tool.shape or tool.profile"},
        BadField{{"terrain.amplitude_m=0.01"}, "terrain.amplitude_m", "does not apply"},
        BadField{{"tool.sphere_radius_m=0.05"}, "tool.sphere_radius_m", "does not apply"},
        // inconsistent
        BadField{{"stroke.z_m=[0.1]"}, "stroke.z_m", "one per waypoint"},
        BadField{
            {"tool.shape=polygon", "tool.polygon_m=[[0,0],[1,1],[1,0],[0,1]]"}, "tool.polygon_m", "simple polygon"},
        BadField{{"stroke.spacing_m=1e-9"}, "stroke.spacing_m", "1e7 stamps"}));

TEST(Scene, MissingRequiredFieldsAreNamed) {
  EXPECT_NE(error_of("[stroke]\npath_m = [[0.0, 0.0]]\n").find("domain.size_m is missing"), std::string::npos);
  EXPECT_NE(error_of("[domain]\nsize_m = [1.0, 1.0]\n").find("stroke.path_m is missing"), std::string::npos);
}

TEST(Scene, InvalidTomlNamesLineAndColumn) {
  const std::string msg = error_of("[domain\nsize_m = 1\n");
  EXPECT_NE(msg.find("test:1:"), std::string::npos) << msg;
}

TEST(Scene, BadOverrideSyntax) {
  EXPECT_NE(error_of(kMinimal, {"tool.radius_m"}).find("key=value"), std::string::npos);
  EXPECT_NE(error_of(kMinimal, {"stroke.path_m.x=1"}).find("not a table"), std::string::npos);
}

TEST(HeightField, DunesAreSeededAndDeterministic) {
  const std::string text = std::string(kMinimal) + "[terrain]\nkind = \"dunes\"\nseed = 3\n";
  const HeightField a = HeightField::from_scene(parse_scene(text, "a"));
  const HeightField b = HeightField::from_scene(parse_scene(text, "b"));
  const HeightField c = HeightField::from_scene(parse_scene(text, "c", {"terrain.seed=4"}));
  double differs = 0.0, lo = 1e9, hi = -1e9;
  for (double x = 0.0; x <= 1.0; x += 0.05)
    for (double y = 0.0; y <= 1.0; y += 0.05) {
      EXPECT_EQ(a({x, y}), b({x, y}));
      differs += std::abs(a({x, y}) - c({x, y}));
      lo = std::min(lo, a({x, y}));
      hi = std::max(hi, a({x, y}));
    }
  EXPECT_GT(differs, 0.0);
  EXPECT_GE(lo, 0.1 - 1e-12);         // base height
  EXPECT_LE(hi, 0.1 + 0.02 + 1e-12);  // base + amplitude
  EXPECT_GT(hi - lo, 0.005);
}

TEST(HeightField, HeightmapFromSixteenBitPng) {
  const auto dir = std::filesystem::temp_directory_path() / "sb_heightmap_test";
  std::filesystem::create_directories(dir);
  Png16 img;
  img.width = 3;
  img.height = 2;
  img.values = {0, 0, 0, 65535, 65535, 65535};  // top row 0, bottom row 65535
  write_png16(dir / "hm.png", img);
  const std::string text =
      std::string(kMinimal) +
      "[terrain]\nkind = \"heightmap\"\npath = \"hm.png\"\nheight_m = 0.1\nvertical_scale_m = 0.2\n";
  const Scene s = parse_scene(text, "hm", {}, dir);
  const HeightField f = HeightField::from_scene(s);
  EXPECT_NEAR(f({0.5, 0.0}), 0.3, 1e-12);  // bottom row of the image is y = origin
  EXPECT_NEAR(f({0.5, 1.0}), 0.1, 1e-12);
  EXPECT_NEAR(f({0.5, 0.5}), 0.2, 1e-12);

  std::ofstream(dir / "not.png") << "hello";
  const Scene bad =
      parse_scene(std::string(kMinimal) + "[terrain]\nkind = \"heightmap\"\npath = \"not.png\"\n", "x", {}, dir);
  try {
    HeightField::from_scene(bad);
    FAIL() << "accepted a non-PNG";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("terrain.path"), std::string::npos);
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace sb
