// Nothing silent: run files of the wrong shape, range or size, replay files with a second
// or backwards stamp table, outputs that cannot be created, runs too large for the memory
// they may use, and a TIN that grows past its estimate: each is exit 2 (or an InputError)
// naming the input, before anything is written.
#include <gtest/gtest.h>
#include <hdf5.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "common/input_error.hpp"
#include "harness/io/session_file.hpp"
#include "harness/run/backends.hpp"
#include "harness/run/preflight.hpp"
#include "harness/run/runner.hpp"
#include "harness_test_support.hpp"

namespace {

namespace fs = std::filesystem;
using sb::test::CliResult;
using sb::test::sandbench;
using sb::test::shipped_scene;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// Replaces `name` in the HDF5 file by a dataset of `dims` of `type` holding `data` (nullptr:
// nothing written, chunked and compressed, so that a huge declared size costs no disk).
void replace_dataset(const fs::path& file, const std::string& name, hid_t type, const std::vector<hsize_t>& dims,
                     const void* data) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  // Keep the attributes of a raster (origin_m, spacing_m).
  std::vector<double> origin(2), spacing(1);
  const bool raster = name.find("raster") != std::string::npos;
  if (raster) {
    const hid_t d = H5Dopen2(f, name.c_str(), H5P_DEFAULT);
    const hid_t a = H5Aopen(d, "origin_m", H5P_DEFAULT), b = H5Aopen(d, "spacing_m", H5P_DEFAULT);
    H5Aread(a, H5T_NATIVE_DOUBLE, origin.data());
    H5Aread(b, H5T_NATIVE_DOUBLE, spacing.data());
    H5Aclose(a);
    H5Aclose(b);
    H5Dclose(d);
  }
  ASSERT_GE(H5Ldelete(f, name.c_str(), H5P_DEFAULT), 0);
  const hid_t space = H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr);
  const hid_t plist = H5Pcreate(H5P_DATASET_CREATE);
  if (!data) {
    std::vector<hsize_t> chunk(dims.size(), 1);
    chunk.back() = std::min<hsize_t>(dims.back(), 1024);
    H5Pset_chunk(plist, static_cast<int>(chunk.size()), chunk.data());
    H5Pset_deflate(plist, 9);
  }
  const hid_t d = H5Dcreate2(f, name.c_str(), type, space, H5P_DEFAULT, plist, H5P_DEFAULT);
  ASSERT_GE(d, 0);
  if (data) {
    EXPECT_GE(H5Dwrite(d, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), 0);
  }
  if (raster) {
    const hsize_t two = 2;
    const hid_t s2 = H5Screate_simple(1, &two, nullptr), s1 = H5Screate(H5S_SCALAR);
    const hid_t a = H5Acreate2(d, "origin_m", H5T_NATIVE_DOUBLE, s2, H5P_DEFAULT, H5P_DEFAULT);
    const hid_t b = H5Acreate2(d, "spacing_m", H5T_NATIVE_DOUBLE, s1, H5P_DEFAULT, H5P_DEFAULT);
    H5Awrite(a, H5T_NATIVE_DOUBLE, origin.data());
    H5Awrite(b, H5T_NATIVE_DOUBLE, spacing.data());
    H5Aclose(a);
    H5Aclose(b);
    H5Sclose(s2);
    H5Sclose(s1);
  }
  H5Dclose(d);
  H5Pclose(plist);
  H5Sclose(space);
  H5Fclose(f);
}

// Overwrites a raster's double attribute.
void set_attribute(const fs::path& file, const std::string& dataset, const std::string& name,
                   const std::vector<double>& values) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  const hid_t d = H5Dopen2(f, dataset.c_str(), H5P_DEFAULT);
  const hid_t a = H5Aopen(d, name.c_str(), H5P_DEFAULT);
  EXPECT_GE(H5Awrite(a, H5T_NATIVE_DOUBLE, values.data()), 0);
  H5Aclose(a);
  H5Dclose(d);
  H5Fclose(f);
}

class StrictInputs : public sb::test::TempDirTest {
 protected:
  StrictInputs() : TempDirTest("sb_strict_") {}

  // A one-stamp grid run (the crater) into dir_/NAME.
  fs::path run_file(const std::string& name) {
    const fs::path out = dir_ / name;
    const CliResult r = sandbench("run " + shipped_scene("crater.toml") + " --backend grid --out " + out.string());
    EXPECT_EQ(r.code, 0) << r.out;
    return out;
  }

