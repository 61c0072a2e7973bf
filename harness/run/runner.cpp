#include "harness/run/runner.hpp"

#include <algorithm>
#include <cmath>

namespace sb {

PreparedScene prepare_scene(Scene scene) {
  PreparedScene p{std::move(scene), {}, {}, {}, {}};
  p.initial = HeightField::from_scene(p.scene);
  p.schedule = make_schedule(p.scene.tool, p.scene.stroke, [&](const Vec2& q) { return p.initial(q); });
  p.rule = ErosionRule::from(p.scene.material, p.scene.erosion.settle_tolerance_deg, p.scene.erosion.rule);
  p.raster_template = Raster::covering(p.scene.domain.box(), p.scene.output.raster_m);
  return p;
}

namespace {

// Sum of z^2 / 2 over the raster times the sample area: the potential energy per unit weight.
double potential_energy(const Terrain& t, Raster raster) {
  t.sample(raster);
  double e = 0.0;
  for (double z : raster.values) e += 0.5 * z * z;
  return e * raster.spacing_m * raster.spacing_m;
}

void record_model(StepRecord& r, const ModelStats& st) {
  r.vertices = st.vertices;
  r.triangles = st.triangles;
  r.constrained_edges = st.constrained_edges;
  r.cells = st.cells;
  r.bytes = st.bytes;
  r.active = st.active;
  r.walk_steps = st.walk_steps;
}

// A phase's volume change: the back-end's own exact bookkeeping (O(1)) when it reports
// one, else a full volume() (O(model)). `volume` is the running total.
double volume_change(double reported, const Terrain& t, double& volume) {
  if (std::isnan(reported)) {
    const double v = t.volume();
    const double change = v - volume;
    volume = v;
    return change;
  }
  volume += reported;
  return reported;
}

// Erosion then simplification, timed, with the volume change of each phase.
void erode_and_simplify(Terrain& t, const PreparedScene& p, const ErosionBudget& budget, StepRecord& r,
                        double& volume) {
  const double energy_before = p.scene.output.energy ? potential_energy(t, p.raster_template) : 0.0;
  Stopwatch sw;
  const ErosionReport er = t.erode(p.rule, budget);
  r.time_erosion_s = sw.seconds();
  r.erosion_updates = er.updates;
  r.erosion_transfers = er.transfers;
  r.volume_delta_erosion = volume_change(er.volume_change_m3, t, volume);
  if (p.scene.output.energy) {
    r.energy_m4 = potential_energy(t, p.raster_template);
    r.energy_delta_erosion_m4 = r.energy_m4 - energy_before;
  }

  sw.restart();
  const SimplifyReport sr = t.simplify(SimplifyParams{p.scene.tin.alpha_flat_deg});
  r.time_simplify_s = sw.seconds();
  r.time_detect_s = sr.detect_s;
  r.time_remove_s = sr.remove_s;
  r.removed = sr.removed;
  r.volume_delta_simplify = volume_change(sr.volume_change_m3, t, volume);
}

}  // namespace

RunResult run_schedule(Terrain& terrain, const PreparedScene& p, const ProgressFn& progress) {
  RunResult run;
  run.backend = std::string(terrain.name());
  run.label = run.backend;
  run.initial_raster = p.raster_template;
  terrain.sample(run.initial_raster);
  run.volume_initial = terrain.volume();
  double volume = run.volume_initial;

  const ErosionBudget step_budget{p.scene.erosion.max_passes_per_step};
  const std::size_t total = p.schedule.stamps.size();
  Stopwatch since_progress;
  for (std::size_t i = 0; i < total; ++i) {
    const ToolStamp& s = p.schedule.stamps[i];
    StepRecord r;
    r.stamp = static_cast<std::int64_t>(s.generation);
    Stopwatch sw;
    const StampReport sr = terrain.stamp(s);
    r.time_tool_s = sw.seconds();
    r.elements_touched = sr.elements_touched;
    r.volume_added = s.is_pour() ? s.pour_volume_m3 : 0.0;
    // What the tool changed beyond a pour.
    r.volume_delta_tool = volume_change(sr.volume_change_m3, terrain, volume) - r.volume_added;
    run.volume_added += r.volume_added;

    erode_and_simplify(terrain, p, step_budget, r, volume);
    r.volume_m3 = volume;
    record_model(r, terrain.stats());
    run.memory_bytes_peak = std::max<std::size_t>(run.memory_bytes_peak, r.bytes);
    run.steps.push_back(r);
    if (progress && (since_progress.seconds() > 0.25 || i + 1 == total)) {
      progress(i + 1, total);
      since_progress.restart();
    }
  }

  // Relaxation after the stroke, recorded as steps with stamp = -1, so that the final shape
  // (and its slope metric) is the settled one.
  if (p.scene.erosion.relax_at_end) {
    int passes_left = p.scene.erosion.relax_max_passes;
    while (passes_left > 0 && terrain.stats().active > 0) {
      const int passes = std::min(passes_left, 64);
      StepRecord r;
      erode_and_simplify(terrain, p, ErosionBudget{passes}, r, volume);
      passes_left -= passes;
      r.volume_m3 = volume;
      record_model(r, terrain.stats());
      run.memory_bytes_peak = std::max<std::size_t>(run.memory_bytes_peak, r.bytes);
      run.steps.push_back(r);
    }
  }

  run.final_stats = terrain.stats();
  run.memory_bytes_peak = std::max(run.memory_bytes_peak, run.final_stats.bytes);
  run.settled = run.final_stats.active == 0;
  run.volume_final = terrain.volume();
  // The bookkeeping checked against the full integral once, at the end.
  run.volume_tracking_error = volume - run.volume_final;
  run.max_slope_deg = terrain.max_slope_deg();
  run.final_raster = p.raster_template;
  terrain.sample(run.final_raster);
  return run;
}

}  // namespace sb
