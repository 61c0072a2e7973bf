#pragma once
// The runner: applies one StampSchedule to one back-end, step by step (stamp, erode,
// simplify), timing each phase and recording counts and volume after every step. Each
// phase's volume change comes from the back-end's own report (O(1); a full volume(),
// outside the timers, only for back-ends that do not track it); volume() runs at the start
// and the end, where the tracked total is checked against it (volume_tracking_error).
// The final mesh is not copied: the run keeps the terrain, and writers stream its mesh.
#include <cstdint>
#include <functional>
#include <memory>
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
  // How many vertices the model may add to its initial count before the run stops with an
  // InputError (0: no bound); what set the bound, named in that message.
  std::size_t max_added_vertices = 0;
  bool replay = false;                   // the schedule is a recorded session's, not the scene's stroke
  std::uint64_t memory_limit_bytes = 0;  // what the pre-flight allowed (--max-memory or available); 0: unknown
  std::string vertex_bound_reason;
};
PreparedScene prepare_scene(Scene scene);

struct RunResult {
  std::string backend;            // "tin", "grid", "sparse"
  std::string label;              // backend plus variant overrides, e.g. "grid:grid.storage=float"
  std::vector<StepRecord> steps;  // stroke steps, then relaxation steps (stamp = -1)
  double volume_initial = 0.0;
  double volume_final = 0.0;
  double volume_added = 0.0;
  double volume_tracking_error = 0.0;  // tracked total minus volume() at the end, m^3
  double max_slope_deg = 0.0;
  bool settled = false;  // erosion active set empty at the end
  // What a researcher should know about this run (summary "warnings", printed on stderr):
  // stamps outside the domain, a tool below the sand bed, a run that did not settle.
  std::vector<std::string> warnings;
  ModelStats final_stats;
  std::size_t memory_bytes_peak = 0;
  Raster initial_raster;
  Raster final_raster;
  SurfaceMesh final_mesh;                        // set by callers that have no terrain
  std::shared_ptr<const Terrain> final_terrain;  // the run's terrain (run_variant sets it)
  // The final surface, streamed: from final_terrain when set, else final_mesh.
  void stream_final_mesh(MeshSink& sink) const {
    if (final_terrain)
      final_terrain->stream_mesh(sink);
    else
      stream_mesh(final_mesh, sink);
  }
  SurfaceMesh final_surface() const { return final_terrain ? final_terrain->mesh() : final_mesh; }
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
