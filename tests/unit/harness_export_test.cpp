// Exports: PLY and OBJ read back with the same vertices, faces and constrained edges; a
// PNG16 heightmap reloads as a scene heightmap within one quantisation step; `sandbench
// export` refuses bad input with exit code 2 and leaves nothing behind.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <string>

#include "common/height_field.hpp"
#include "common/input_error.hpp"
#include "common/scene.hpp"
#include "harness/io/export.hpp"
#include "harness/render/mesh.hpp"
#include "harness_test_support.hpp"

namespace sb {
namespace {

namespace fs = std::filesystem;

using test::slurp;

class Export : public test::TempDirTest {
 protected:
  Export() : TempDirTest("sb_export_") {}
  void SetUp() override {
    TempDirTest::SetUp();
    // A small TIN-like mesh: a raster's lattice with two triangles turned clockwise, and
    // constrained edges along one row.
    raster_ = Raster::covering({Vec2(0.1, 0.2), Vec2(0.3, 0.35)}, 0.01);
    for (std::size_t iy = 0; iy < raster_.ny; ++iy)
      for (std::size_t ix = 0; ix < raster_.nx; ++ix) {
        const Vec2 p = raster_.point(ix, iy);
        raster_.at(ix, iy) = 0.1 + 0.01 * std::sin(40 * p.x()) * std::cos(30 * p.y()) - 0.004 * (ix == 7);
      }
    mesh_ = mesh_from_raster(raster_);
    std::swap(mesh_.triangles[3][1], mesh_.triangles[3][2]);
    std::swap(mesh_.triangles[10][0], mesh_.triangles[10][1]);
    for (std::uint32_t ix = 0; ix + 1 < raster_.nx; ++ix) mesh_.constrained_edges.push_back({ix + 21, ix + 22});
  }
  Raster raster_;
  SurfaceMesh mesh_;
};

struct Ply {
  std::vector<std::string> header;
  std::vector<std::array<double, 3>> vertices;  // double: UTM-sized coordinates survive exactly
  std::vector<std::array<std::int32_t, 3>> faces;
  std::vector<std::array<std::int32_t, 2>> edges;
  std::vector<std::uint8_t> constrained;
};

// Reads exactly the layout export_ply writes, checking the header on the way.
Ply read_ply(const fs::path& file) {
  const std::string data = slurp(file);
  Ply ply;
  std::size_t pos = 0;
  std::size_t nv = 0, nf = 0, ne = 0;
  while (true) {
    const std::size_t end = data.find('\n', pos);
    if (end == std::string::npos) throw std::runtime_error("no end_header");
    const std::string line = data.substr(pos, end - pos);
    pos = end + 1;
    ply.header.push_back(line);
    std::istringstream in(line);
    std::string word, what;
    in >> word;
    if (word == "element") {
      std::size_t n = 0;
      in >> what >> n;
      (what == "vertex" ? nv : what == "face" ? nf : ne) = n;
    }
    if (line == "end_header") break;
  }
  auto get = [&](auto& v) {
    if (pos + sizeof v > data.size()) throw std::runtime_error("PLY body too short");
    std::memcpy(&v, data.data() + pos, sizeof v);
    pos += sizeof v;
  };
  ply.vertices.resize(nv);
  for (auto& v : ply.vertices) get(v);
  for (std::size_t i = 0; i < nf; ++i) {
    std::uint8_t n = 0;
    get(n);
    if (n != 3) throw std::runtime_error("face is not a triangle");
    std::array<std::int32_t, 3> f{};
    get(f);
    ply.faces.push_back(f);
  }
  for (std::size_t i = 0; i < ne; ++i) {
    std::array<std::int32_t, 2> e{};
    std::uint8_t c = 0;
    get(e);
    get(c);
    ply.edges.push_back(e);
    ply.constrained.push_back(c);
  }
  if (pos != data.size()) throw std::runtime_error("PLY body has trailing bytes");
  return ply;
}

std::set<std::pair<int, int>> undirected_edges(const std::vector<std::array<std::uint32_t, 3>>& triangles) {
  std::set<std::pair<int, int>> out;
  for (const auto& t : triangles)
    for (int k = 0; k < 3; ++k)
      out.insert({static_cast<int>(std::min(t[k], t[(k + 1) % 3])), static_cast<int>(std::max(t[k], t[(k + 1) % 3]))});
  return out;
}

TEST_F(Export, PlyReadsBackWithTheSameVerticesFacesAndConstrainedEdges) {
  const fs::path file = dir_ / "mesh.ply";
  export_ply(file, mesh_, {"backend test", "line\nbreak"});
  const Ply ply = read_ply(file);
  EXPECT_EQ(ply.header[0], "ply");
  EXPECT_EQ(ply.header[1], "format binary_little_endian 1.0");
  EXPECT_NE(std::find(ply.header.begin(), ply.header.end(), "comment line break"), ply.header.end());
  ASSERT_EQ(ply.vertices.size(), mesh_.vertices.size());
  ASSERT_EQ(ply.faces.size(), mesh_.triangles.size());
  for (std::size_t i = 0; i < ply.vertices.size(); ++i)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(ply.vertices[i][k], mesh_.vertices[i][k]);
  for (std::size_t i = 0; i < ply.faces.size(); ++i) {
    std::multiset<int> got(ply.faces[i].begin(), ply.faces[i].end());
    std::multiset<int> want(mesh_.triangles[i].begin(), mesh_.triangles[i].end());
    EXPECT_EQ(got, want);
    // Every face counter-clockwise seen from above, including the two turned ones.
    const auto& a = ply.vertices[ply.faces[i][0]];
    const auto& b = ply.vertices[ply.faces[i][1]];
    const auto& c = ply.vertices[ply.faces[i][2]];
    EXPECT_GT((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]), 0.0f) << i;
  }
  const auto unique = undirected_edges(mesh_.triangles);
  ASSERT_EQ(ply.edges.size(), unique.size());
  std::size_t flagged = 0;
  for (std::size_t i = 0; i < ply.edges.size(); ++i) {
    EXPECT_TRUE(unique.count({ply.edges[i][0], ply.edges[i][1]}));
    if (ply.constrained[i]) {
      ++flagged;
      EXPECT_EQ(ply.edges[i][1], ply.edges[i][0] + 1);
      EXPECT_GE(ply.edges[i][0], 21);
    }
  }
  EXPECT_EQ(flagged, mesh_.constrained_edges.size());
}

TEST_F(Export, ObjReadsBackWithTheSameVerticesFacesAndConstrainedEdges) {
  const fs::path file = dir_ / "mesh.obj";
  export_obj(file, mesh_, {"backend test"});
  std::ifstream in(file);
  std::vector<Vec3> v;
  std::vector<std::array<int, 3>> f;
  std::vector<std::array<int, 2>> l;
  for (std::string line; std::getline(in, line);) {
    std::istringstream s(line);
    std::string kind;
    s >> kind;
    if (kind == "v") {
      double x, y, z;
      s >> x >> y >> z;
      v.emplace_back(x, y, z);
    } else if (kind == "f") {
      std::array<int, 3> t{};
      s >> t[0] >> t[1] >> t[2];
      f.push_back(t);
    } else if (kind == "l") {
      std::array<int, 2> e{};
      s >> e[0] >> e[1];
      l.push_back(e);
    }
  }
  ASSERT_EQ(v.size(), mesh_.vertices.size());
  ASSERT_EQ(f.size(), mesh_.triangles.size());
  ASSERT_EQ(l.size(), mesh_.constrained_edges.size());
  for (std::size_t i = 0; i < v.size(); ++i) EXPECT_EQ(v[i], mesh_.vertices[i]);  // shortest round-trip digits
  for (std::size_t i = 0; i < f.size(); ++i) {
    std::multiset<int> got(f[i].begin(), f[i].end());
    std::multiset<int> want;
    for (auto k : mesh_.triangles[i]) want.insert(static_cast<int>(k) + 1);
    EXPECT_EQ(got, want);
  }
  EXPECT_EQ(l.front()[0], 22);
}

TEST_F(Export, Png16ReloadsAsAHeightmapWithinOneQuantisationStep) {
  const fs::path file = dir_ / "height.png";
  const HeightmapKeys k = export_png16(file, raster_, "test");
  EXPECT_NEAR(k.size_m.x(), 0.2, 1e-12);
  EXPECT_NEAR(k.size_m.y(), 0.15, 1e-12);
  EXPECT_GT(k.step_m(), 0.0);
  // The keys travel with the file: text chunks and the GDAL sidecar.
  const std::string bytes = slurp(file);
  EXPECT_NE(bytes.find("sandbench.scene"), std::string::npos);
  EXPECT_NE(bytes.find("vertical_scale_m = "), std::string::npos);
  EXPECT_NE(slurp(dir_ / "height.png.aux.xml").find("<GeoTransform>"), std::string::npos);

  const std::string scene_text = heightmap_scene_snippet(k, "height.png") + "\n[stroke]\npath_m = [[0.2, 0.3]]\n";
  const Scene scene = parse_scene(scene_text, "reload.toml", {}, dir_);
  const HeightField field = HeightField::from_scene(scene);
  double worst = 0.0;
  for (std::size_t iy = 0; iy < raster_.ny; ++iy)
    for (std::size_t ix = 0; ix < raster_.nx; ++ix)
      worst = std::max(worst, std::abs(field(raster_.point(ix, iy)) - raster_.at(ix, iy)));
  EXPECT_LE(worst, k.step_m());
  EXPECT_GT(worst, 0.0);  // it was quantised
  // The trench at column 7 is where it was, not mirrored.
  EXPECT_NEAR(field(raster_.point(7, 3)), raster_.at(7, 3), k.step_m());
}

TEST_F(Export, LevelRasterStillExportsAValidHeightmap) {
  Raster level = Raster::covering({Vec2(0, 0), Vec2(0.1, 0.1)}, 0.01);
  std::fill(level.values.begin(), level.values.end(), 0.1);
  const HeightmapKeys k = export_png16(dir_ / "level.png", level, "test");
  EXPECT_GT(k.vertical_scale_m, 0.0);
  const Png16 png = read_png16(dir_ / "level.png", "test");
  for (auto v : png.values) EXPECT_EQ(v, 0);
}

TEST(ExportFormat, OnlyThreeFormatsAreAccepted) {
  EXPECT_EQ(export_formats().at("ply"), ExportFormat::Ply);
  EXPECT_EQ(export_formats().at("obj"), ExportFormat::Obj);
  EXPECT_EQ(export_formats().at("png16"), ExportFormat::Png16);
  EXPECT_EQ(export_formats().count("stl"), 0u);
}

using test::sandbench;  // the binary as a process (harness_test_support.hpp)

TEST_F(Export, CommandWritesEachFormatAndRefusesBadInput) {
  const fs::path run = dir_ / "grid.h5";
  auto r = sandbench("run " + test::shipped_scene("flat_stroke.toml") + " --backend grid --out " + run.string());
  ASSERT_EQ(r.code, 0) << r.out;
  for (const char* format : {"ply", "obj", "png16"}) {
    const fs::path out = dir_ / (std::string("out.") + format);
    r = sandbench("export " + run.string() + " --format " + format + " -o " + out.string());
    EXPECT_EQ(r.code, 0) << r.out;
    EXPECT_TRUE(fs::exists(out)) << format;
  }
  EXPECT_EQ(slurp(dir_ / "out.ply").substr(0, 4), "ply\n");
  EXPECT_EQ(read_png16(dir_ / "out.png16", "test").width, 283u);  // the common raster, 2.5 mm

  const std::size_t before = static_cast<std::size_t>(std::distance(fs::directory_iterator(dir_), {}));
  r = sandbench("export " + run.string() + " --format stl -o " + (dir_ / "x.stl").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("--format"), std::string::npos) << r.out;
  r = sandbench("export " + (dir_ / "missing.h5").string() + " --format ply -o " + (dir_ / "x.ply").string());
  EXPECT_EQ(r.code, 2) << r.out;
  r = sandbench("export " + run.string() + " --format ply -o " + (dir_ / "none" / "x.ply").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_EQ(sandbench("export " + run.string() + " -o " + (dir_ / "x.ply").string()).code, 2);  // --format required
  EXPECT_EQ(static_cast<std::size_t>(std::distance(fs::directory_iterator(dir_), {})), before);
}

}  // namespace
}  // namespace sb
