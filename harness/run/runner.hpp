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
  std::string backend;            // "tin", "grid"
  std::string label;              // backend plus variant overrides, e.g. "grid:grid.storage=float"
  std::vector<StepRecord> steps;  // stroke steps, then relaxation steps (stamp = -1)
  double volume_initial = 0.0;
  double volume_final = 0.0;
  double volume_added = 0.0;
  double max_slope_deg = 0.0;
  bool settled = false;  // erosion active set empty at the end
  // What a researcher should know about this run (summary "warnings", printed on stderr):
  // stamps outside the domain, a tool below the sand bed, a run that did not settle.
  std::vector<std::string> warnings;
  ModelStats final_stats;
  std::size_t memory_bytes_peak = 0;
  Raster initial_raster;
  Raster final_raster;
  SurfaceMesh final_mesh;
};

// Progress callback: (done, total) stamps. Called at most every few hundred milliseconds.
using ProgressFn = std::function<void(std::size_t done, std::size_t total)>;

struct RunCallbacks {
  ProgressFn progress;
  // During the settling after the stroke: passes so far, the pass budget, active elements.
  std::function<void(long long passes, long long max_passes, std::size_t active)> settling;
  // One-line announcements as they arise: a run of kManyStamps or more before it starts; a
  // long run's estimate (after about a second of stamping, when the whole stroke looks
  // longer than kLongRunSeconds); settling that takes longer than kSlowSettlingSeconds.
  std::function<void(const std::string& message)> notice;
};
inline constexpr double kLongRunSeconds = 30.0;
inline constexpr std::size_t kManyStamps = 100000;   // announced before the first stamp
inline constexpr double kSlowSettlingSeconds = 5.0;  // settling announced after this long

RunResult run_schedule(Terrain& terrain, const PreparedScene& prepared, const RunCallbacks& callbacks);
inline RunResult run_schedule(Terrain& terrain, const PreparedScene& prepared, const ProgressFn& progress = {}) {
  return run_schedule(terrain, prepared, RunCallbacks{progress, {}, {}});
}

}  // namespace sb
