#include "harness/run/runner.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <memory>
#include <sstream>

#include "common/input_error.hpp"

namespace sb {

PreparedScene prepare_scene(Scene scene) {
  PreparedScene p;
  p.scene = std::move(scene);
  p.initial = HeightField::from_scene(p.scene);
  // The lazy schedule outlives this function and copies of `p`: it keeps its own surface.
  auto surface = std::make_shared<const HeightField>(p.initial);
  p.schedule = make_schedule(p.scene.tool, p.scene.stroke, [surface](const Vec2& q) { return (*surface)(q); });
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

namespace {

std::string num(double v) {
  std::ostringstream s;
  s << std::setprecision(4) << v;
  return s.str();
}

// Watches the stamps as they are applied and turns what a researcher would want to know
// into warnings: stamps that cannot touch the domain, a tool bottom below the sand bed.
class StampWatch {
 public:
  // The sand lies on a bed at z = 0 (terrain.height_m is the sand's thickness there), or at
  // the lowest initial surface when the terrain starts below 0.
  StampWatch(const PreparedScene& p, const Raster& initial) : domain_(p.scene.domain.box()) {
    for (double z : initial.values) bed_ = std::min(bed_, z);
  }

  void see(const ToolStamp& s) {
    const Aabb2 reach = s.is_pour() ? Aabb2{s.pose.xy - Vec2(s.pour_radius_m, s.pour_radius_m),
                                            s.pose.xy + Vec2(s.pour_radius_m, s.pour_radius_m)}
                                    : s.influence_bounds();
    const bool outside = reach.hi.x() < domain_.lo.x() || reach.lo.x() > domain_.hi.x() ||
                         reach.hi.y() < domain_.lo.y() || reach.lo.y() > domain_.hi.y();
    outside_ += outside;
    if (!s.is_pour() && !outside && s.pose.bottom_z < bed_) {
      ++below_bed_;
      lowest_ = std::min(lowest_, s.pose.bottom_z);
    }
    ++seen_;
  }

  void warn(std::vector<std::string>& warnings) const {
    if (outside_ > 0)
      warnings.push_back(std::to_string(outside_) + " of " + std::to_string(seen_) +
                         " stamps lie entirely outside the domain, where they change nothing" +
                         (outside_ == seen_ ? " (the whole stroke misses the domain: check stroke.path_m)" : ""));
    if (below_bed_ > 0)
      warnings.push_back(
          std::to_string(below_bed_) + " stamps take the tool bottom below the sand bed (z = " + num(bed_) +
          "), down to z = " + num(lowest_) + " m: sand is dug below its base; check tool.depth_m or stroke.z_m");
  }

 private:
  Aabb2 domain_;
  std::size_t seen_ = 0, outside_ = 0, below_bed_ = 0;
  double bed_ = 0.0, lowest_ = 0.0;
};

// Stops a model that grows past what its scene was estimated to need, before it takes the
// machine's memory.
void check_growth(const PreparedScene& p, std::size_t initial_vertices, const StepRecord& r) {
  if (p.max_added_vertices == 0 || r.vertices <= initial_vertices + p.max_added_vertices) return;
  throw InputError("the model grew to " + std::to_string(r.vertices) + " vertices (from " +
                   std::to_string(initial_vertices) + "), past the " + std::to_string(p.max_added_vertices) +
                   " it may add by the pre-flight's estimate (" + p.vertex_bound_reason + "); stopped at " +
                   (r.stamp >= 0 ? "stamp " + std::to_string(r.stamp) : std::string("settling")) + ", nothing written");
}

}  // namespace

RunResult run_schedule(Terrain& terrain, const PreparedScene& p, const RunCallbacks& cb) {
  RunResult run;
  run.backend = std::string(terrain.name());
  run.label = run.backend;
  run.initial_raster = p.raster_template;
  terrain.sample(run.initial_raster);
  run.volume_initial = terrain.volume();
  double volume = run.volume_initial;
  StampWatch watch(p, run.initial_raster);
  const std::size_t initial_vertices = terrain.stats().vertices;

  const ErosionBudget step_budget{p.scene.erosion.max_passes_per_step};
  const std::size_t total = p.schedule.stamps.size();
  Stopwatch since_progress, since_start;
  bool estimated = false;
  if (cb.notice && total >= kManyStamps)
    cb.notice(std::to_string(total) + " stamps: a long run; an estimate follows after its first second");
  for (std::size_t i = 0; i < total; ++i) {
    const ToolStamp s = p.schedule.stamps[i];
    watch.see(s);
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
    check_growth(p, initial_vertices, r);
    run.memory_bytes_peak = std::max<std::size_t>(run.memory_bytes_peak, r.bytes);
    run.steps.push_back(r);
    // After about a second, a run that looks long says so once, whatever the terminal.
    if (!estimated && cb.notice && since_start.seconds() > 1.0 && i + 1 < total) {
      estimated = true;
      const double per_stamp = since_start.seconds() / static_cast<double>(i + 1);
      const double estimate = per_stamp * static_cast<double>(total);
      if (estimate > kLongRunSeconds)
        cb.notice("a long run: " + std::to_string(total) + " stamps at about " + num(per_stamp * 1e3) +
                  " ms each, about " + num(estimate / 60.0) + " min for the stroke (plus settling)");
    }
    if (cb.progress && (since_progress.seconds() > 0.25 || i + 1 == total)) {
      cb.progress(i + 1, total);
      since_progress.restart();
    }
  }

  // Relaxation after the stroke, recorded as steps with stamp = -1, so that the final shape
  // (and its slope metric) is the settled one.
  if (p.scene.erosion.relax_at_end) {
    const long long max_passes = p.scene.erosion.relax_max_passes;
    long long passes_left = max_passes;
    since_progress.restart();
    Stopwatch settling;
    bool announced = false;
    while (passes_left > 0 && terrain.stats().active > 0) {
      const int passes = static_cast<int>(std::min<long long>(passes_left, 64));
      StepRecord r;
      const ErosionBudget budget{.max_passes = passes, .settling = true, .cascade = p.scene.erosion.cascade};
      erode_and_simplify(terrain, p, budget, r, volume);
      passes_left -= passes;
      r.volume_m3 = volume;
      record_model(r, terrain.stats());
      check_growth(p, initial_vertices, r);
      run.memory_bytes_peak = std::max<std::size_t>(run.memory_bytes_peak, r.bytes);
      run.steps.push_back(r);
      if (cb.notice && !announced && settling.seconds() > kSlowSettlingSeconds) {
        announced = true;
        const double done = static_cast<double>(max_passes - passes_left);
        cb.notice("settling is slow: " + std::to_string(max_passes - passes_left) + " passes in " +
                  num(settling.seconds()) + " s, " + std::to_string(r.active) + " elements still active; at most " +
                  num((max_passes - done) / done * settling.seconds() / 60.0) +
                  " min more (erosion.relax_max_passes = " + std::to_string(max_passes) + ")");
      }
      if (cb.settling && since_progress.seconds() > 0.25) {
        cb.settling(max_passes - passes_left, max_passes, r.active);
        since_progress.restart();
      }
    }
  }

  run.final_stats = terrain.stats();
  run.memory_bytes_peak = std::max(run.memory_bytes_peak, run.final_stats.bytes);
  run.settled = run.final_stats.active == 0;
  if (cb.settling) cb.settling(-1, 0, run.final_stats.active);  // settling over
  run.volume_final = terrain.volume();
  // The bookkeeping checked against the full integral once, at the end.
  run.volume_tracking_error = volume - run.volume_final;
  run.max_slope_deg = terrain.max_slope_deg();
  run.final_raster = p.raster_template;
  terrain.sample(run.final_raster);
  watch.warn(run.warnings);
  if (!run.settled)
    run.warnings.push_back(
        "the run did not settle: " + std::to_string(run.final_stats.active) + " elements still unstable at the end" +
        (p.scene.erosion.relax_at_end ? " after erosion.relax_max_passes = " +
                                            std::to_string(p.scene.erosion.relax_max_passes) + " settling passes"
                                      : " (erosion.relax_at_end = false)") +
        "; slopes may exceed the critical angle");
  return run;
}

}  // namespace sb
