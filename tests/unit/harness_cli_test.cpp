// The sandbench command line, run as a process: exit codes, messages, whole-or-nothing output.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "harness_test_support.hpp"

namespace {

namespace fs = std::filesystem;

using sb::test::sandbench;  // the binary as a process (harness_test_support.hpp)

using sb::test::shipped_scene;

class Cli : public sb::test::TempDirTest {
 protected:
  Cli() : TempDirTest("sb_cli_") {}
  bool dir_is_empty() const { return fs::is_empty(dir_); }
};

TEST_F(Cli, BadSceneValueExitsTwoNamesTheFieldAndWritesNothing) {
  const fs::path out = dir_ / "run.h5";
  const auto r = sandbench("run " + shipped_scene("flat_stroke.toml") + " --backend grid --out " + out.string() +
                           " --set tool.radius_m=-3");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("tool.radius_m"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("out of range"), std::string::npos) << r.out;
  EXPECT_TRUE(dir_is_empty());
}

TEST_F(Cli, UnknownKeyInSceneFileExitsTwo) {
  const fs::path bad = dir_ / "bad.toml";
  std::ofstream(bad) << "[domain]\nsize_m = [1.0, 1.0]\nsizee = 2\n[stroke]\npath_m = [[0.5, 0.5]]\n";
  const auto r = sandbench("run " + bad.string() + " --backend grid --out " + (dir_ / "x.h5").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("domain.sizee"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir_ / "x.h5"));
}

TEST_F(Cli, MissingSceneFileAndBadOptionsExitTwo) {
  EXPECT_EQ(sandbench("run " + (dir_ / "none.toml").string() + " --backend grid").code, 2);
  EXPECT_EQ(sandbench("run " + shipped_scene("flat_stroke.toml") + " --backend voxels").code, 2);
  EXPECT_EQ(sandbench("run " + shipped_scene("flat_stroke.toml")).code, 2);  // --backend is required
  EXPECT_EQ(sandbench("frobnicate").code, 2);
  EXPECT_EQ(
      sandbench("compare " + shipped_scene("flat_stroke.toml") + " --backends grid,hex --out " + dir_.string()).code,
      2);
  EXPECT_TRUE(dir_is_empty());
}

TEST_F(Cli, RunPrintsEveryContractMetricAndWritesTheRunFile) {
  const fs::path out = dir_ / "grid.h5";
  const auto r = sandbench("run " + shipped_scene("flat_stroke.toml") + " --backend grid --json --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.out;
  const auto json_start = r.out.find('{');
  const auto json = nlohmann::json::parse(r.out.substr(json_start, r.out.rfind('}') - json_start + 1));
  for (const char* key : {"time_s.tool",  "time_s.erosion",   "time_s.simplify",
                          "time_s.total", "step_ms.p50",      "step_ms.p95",
                          "step_ms.max",  "memory_bytes",     "memory_bytes_peak",
                          "vertices",     "triangles",        "constrained_edges",
                          "cells",        "volume_initial",   "volume_final",
                          "volume_added", "volume_drift_rel", "max_slope_excess_deg",
                          "stamps",       "backend",          "scene"})
    EXPECT_TRUE(json.contains(key)) << key;
  EXPECT_EQ(json["backend"], "grid");
  EXPECT_EQ(json["stamps"], 21);
  EXPECT_LT(std::abs(json["volume_drift_rel"].get<double>()), 1e-9);
  EXPECT_TRUE(fs::exists(out));
}

}  // namespace
