#pragma once
// The runner: applies one StampSchedule to one back-end, step by step (stamp, erode,
// simplify), timing each phase and recording counts and volume after every step. Volume is
// measured between phases and outside the timers, so each phase's volume change is known.
#include <functional>
#include <string>
#include <vector>

#include "common/height_field.hpp"
#include "common/metrics.hpp"
#include "common/raster.hpp"
#include "common/scene.hpp"
#include "common/schedule.hpp"
#include "common/terrain.hpp"

namespace sb {

// What every back-end run of a scene shares: built once, so all back-ends see the same
// initial surface, the same stamps and the same comparison raster.
struct PreparedScene {
  Scene scene;
  HeightField initial;
  StampSchedule schedule;
  ErosionRule rule;
  Raster raster_template;  // the common sampling lattice (values zero)
};
PreparedScene prepare_scene(Scene scene);

struct RunResult {
  std::string backend;            // "tin", "grid", "sparse"
  std::string label;              // backend plus variant overrides, e.g. "grid:grid.storage=float"
  std::vector<StepRecord> steps;  // stroke steps, then relaxation steps (stamp = -1)
  double volume_initial = 0.0;
  double volume_final = 0.0;
  double volume_added = 0.0;
  double max_slope_deg = 0.0;
  bool settled = false;  // erosion active set empty at the end
  ModelStats final_stats;
  std::size_t memory_bytes_peak = 0;
  Raster initial_raster;
  Raster final_raster;
  SurfaceMesh final_mesh;
};

// Progress callback: (done, total) stamps. Called at most every few hundred milliseconds.
using ProgressFn = std::function<void(std::size_t done, std::size_t total)>;

RunResult run_schedule(Terrain& terrain, const PreparedScene& prepared, const ProgressFn& progress = {});

}  // namespace sb
