// Trustworthy outputs: user mistakes exit 2 with a message that names them, outputs
// never destroy inputs or special files, damaged run files are refused, warnings reach the
// researcher, exports keep their precision, and a failing disk leaves nothing behind.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "common/scene.hpp"
#include "harness/io/run_file.hpp"
#include "harness/io/session_file.hpp"
#include "harness/run/variant.hpp"
#include "harness_test_support.hpp"

namespace {

namespace fs = std::filesystem;
using sb::test::CliResult;
using sb::test::sandbench;

using sb::test::shipped_scene;
using sb::test::slurp;

// `sh -c SCRIPT`: for environment changes and resource limits. SCRIPT must not hold quotes '.
CliResult run_sh(const std::string& script) { return sb::test::run_shell("sh -c '" + script + "' 2>&1"); }

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

class Outputs : public sb::test::TempDirTest {
 protected:
  Outputs() : TempDirTest("sb_outputs_") {}

  // A grid run of the flat stroke into dir_/NAME.
  fs::path grid_run(const std::string& name = "run.h5", const std::string& extra = "") {
    const fs::path out = dir_ / name;
    const CliResult r =
        sandbench("run " + shipped_scene("flat_stroke.toml") + " --backend grid --out " + out.string() + extra);
    EXPECT_EQ(r.code, 0) << r.out;
    return out;
  }
};

// --- the command line ---------------------------------------------------------------------

TEST_F(Outputs, UnknownCommandsHelpAndVersion) {
  CliResult r = sandbench("frobnicate");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_TRUE(contains(r.out, "unknown command 'frobnicate'")) << r.out;
  EXPECT_TRUE(contains(r.out, "run, compare")) << r.out;
  r = sandbench("");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_TRUE(contains(r.out, "scene-keys")) << r.out;
  r = sandbench("help");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(contains(r.out, "compare")) << r.out;
  r = sandbench("help export");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(contains(r.out, "--format")) << r.out;
  r = sandbench("-V");
  EXPECT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(contains(r.out, "sandbench ")) << r.out;
}

TEST_F(Outputs, WrongFlagsNameTheCommandAndBackEndsComeFromTheFactory) {
  CliResult r = sandbench("run " + shipped_scene("flat_stroke.toml") + " --backend grid --frobnicate");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_TRUE(contains(r.out, "sandbench run: error")) << r.out;
  EXPECT_TRUE(contains(r.out, "--frobnicate")) << r.out;
  r = sandbench("run " + shipped_scene("flat_stroke.toml") + " --backend voxel --out " + (dir_ / "x.h5").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_TRUE(contains(r.out, "--backend: \"voxel\"")) << r.out;  // not --backends
  EXPECT_TRUE(contains(r.out, "tin, grid")) << r.out;
  EXPECT_TRUE(fs::is_empty(dir_));
}

TEST_F(Outputs, InteractiveWithoutADisplaySaysSoWithTheXvfbHint) {
  const CliResult r = run_sh("env -u DISPLAY -u WAYLAND_DISPLAY " + std::string(SB_CLI_PATH) + " interactive " +
                             shipped_scene("flat_stroke.toml") + " --backend grid --frames 1");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_TRUE(contains(r.out, "xvfb-run")) << r.out;
}

// --- outputs that must not destroy anything -----------------------------------------------

TEST_F(Outputs, OutputThatIsTheSceneIsRefusedAndTheSceneSurvives) {
  const fs::path copy = dir_ / "scene.toml";
  fs::copy_file(shipped_scene("flat_stroke.toml"), copy);
  const std::string before = slurp(copy);
  const CliResult r = sandbench("run " + copy.string() + " --backend grid --out " + copy.string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_TRUE(contains(r.out, "is the input")) << r.out;
  EXPECT_EQ(slurp(copy), before);
  // Another spelling of the same file is caught too.
  const CliResult r2 =
      sandbench("run " + copy.string() + " --backend grid --out " + (dir_ / "." / "scene.toml").string());
  EXPECT_EQ(r2.code, 2) << r2.out;
  EXPECT_EQ(slurp(copy), before);
}

TEST_F(Outputs, ExportOverItsOwnRunFileIsRefused) {
  const fs::path run = grid_run();
  const std::string before = slurp(run);
  for (const char* format : {"ply", "obj", "png16"}) {
    const CliResult r = sandbench("export " + run.string() + " --format " + format + " -o " + run.string());
    EXPECT_EQ(r.code, 2) << format << ": " << r.out;
  }
  const CliResult r = sandbench("render " + run.string() + " -o " + run.string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_EQ(slurp(run), before);
}

TEST_F(Outputs, SpecialFilesDirectoriesSymlinksAndEmptyPathsAreRefused) {
  const fs::path fifo = dir_ / "fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const fs::path target = dir_ / "target.h5";
  std::ofstream(target) << "keep";
  fs::create_symlink(target, dir_ / "link.h5");
  fs::create_directories(dir_ / "folder");
  const std::string run = "run " + shipped_scene("flat_stroke.toml") + " --backend grid --out ";
  for (const std::string& out : {fifo.string(), (dir_ / "link.h5").string(), (dir_ / "folder").string(),
                                 std::string("/dev/null"), std::string("''")}) {
    const CliResult r = sandbench(run + out);
    EXPECT_EQ(r.code, 2) << out << ": " << r.out;
    EXPECT_TRUE(contains(r.out, "--out")) << r.out;
  }
  EXPECT_TRUE(fs::is_fifo(fifo));
  EXPECT_TRUE(fs::is_symlink(dir_ / "link.h5"));
  EXPECT_EQ(slurp(target), "keep");
  EXPECT_TRUE(fs::is_character_file("/dev/null"));
  // compare --out must be a directory.
  const CliResult c =
      sandbench("compare " + shipped_scene("flat_stroke.toml") + " --backends grid --out " + target.string());
  EXPECT_EQ(c.code, 2) << c.out;
  EXPECT_EQ(slurp(target), "keep");
}

TEST_F(Outputs, TemporariesOfAKilledRunAreRemovedByTheNextOne) {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ::waitpid(child, nullptr, 0);  // its PID now names no process
  const fs::path stale = dir_ / ("run.h5.tmp" + std::to_string(child));
  std::ofstream(stale) << "half-written";
  grid_run();
  EXPECT_FALSE(fs::exists(stale));
  EXPECT_TRUE(fs::exists(dir_ / "run.h5"));
}

TEST_F(Outputs, DiskFullIsOneCleanLineAndLeavesNothing) {
  // A 64 KiB tmpfs when the test may mount one (CI runs as root), else a file-size limit: both
  // make the run file's write fail half-way.
  const fs::path small = dir_ / "small";
  fs::create_directories(small);
  const bool mounted =
      ::geteuid() == 0 &&
      std::system(("mount -t tmpfs -o size=64k tmpfs " + small.string() + " 2>/dev/null").c_str()) == 0;
  const std::string limit = mounted ? "" : "trap \"\" XFSZ; ulimit -f 64; ";
  const CliResult r = run_sh(limit + std::string(SB_CLI_PATH) + " run " + shipped_scene("flat_stroke.toml") +
                             " --backend tin --out " + (small / "run.h5").string());
  const bool empty = fs::is_empty(small);
  if (mounted) std::system(("umount " + small.string()).c_str());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_TRUE(contains(r.out, "cannot write the run file")) << r.out;
  EXPECT_FALSE(contains(r.out, "HDF5-DIAG")) << r.out;
  EXPECT_FALSE(contains(r.out, "internal error")) << r.out;
  EXPECT_TRUE(empty);
  EXPECT_LE(std::count(r.out.begin(), r.out.end(), '\n'), 4) << r.out;  // summary to stdout is not printed
}

// --- damaged run files --------------------------------------------------------------------

// Rewrites one value of a dataset in a run file.
void poke(const fs::path& file, const char* dataset, hid_t type, const void* value) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  const hid_t d = H5Dopen2(f, dataset, H5P_DEFAULT);
  ASSERT_GE(d, 0);
  const hid_t space = H5Dget_space(d);
  const int rank = H5Sget_simple_extent_ndims(space);
  const hsize_t start[2] = {0, 0}, count[2] = {1, 1};
  H5Sselect_hyperslab(space, H5S_SELECT_SET, start, nullptr, count, nullptr);
  const hsize_t one = 1;
  const hid_t mem = H5Screate_simple(1, &one, nullptr);
  EXPECT_GE(rank, 1);
  EXPECT_GE(H5Dwrite(d, type, mem, space, H5P_DEFAULT, value), 0);
  H5Sclose(mem);
  H5Sclose(space);
  H5Dclose(d);
  H5Fclose(f);
}

TEST_F(Outputs, InfiniteRasterAndBadIndicesAreRefusedByRenderAndExport) {
  const fs::path inf_run = grid_run("inf.h5");
  const double inf = HUGE_VAL;
  poke(inf_run, "/final/raster", H5T_NATIVE_DOUBLE, &inf);
  CliResult r = sandbench("render " + inf_run.string() + " --contours -o " + (dir_ / "a.png").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_TRUE(contains(r.out, "/final/raster")) << r.out;
  r = sandbench("export " + inf_run.string() + " --format png16 -o " + (dir_ / "a16.png").string());
  EXPECT_EQ(r.code, 2) << r.out;

  const fs::path bad_index = grid_run("index.h5");
  const std::uint32_t huge = 4000000000u;
  poke(bad_index, "/final/mesh/triangles", H5T_NATIVE_UINT32, &huge);
  r = sandbench("export " + bad_index.string() + " --format ply -o " + (dir_ / "a.ply").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_TRUE(contains(r.out, "names vertex")) << r.out;
  r = sandbench("render " + bad_index.string() + " -o " + (dir_ / "b.png").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_FALSE(fs::exists(dir_ / "a.png") || fs::exists(dir_ / "a16.png") || fs::exists(dir_ / "a.ply") ||
               fs::exists(dir_ / "b.png"));
}

// --- what the run file holds --------------------------------------------------------------

H5T_class_t dataset_class(hid_t file, const char* name) {
  const hid_t d = H5Dopen2(file, name, H5P_DEFAULT);
  const hid_t t = H5Dget_type(d);
  const H5T_class_t c = H5Tget_class(t);
  H5Tclose(t);
  H5Dclose(d);
  return c;
}

TEST_F(Outputs, RunFileKeepsTypesAndHasNoPlaceholderColumns) {
  const fs::path run = grid_run();
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t f = H5Fopen(run.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  EXPECT_EQ(dataset_class(f, "/steps/stamp"), H5T_INTEGER);
  EXPECT_EQ(dataset_class(f, "/steps/vertices"), H5T_INTEGER);
  EXPECT_EQ(dataset_class(f, "/steps/volume_m3"), H5T_FLOAT);
  EXPECT_LE(H5Lexists(f, "/steps/energy_m4", H5P_DEFAULT), 0);  // output.energy is off
  const hid_t a = H5Aopen_by_name(f, "/summary", "settled", H5P_DEFAULT, H5P_DEFAULT);
  const hid_t at = H5Aget_type(a);
  EXPECT_EQ(H5Tget_class(at), H5T_INTEGER);
  H5Tclose(at);
  H5Aclose(a);
  const hid_t s = H5Dopen2(f, "/scene/text", H5P_DEFAULT);
  const hid_t st = H5Dget_type(s);
  EXPECT_GT(H5Tis_variable_str(st), 0);
  H5Tclose(st);
  H5Dclose(s);
  H5Fclose(f);
}

TEST_F(Outputs, SceneOfMegabytesIsStoredWhole) {
  // A stroke of 10^5 waypoints (a scene of about 3 MB, far over HDF5's 64 KiB attribute limit).
  std::ostringstream text;
  text << "[domain]\nsize_m = [0.5, 0.5]\n[tool]\nradius_m = 0.01\n[stroke]\nspacing_m = 0.004\npath_m = [";
  for (int i = 0; i < 100000; ++i) text << (i ? ", " : "") << "[" << 0.2 + 1e-6 * i << ", 0.25]";
  text << "]\n";
  const fs::path big = dir_ / "big.toml";
  std::ofstream(big) << text.str();
  const fs::path out = dir_ / "big.h5";
  const CliResult r = sandbench("run " + big.string() + " --backend grid --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.out.substr(0, 2000);
  const sb::RunFile back = sb::read_run_file(out);
  EXPECT_EQ(back.attributes.at("scene_text"), text.str());
}

// --- warnings -----------------------------------------------------------------------------

nlohmann::json summary_of(const CliResult& r) {
  const auto start = r.out.find("{\n");
  return nlohmann::json::parse(r.out.substr(start, r.out.rfind('}') - start + 1));
}

TEST_F(Outputs, WarningsOnStderrAndInTheSummary) {
  const std::string base = "run " + shipped_scene("flat_stroke.toml") + " --backend grid --json --out ";
  CliResult r = sandbench(base + (dir_ / "a.h5").string() + " --set 'stroke.path_m=[[5.0, 5.0], [5.1, 5.1]]'");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(contains(r.out, "sandbench: warning")) << r.out;
  EXPECT_TRUE(contains(summary_of(r)["warnings"].dump(), "outside the domain")) << r.out;

  r = sandbench(base + (dir_ / "b.h5").string() + " --set tool.depth_m=0.25");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(contains(summary_of(r)["warnings"].dump(), "below the sand bed")) << r.out;

  r = sandbench(base + (dir_ / "c.h5").string() + " --set erosion.relax_max_passes=0");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_FALSE(summary_of(r)["settled"].get<bool>());
  EXPECT_TRUE(contains(summary_of(r)["warnings"].dump(), "did not settle")) << r.out;

  r = sandbench(base + (dir_ / "d.h5").string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(summary_of(r)["warnings"].empty()) << r.out;
}

TEST_F(Outputs, HopelesslyLongRunsAreRefusedUpFront) {
  // 2.1e6 stamps of a 4096-gon: refused in the scene check, before any allocation.
  const CliResult r = sandbench("run " + shipped_scene("flat_stroke.toml") + " --backend grid --out " +
                                (dir_ / "x.h5").string() + " --set tool.sides=4096 --set stroke.repeat=100000");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_TRUE(contains(r.out, "stroke.spacing_m")) << r.out;
  EXPECT_TRUE(contains(r.out, "tool.sides")) << r.out;
  EXPECT_TRUE(fs::is_empty(dir_));
}

// --- --unset, scene-keys ------------------------------------------------------------------

TEST_F(Outputs, UnsetSwitchesTheToolShape) {
  const std::string base =
      "run " + shipped_scene("flat_stroke.toml") + " --backend grid --out " + (dir_ / "x.h5").string();
  CliResult r = sandbench(base + " --set tool.shape=box --set 'tool.size_m=[0.04, 0.02]'");
  EXPECT_EQ(r.code, 2) << r.out;  // radius_m and sides are not box keys
  r = sandbench(base +
                " --unset tool.radius_m --unset tool.sides --set tool.shape=box --set 'tool.size_m=[0.04, 0.02]'");
  EXPECT_EQ(r.code, 0) << r.out;
}

TEST_F(Outputs, SceneKeysListEveryKeyAndTheReadmeTableMatches) {
  const CliResult r = sandbench("scene-keys");
  ASSERT_EQ(r.code, 0) << r.out;
  const std::string readme = slurp(std::string(SB_SOURCE_DIR) + "/README.md");
  for (const sb::SceneKey& k : sb::scene_keys()) {
    EXPECT_TRUE(contains(r.out, k.key)) << k.key;
    EXPECT_FALSE(k.meaning.empty()) << k.key << " has no meaning in common/scene_keys.cpp";
    // The README's table names each key, in full or (grouped rows) by its last part.
    const std::string leaf = k.key.substr(k.key.find('.') + 1);
    EXPECT_TRUE(contains(readme, "`" + k.key + "`") || contains(readme, "`" + leaf + "`"))
        << k.key << " is missing from the README's scene table";
  }
}

// --- replayed sessions --------------------------------------------------------------------

sb::Session one_stamp_session(double bottom_z) {
  sb::Session s;
  sb::ToolSpec disk;
  disk.radius_m = 0.02;
  disk.depth_m = 0.01;
  s.tools.push_back(disk);
  s.stamps.push_back({0.0, {sb::Vec2(0.35, 0.35), bottom_z, 0.0}, sb::Vec2(1.0, 0.0), 0});
  s.stamps.push_back({0.01, {sb::Vec2(0.36, 0.35), bottom_z, 0.0}, sb::Vec2(1.0, 0.0), 0});
  return s;
}

TEST_F(Outputs, ReplayOutOfRangeIsRefusedAndCompareReplaysOnEveryBackEnd) {
  const fs::path bad = dir_ / "bad.csv";
  sb::write_session(bad, one_stamp_session(-1e300));
  CliResult r = sandbench("run " + shipped_scene("flat_stroke.toml") + " --backend tin --replay " + bad.string() +
                          " --out " + (dir_ / "x.h5").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_TRUE(contains(r.out, "bottom_z")) << r.out;

  sb::Session huge_pour = one_stamp_session(0.09);
  huge_pour.tools[0].shape = sb::ToolShape::Pour;
  huge_pour.tools[0].pour_volume_m3 = 1e300;
  sb::write_session(dir_ / "pour.csv", huge_pour);
  r = sandbench("run " + shipped_scene("flat_stroke.toml") + " --backend grid --replay " +
                (dir_ / "pour.csv").string() + " --out " + (dir_ / "y.h5").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_TRUE(contains(r.out, "tool.volume_m3")) << r.out;

  // A denormal coordinate (as the UDP device can record) replays.
  sb::Session tiny = one_stamp_session(0.09);
  tiny.stamps[0].motion_dir = sb::Vec2(1.0, 5e-324);
  sb::write_session(dir_ / "good.csv", tiny);
  r = sandbench("compare " + shipped_scene("flat_stroke.toml") + " --backends tin,grid --replay " +
                (dir_ / "good.csv").string() + " --json --out " + (dir_ / "cmp").string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(summary_of(r)["stamps"], 2);
  EXPECT_TRUE(fs::exists(dir_ / "cmp" / "side_by_side.png"));
  EXPECT_FALSE(fs::exists(dir_ / "cmp" / "INCOMPLETE"));
}

// --- exports ------------------------------------------------------------------------------

// Reads the vertices of a binary PLY written by export_ply (double x y z).
std::vector<sb::Vec3> ply_vertices(const fs::path& file) {
  const std::string data = slurp(file);
  const auto end = data.find("end_header\n");
  EXPECT_NE(end, std::string::npos);
  EXPECT_TRUE(contains(data.substr(0, end), "property double x"));
  const auto at = data.find("element vertex ");
  const std::size_t n = std::stoul(data.substr(at + 15));
  std::vector<sb::Vec3> v(n);
  const char* p = data.data() + end + 11;
  for (std::size_t i = 0; i < n; ++i) {
    double xyz[3];
    std::memcpy(xyz, p + 24 * i, 24);
    v[i] = sb::Vec3(xyz[0], xyz[1], xyz[2]);
  }
  return v;
}

TEST_F(Outputs, UtmOffsetTinSurvivesPlyExactlyAndTheCrsReachesTheSidecar) {
  const fs::path run = dir_ / "utm.h5";
  const CliResult r = sandbench("run " + shipped_scene("flat_stroke.toml") + " --backend tin --out " + run.string() +
                                " --set 'domain.origin_m=[500000.0, 5000000.0]'" +
                                " --set 'stroke.path_m=[[500000.3182, 5000000.3182], [500000.38891, 5000000.38891]]'" +
                                " --set 'domain.crs=\"EPSG:32633\"'");
  ASSERT_EQ(r.code, 0) << r.out;
  const sb::RunFile back = sb::read_run_file(run);
  ASSERT_GT(back.mesh.vertices.size(), 100u);
  const CliResult e = sandbench("export " + run.string() + " --format ply -o " + (dir_ / "utm.ply").string());
  ASSERT_EQ(e.code, 0) << e.out;
  const std::vector<sb::Vec3> ply = ply_vertices(dir_ / "utm.ply");
  ASSERT_EQ(ply.size(), back.mesh.vertices.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < ply.size(); ++i) worst = std::max(worst, (ply[i] - back.mesh.vertices[i]).norm());
  EXPECT_LE(worst, 1e-9);

  const CliResult g = sandbench("export " + run.string() + " --format png16 -o " + (dir_ / "utm.png").string());
  ASSERT_EQ(g.code, 0) << g.out;
  EXPECT_TRUE(contains(slurp(dir_ / "utm.png.aux.xml"), "<SRS>EPSG:32633</SRS>"));
}

// A TIN of millions of initial points takes long to build, before any stamp: the run says so
// when it starts, with the time and memory to expect; smaller models say nothing.
TEST(BuildNotice, ALargeTinBuildSaysSoWhenItStarts) {
  const std::string text = "[domain]\nsize_m = [1.0, 1.0]\n[stroke]\npath_m = [[0.5, 0.5]]\n";
  const sb::Scene large = sb::parse_scene(text, "test", {"tin.initial_points=4000000"});
  const std::string notice = sb::build_notice("tin", large);
  EXPECT_NE(notice.find("4000000 initial points"), std::string::npos) << notice;
  EXPECT_NE(notice.find("about 11 s and 1.2 GB"), std::string::npos) << notice;
  EXPECT_EQ(sb::build_notice("grid", large), "");
  EXPECT_EQ(sb::build_notice("tin", sb::parse_scene(text, "test", {"tin.initial_points=1000000"})), "");
  EXPECT_EQ(sb::build_notice("tin", sb::parse_scene(text, "test")), "");
}

}  // namespace
