// Inputs are read whole or refused: CSV numbers and indices parsed in full (no trailing bytes,
// no NUL, decimal only), one table per header, strings of a scene without NUL, and tools that
// must fit in the domain where the scene's reference measures them.
#include <gtest/gtest.h>

#include <string>

#include "common/haptics/csv_tables.hpp"
#include "common/haptics/trajectory.hpp"
#include "common/input_error.hpp"
#include "common/reference.hpp"
#include "common/scene.hpp"

namespace sb {
namespace {

using haptics::parse_csv_tables;
using haptics::trajectory_from;
using namespace std::string_literals;

// The InputError message of `fn`, or "" when it does not throw one.
template <typename Fn>
std::string error_of(Fn&& fn) {
  try {
    fn();
  } catch (const InputError& e) {
    return e.what();
  }
  return {};
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

std::string trajectory_error(const std::string& text) {
  return error_of([&] { trajectory_from(parse_csv_tables(text, "t.csv")); });
}

TEST(StrictCsv, DecimalNumbersAreReadWholeAndNothingElse) {
  double v = 0.0;
  for (const char* ok : {"0", "-1.5", "+2", ".5", "5.", "1e-3", "-1.25E+07", "5e-324"}) {
    EXPECT_TRUE(haptics::parse_decimal(ok, v)) << ok;
  }
  EXPECT_TRUE(haptics::parse_decimal("-1.25E+07", v));
  EXPECT_EQ(v, -1.25e7);
  for (const std::string& bad :
       std::vector<std::string>{"", "0x1p3", "0X10", "inf", "-infinity", "nan", "1e", "1e+", ".", "-", "1.0 9", "1,5",
                                " 1", "1 ", "1e400", "--1", "1.2.3", "0.0\0 9"s}) {
    EXPECT_FALSE(haptics::parse_decimal(bad, v)) << bad;
  }
}

TEST(StrictCsv, ANulInsideANumberIsRefusedAndShownEscaped) {
  const std::string text = "t,x,y,z,buttons\n0,0.1,0.1,0.1,0\n1,0.0\0 9,0.1,0.1,0\n"s;
  const std::string e = trajectory_error(text);
  EXPECT_TRUE(contains(e, "t.csv:3: column x")) << e;
  EXPECT_TRUE(contains(e, "\\x00")) << e;
  // In an integer column too (strtoull would stop at the NUL).
  const std::string mask = trajectory_error("t,x,y,z,buttons\n0,0.1,0.1,0.1,1\0\n"s);
  EXPECT_TRUE(contains(mask, "column buttons")) << mask;
}

TEST(StrictCsv, HexFloatsInfinitiesAndSignedIntegersAreRefused) {
  EXPECT_TRUE(contains(trajectory_error("t,x,y,z,buttons\n0,0x1p-3,0.1,0.1,0\n"), "column x")) << "hex float";
  // A row whose first cell is not a number is refused, not taken for another table's header.
  EXPECT_TRUE(contains(trajectory_error("t,x,y,z,buttons\n0,0.1,0.1,0.1,0\ninf,0.1,0.1,0.1,0\n"), "column t"));
  EXPECT_TRUE(contains(trajectory_error("t,x,y,z,buttons\n0,0.1,0.1,0.1,0\nnan,0.1,0.1,0.1,0\n"), "column t"));
  EXPECT_TRUE(contains(trajectory_error("t,x,y,z,buttons\n0,0.1,0.1,0.1,+1\n"), "column buttons"));
}

TEST(StrictCsv, ASecondTableWithTheSameHeaderIsRefused) {
  const std::string e =
      trajectory_error("t,x,y,z,buttons\n0,0.1,0.1,0.1,0\n# more\nt,x,y,z,buttons\n1,0.2,0.1,0.1,0\n");
  EXPECT_TRUE(contains(e, "t.csv:4: a second table with the header t,x,y,z,buttons (the first is at line 1)")) << e;
}

TEST(StrictCsv, TimeGoingBackIsRefusedWithBothRows) {
  const std::string e = trajectory_error("t,x,y,z,buttons\n0.5,0.1,0.1,0.1,0\n0.25,0.1,0.1,0.1,0\n");
  EXPECT_TRUE(contains(e, "t.csv:3: column t = 0.25 goes back in time (previous row: 0.5)")) << e;
}

const char* kScene = R"([domain]
size_m = [0.3, 0.3]
[stroke]
path_m = [[0.15, 0.15]]
)";

std::string scene_error(const std::vector<std::string>& overrides) {
  return error_of([&] { parse_scene(kScene, "s.toml", overrides); });
}

TEST(StrictScene, StringsWithANulAreRefused) {
  const std::string e = scene_error({"terrain.kind=\"heightmap\"", "terrain.path=\"a.png\\u0000b.png\""});
  EXPECT_TRUE(contains(e, "terrain.path must not contain a NUL")) << e;
  EXPECT_TRUE(contains(scene_error({"domain.crs=\"EPSG\\u00004326\""}), "domain.crs must not contain a NUL"));
}

TEST(StrictScene, ToolsThatCannotFitWhereTheReferenceMeasuresAreRefused) {
  // A pour of radius 3 m on a 0.3 m domain: the pile reference would report nonsense.
  std::string e = scene_error({"tool.shape=\"pour\"", "tool.volume_m3=1e-6", "tool.radius_m=3", "reference.kind=pile"});
  EXPECT_TRUE(contains(e, "tool.radius_m gives a tool reaching 3 m")) << e;
  EXPECT_TRUE(contains(e, "reference.kind = \"pile\"")) << e;
  // A crater whose rim band leaves the domain at the stroke's point.
  e = scene_error({"tool.radius_m=0.1", "tool.rim_width_m=0.06", "reference.kind=crater"});
  EXPECT_TRUE(contains(e, "tool.radius_m gives a tool reaching 0.16")) << e;
  // A trench whose middle half runs along the border.
  e = scene_error({"stroke.path_m=[[0.05, 0.01], [0.25, 0.01]]", "reference.kind=trench"});
  EXPECT_TRUE(contains(e, "tool.radius_m")) << e;
  // What fits is accepted.
  EXPECT_EQ(scene_error({"tool.shape=\"pour\"", "tool.volume_m3=1e-6", "tool.radius_m=0.004", "reference.kind=pile"}),
            "");
}

TEST(ResultsThatAreResults, APileThatCannotFitReportsNoNumbersAndSaysWhy) {
  // 1e-3 m^3 at 30 degrees: a cone of radius 0.15 m on a 0.3 m domain around (0.15, 0.15) fits
  // exactly at its edge only; 4e-3 m^3 does not.
  const Scene s = parse_scene(
      kScene, "s.toml", {"tool.shape=\"pour\"", "tool.volume_m3=4e-3", "tool.radius_m=0.004", "reference.kind=pile"});
  const HeightField f = HeightField::from_scene(s);
  const StampSchedule schedule = make_schedule(s.tool, s.stroke, [&](const Vec2& q) { return f(q); });
  const Raster lattice = Raster::covering(s.domain.box(), s.output.raster_m);
  Raster final_raster = lattice;
  for (double& v : final_raster.values) v = 0.1;
  std::vector<std::string> warnings;
  const auto m = accuracy_metrics(s, schedule, f, lattice, final_raster, &warnings);
  EXPECT_EQ(m.value("reference", ""), "pile");
  EXPECT_FALSE(m.contains("pile.radius_m"));
  EXPECT_FALSE(m.contains("pile.flank_angle_deg"));
  EXPECT_FALSE(m.contains("reference.rmse_m"));
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_TRUE(contains(warnings[0], "the pile reference metrics are absent: the pile's expected foot")) << warnings[0];
}

TEST(ResultsThatAreResults, APileCutByTheBorderIsNotMeasured) {
  // The reference fits, but the surface holds a flat-topped mound over the whole raster: its
  // foot is nowhere within the raster, so nothing about it is reported.
  const Scene s = parse_scene(
      kScene, "s.toml", {"tool.shape=\"pour\"", "tool.volume_m3=1e-6", "tool.radius_m=0.004", "reference.kind=pile"});
  const HeightField f = HeightField::from_scene(s);
  const StampSchedule schedule = make_schedule(s.tool, s.stroke, [&](const Vec2& q) { return f(q); });
  const Raster lattice = Raster::covering(s.domain.box(), s.output.raster_m);
  Raster final_raster = lattice;
  for (std::size_t iy = 0; iy < final_raster.ny; ++iy)
    for (std::size_t ix = 0; ix < final_raster.nx; ++ix)
      final_raster.at(ix, iy) = 0.2 - 0.01 * (final_raster.point(ix, iy) - Vec2(0.15, 0.15)).norm();
  std::vector<std::string> warnings;
  const auto m = accuracy_metrics(s, schedule, f, lattice, final_raster, &warnings);
  EXPECT_FALSE(m.contains("pile.radius_m"));
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_TRUE(contains(warnings[0], "no pile was found")) << warnings[0];
}

}  // namespace
}  // namespace sb
