#include <gtest/gtest.h>

#include <filesystem>

#include "common/input_error.hpp"
#include "harness/io/run_file.hpp"

namespace sb {
namespace {

const char* kScene = R"(# a comment that must survive
[domain]
size_m = [0.1, 0.1]
[stroke]
path_m = [[0.05, 0.05]]
)";

TEST(RunFile, RoundTripKeepsStepsRastersMeshAndAttributes) {
  PreparedScene p = prepare_scene(parse_scene(kScene, "scene.toml", {"tool.radius_m=0.01"}));
  RunResult run;
  run.backend = "grid";
  run.label = "grid:grid.storage=float";
  for (int i = 0; i < 3; ++i) {
    StepRecord r;
    r.stamp = i;
    r.time_tool_s = 0.001 * i;
    r.volume_m3 = 1.0 + i;
    r.vertices = 10u + i;
    run.steps.push_back(r);
  }
  run.initial_raster = p.raster_template;
  run.final_raster = p.raster_template;
  for (std::size_t i = 0; i < run.final_raster.values.size(); ++i) run.final_raster.values[i] = 0.001 * i;
  run.final_mesh.vertices = {{0, 0, 1}, {1, 0, 2}, {0, 1, 3}};
  run.final_mesh.triangles = {{0, 1, 2}};
  run.final_mesh.constrained_edges = {{0, 1}};
  Json summary = summarize(run, p);

  const auto path = std::filesystem::temp_directory_path() / "sb_run_file_test.h5";
  write_run_file(path, run, p, summary);
  const RunFile back = read_run_file(path);
  std::filesystem::remove(path);

  EXPECT_EQ(back.attributes.at("backend"), "grid");
  EXPECT_EQ(back.attributes.at("label"), "grid:grid.storage=float");
  EXPECT_EQ(back.attributes.at("scene_text"), kScene);
  EXPECT_NE(back.attributes.at("scene_resolved").find("radius_m = 0.01"), std::string::npos);
  EXPECT_EQ(back.attributes.at("overrides"), "tool.radius_m=0.01");
  EXPECT_FALSE(back.attributes.at("version").empty());
  EXPECT_EQ(back.attributes.at("date").size(), 20u);  // 2026-01-01T00:00:00Z
  EXPECT_EQ(back.summary, summary);
  ASSERT_EQ(back.steps.at("stamp").size(), 3u);
  EXPECT_EQ(back.steps.at("stamp")[2], 2.0);
  EXPECT_EQ(back.steps.at("volume_m3")[1], 2.0);
  EXPECT_EQ(back.steps.at("vertices")[2], 12.0);
  EXPECT_EQ(back.final_raster.nx, run.final_raster.nx);
  EXPECT_EQ(back.final_raster.ny, run.final_raster.ny);
  EXPECT_EQ(back.final_raster.values, run.final_raster.values);
  EXPECT_EQ(back.final_raster.spacing_m, run.final_raster.spacing_m);
  EXPECT_EQ(back.mesh.vertices, run.final_mesh.vertices);
  EXPECT_EQ(back.mesh.triangles, run.final_mesh.triangles);
  EXPECT_EQ(back.mesh.constrained_edges, run.final_mesh.constrained_edges);
}

TEST(RunFile, ReadingSomethingElseIsAnInputError) {
  const auto path = std::filesystem::temp_directory_path() / "sb_not_a_run.h5";
  EXPECT_THROW(read_run_file(path), InputError);
}

}  // namespace
}  // namespace sb