  // Export and render of `run` both exit 2 with a message holding `part`, writing nothing.
  void refused(const fs::path& run, const std::string& part) {
    for (const std::string& cmd : {"export " + run.string() + " --format ply -o " + (dir_ / "out.ply").string(),
                                   "export " + run.string() + " --format png16 -o " + (dir_ / "out.png").string(),
                                   "render " + run.string() + " -o " + (dir_ / "pic.png").string()}) {
      const CliResult r = sandbench(cmd);
      EXPECT_EQ(r.code, 2) << cmd << "\n" << r.out;
      EXPECT_TRUE(contains(r.out, part)) << cmd << "\n" << r.out;
    }
    EXPECT_FALSE(fs::exists(dir_ / "out.ply") || fs::exists(dir_ / "out.png") || fs::exists(dir_ / "pic.png"));
  }
};

TEST_F(StrictInputs, TrianglesOfTwoColumnsAndNegativeIndicesAreRefused) {
  const fs::path two = run_file("two.h5");
  const std::vector<std::uint32_t> pairs{0, 1, 1, 2, 2, 0};
  replace_dataset(two, "/final/mesh/triangles", H5T_NATIVE_UINT32, {3, 2}, pairs.data());
  refused(two, "/final/mesh/triangles must be a n x 3 (vertex indices) dataset (it has 2 columns)");

  const fs::path negative = run_file("negative.h5");
  const std::vector<std::int64_t> tri{0, 1, -1};
  replace_dataset(negative, "/final/mesh/triangles", H5T_STD_I64LE, {1, 3}, tri.data());
  refused(negative, "/final/mesh/triangles: row 0 names vertex -1, not one of the");

  const fs::path floats = run_file("floats.h5");
  const std::vector<double> ftri{0.0, 1.0, 2.5};
  replace_dataset(floats, "/final/mesh/constrained_edges", H5T_NATIVE_DOUBLE, {1, 3}, ftri.data());
  refused(floats, "/final/mesh/constrained_edges must hold integers");
}

TEST_F(StrictInputs, RasterMagnitudesSpacingAndOriginMustBeSane) {
  const fs::path big = run_file("big.h5");
  std::vector<double> values(4, 0.1);
  values[3] = 1e308;
  replace_dataset(big, "/final/raster", H5T_NATIVE_DOUBLE, {2, 2}, values.data());
  replace_dataset(big, "/initial/raster", H5T_NATIVE_DOUBLE, {2, 2}, std::vector<double>(4, 0.1).data());
  refused(big, "/final/raster: value at row 1, column 1 = 1e+308 is not a finite height");

  const fs::path tiny = run_file("tiny.h5");
  set_attribute(tiny, "/final/raster", "spacing_m", {1e-300});
  refused(tiny, "/final/raster: attribute spacing_m = 1e-300 must be one number in [1e-09, 1e7] m");

  const fs::path far = run_file("far.h5");
  set_attribute(far, "/initial/raster", "origin_m", {1e300, 0.0});
  refused(far, "/initial/raster: attribute origin_m must be 2 finite numbers within (-1e10, 1e10) m");
}

TEST_F(StrictInputs, OneByOneHugeAndMismatchedRastersAreRefusedByName) {
  const fs::path one = run_file("one.h5");
  const double v = 0.1;
  replace_dataset(one, "/initial/raster", H5T_NATIVE_DOUBLE, {1, 1}, &v);
  replace_dataset(one, "/final/raster", H5T_NATIVE_DOUBLE, {1, 1}, &v);
  refused(one, "/initial/raster has 1 x 1 values; a raster has at least 2 x 2");

  // 20000 x 20000 declared in a file of kilobytes: refused before any of it is read.
  const fs::path huge = run_file("huge.h5");
  replace_dataset(huge, "/final/raster", H5T_NATIVE_DOUBLE, {20000, 20000}, nullptr);
  EXPECT_LT(fs::file_size(huge), 10u << 20);
  refused(huge, "/final/raster declares 400000000 values, more than a run writes (at most 100000000)");

  const fs::path other = run_file("other.h5");
  replace_dataset(other, "/final/raster", H5T_NATIVE_DOUBLE, {3, 3}, std::vector<double>(9, 0.1).data());
  refused(other, "/final/raster (3 x 3) is not on the lattice of /initial/raster");
}

TEST_F(StrictInputs, AnOutputInAPseudoFileSystemSaysSo) {
  const fs::path run = run_file("run.h5");
  const CliResult r = sandbench("export " + run.string() + " --format ply -o /proc/version");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_TRUE(contains(r.out, "cannot create files in directory /proc (of /proc/version)")) << r.out;
  EXPECT_FALSE(contains(r.out, "No such file or directory")) << r.out;
}

TEST_F(StrictInputs, ASessionWithASecondOrBackwardsStampTableIsRefused) {
  const std::string tools =
      "tool,shape,radius_m,size_x_m,size_y_m,sides,profile,sphere_radius_m,depth_m,rim_width_m,rim_forward_bias,"
      "pour_volume_m3,polygon_m\n0,disk,0.02,0.04,0.02,32,flat,0.05,0.01,0.01,0.8,0,\n";
  const std::string header = "stamp,t,x,y,bottom_z,heading_rad,dir_x,dir_y,tool\n";
  auto error = [&](const std::string& text) {
    std::ofstream(dir_ / "s.csv") << text;
    try {
      sb::read_session(dir_ / "s.csv", "--replay");
    } catch (const sb::InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string row0 = "0,0.5,0.1,0.1,0.05,0,1,0,0\n", row1 = "1,0.25,0.1,0.1,0.05,0,1,0,0\n";
  EXPECT_TRUE(contains(error(tools + header + row0 + row1), "column t = 0.25 goes back in time (previous row: 0.5)"));
  EXPECT_TRUE(contains(error(tools + header + row0 + header + "0,0.75,0.1,0.1,0.05,0,1,0,0\n"),
                       "a second table with the header stamp,t,x,y"));
  EXPECT_TRUE(contains(error(tools + header + "3,0.5,0.1,0.1,0.05,0,1,0,0\n"), "column stamp must count 0, 1, 2"));
  EXPECT_TRUE(contains(error(tools + header + "0,0.5,0x1p-3,0.1,0.05,0,1,0,0\n"), "column x = '0x1p-3'"));
  EXPECT_EQ(error(tools + header + row0 + "1,0.75,0.1,0.1,0.05,0,1,0,0\n"), "");
}

// --- the resource pre-flight --------------------------------------------------------------

TEST_F(StrictInputs, ARunLargerThanMaxMemoryIsRefusedUpFrontNamingTheKeys) {
  // 9e8 grid nodes: about 9 GB for the dense grid; refused in well under a second.
  CliResult r =
      sandbench("run " + shipped_scene("pile.toml") + " --backend grid --set grid.cell_m=1e-5 --max-memory 4G" +
                " --out " + (dir_ / "a.h5").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_TRUE(contains(r.out, "more than --max-memory (4.00 GiB)")) << r.out;
  EXPECT_TRUE(contains(r.out, "grid.cell_m, domain.size_m: [grid] grid nodes, 9e+08")) << r.out;
  // The TIN refined to its floor over a tilted plane (the whole domain moves).
  r = sandbench("run " + shipped_scene("plane.toml") + " --backend tin --set tin.refine_m=1e-9 --max-memory 1G --out " +
                (dir_ / "b.h5").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_TRUE(contains(r.out, "tin.refine_m: [tin] TIN vertices refined over the disturbed area")) << r.out;
  // compare adds up the back-ends it keeps.
  r = sandbench("compare " + shipped_scene("pile.toml") + " --backends grid,sparse --set grid.cell_m=1e-4" +
                " --max-memory 50M");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_TRUE(contains(r.out, "[grid] grid nodes")) << r.out;
  EXPECT_FALSE(fs::exists(dir_ / "a.h5") || fs::exists(dir_ / "b.h5"));
  // A bad limit is the option's error.
  r = sandbench("run " + shipped_scene("crater.toml") + " --backend grid --max-memory 0x10 --out " +
                (dir_ / "c.h5").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_TRUE(contains(r.out, "--max-memory")) << r.out;
}

TEST_F(StrictInputs, InteractiveRefusesAModelLargerThanMaxMemoryBeforeAnyWindow) {
  // The same pre-flight as `run`, before the model (and the window, or even the display, is
  // looked for): the display variables are unset, so only the pre-flight can give this answer.
  const std::string interactive = "env -u DISPLAY -u WAYLAND_DISPLAY " + std::string(SB_CLI_PATH) + " interactive ";
  CliResult r = sb::test::run_shell(interactive + shipped_scene("pile.toml") +
                                    " --backend grid --set grid.cell_m=1e-5 --max-memory 4G --frames 1 2>&1");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_TRUE(contains(r.out, "more than --max-memory (4.00 GiB)")) << r.out;
  EXPECT_TRUE(contains(r.out, "grid.cell_m, domain.size_m: [grid] grid nodes, 9e+08")) << r.out;
  // The device may take the tool anywhere: a TIN counts its refinement over the whole domain.
  r = sb::test::run_shell(interactive + shipped_scene("flat_stroke.toml") +
                          " --backend tin --set tin.refine_m=1e-6 --max-memory 1G --frames 1 2>&1");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_TRUE(contains(r.out, "tin.refine_m: [tin] TIN vertices refined over the disturbed area")) << r.out;
  // Within the limit, the next check speaks (no display), and a bad limit is the option's error.
  r = sb::test::run_shell(interactive + shipped_scene("pile.toml") + " --backend grid --max-memory 4G --frames 1 2>&1");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_TRUE(contains(r.out, "xvfb-run")) << r.out;
  r = sb::test::run_shell(interactive + shipped_scene("pile.toml") + " --backend grid --max-memory 1X --frames 1 2>&1");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_TRUE(contains(r.out, "--max-memory")) << r.out;
}

TEST_F(StrictInputs, AHugeHeightmapIsRefusedNamingTerrainPath) {
  // A valid 20000 x 20000 16-bit PNG of zeros (about 800 kB), written row by row.
  const fs::path png = dir_ / "huge.png";
  const CliResult made = sb::test::run_shell(
      "/usr/bin/python3 -c \"\nimport struct, zlib\n"
      "def chunk(t, d): return struct.pack('>I', len(d)) + t + d + struct.pack('>I', zlib.crc32(t + d) & 0xffffffff)\n"
      "w = h = 20000\nz = zlib.compressobj(9)\nrow = bytes(1 + 2 * w)\n"
      "data = b''.join(z.compress(row) for _ in range(h)) + z.flush()\n"
      "open('" +
      png.string() +
      "', 'wb').write(b'\\x89PNG\\r\\n\\x1a\\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', w, h, 16, 0, "
      "0, 0, 0)) + chunk(b'IDAT', data) + chunk(b'IEND', b''))\n\" 2>&1");
  ASSERT_EQ(made.code, 0) << made.out;
  std::ofstream(dir_ / "scene.toml") << "[domain]\nsize_m = [1.0, 1.0]\n[terrain]\nkind = \"heightmap\"\n"
                                     << "path = \"huge.png\"\n[stroke]\npath_m = [[0.5, 0.5]]\n";
  const CliResult r = sandbench("run " + (dir_ / "scene.toml").string() + " --backend grid --max-memory 2G --out " +
                                (dir_ / "a.h5").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_TRUE(contains(r.out, "terrain.path: heightmap pixels (20000 x 20000), 4e+08")) << r.out;
}

TEST(Preflight, EstimatesNameTheirKeysAndLargeRunsWarn) {
  const sb::Scene s = sb::load_scene(shipped_scene("pile.toml"), {"grid.cell_m=1e-4"});
  const sb::ResourceEstimate e = sb::estimate_resources({{"grid", s}}, 20, false);
  ASSERT_NE(e.largest(), nullptr);
  EXPECT_EQ(e.largest()->keys, "grid.cell_m, domain.size_m");
  EXPECT_EQ(e.largest()->elements, 3001.0 * 3001.0);
  // compare keeps every back-end's model: both are counted.
  const sb::ResourceEstimate two = sb::estimate_resources({{"grid", s}, {"sparse", s}}, 20, false);
  EXPECT_GT(two.bytes(), e.bytes() + 0.39 * 3001.0 * 3001.0);
  EXPECT_NEAR(e.largest()->bytes, 3001.0 * 3001.0 * 10.0, 1.0);
  EXPECT_THROW(sb::preflight(e, std::uint64_t{1} << 20), sb::InputError);
  EXPECT_EQ(sb::preflight(e, std::uint64_t{1} << 40), std::uint64_t{1} << 40);
  EXPECT_TRUE(contains(sb::out_of_memory_context(), "grid.cell_m, domain.size_m")) << sb::out_of_memory_context();
  EXPECT_NO_THROW(sb::preflight(e, std::uint64_t{1} << 40));
  EXPECT_EQ(sb::parse_memory_size("1.5G"), std::uint64_t{3} << 29);
  EXPECT_EQ(sb::parse_memory_size("4096"), 4096u);
  for (const char* bad : {"", "G", "-1G", "0", "1X", "0x10", "inf", " 1G", "1 G"})
    EXPECT_FALSE(sb::parse_memory_size(bad).has_value()) << bad;
}

TEST(Preflight, ATinThatGrowsPastItsAllowanceStopsWithAMessage) {
  const sb::Scene s = sb::load_scene(shipped_scene("trench.toml"), {});
  sb::PreparedScene p = sb::prepare_scene(s);
  p.max_added_vertices = 10;
  p.vertex_bound_reason = "a test's bound";
  auto terrain = sb::make_terrain("tin", p.scene, p.initial);
  try {
    sb::run_schedule(*terrain, p);
    FAIL() << "the run did not stop";
  } catch (const sb::InputError& e) {
    EXPECT_TRUE(contains(e.what(), "past the 10 it may add by the pre-flight's estimate (a test's bound)")) << e.what();
  }
  // The real allowance is far above what the shipped trench needs.
  EXPECT_GT(sb::tin_vertex_allowance(s, p.schedule.stamps.size(), false, 0), 200000u);
  // And never more than the memory limit holds (290 bytes a vertex).
  EXPECT_EQ(sb::tin_vertex_allowance(s, p.schedule.stamps.size(), false, 290000), 1000u);
}

}  // namespace
