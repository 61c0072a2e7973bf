#include "harness/run/summary.hpp"

#include <algorithm>
#include <cmath>

#include "common/reference.hpp"

namespace sb {

Json summarize(const RunResult& run, const PreparedScene& p) {
  double tool = 0, erosion = 0, simplify = 0, detect = 0, remove = 0, relax = 0;
  double d_tool = 0, d_erosion = 0, d_simplify = 0;
  std::uint64_t touched = 0, updates = 0, relax_updates = 0, removed = 0;
  std::vector<double> step_ms;
  std::size_t stamps = 0, relax_steps = 0;
  for (const StepRecord& r : run.steps) {
    d_tool += r.volume_delta_tool;
    d_erosion += r.volume_delta_erosion;
    d_simplify += r.volume_delta_simplify;
    removed += r.removed;
    if (r.stamp < 0) {
      relax += r.total_s();
      relax_updates += r.erosion_updates;
      ++relax_steps;
      continue;
    }
    ++stamps;
    tool += r.time_tool_s;
    erosion += r.time_erosion_s;
    simplify += r.time_simplify_s;
    detect += r.time_detect_s;
    remove += r.time_remove_s;
    touched += r.elements_touched;
    updates += r.erosion_updates;
    step_ms.push_back(1e3 * r.total_s());
  }
  const ModelStats& st = run.final_stats;
  const double crit = p.scene.material.critical_angle_deg;

  Json j;
  j["backend"] = run.backend;
  j["label"] = run.label;
  j["scene"] = p.scene.path;
  j["stamps"] = stamps;
  j["time_s.tool"] = tool;
  j["time_s.erosion"] = erosion;
  j["time_s.simplify"] = simplify;
  j["time_s.total"] = tool + erosion + simplify;
  j["step_ms.p50"] = percentile(step_ms, 0.5);
  j["step_ms.p95"] = percentile(step_ms, 0.95);
  j["step_ms.max"] = step_ms.empty() ? 0.0 : *std::max_element(step_ms.begin(), step_ms.end());
  j["memory_bytes"] = st.bytes;
  j["memory_bytes_peak"] = run.memory_bytes_peak;
  j["vertices"] = st.vertices;
  j["triangles"] = st.triangles;
  j["constrained_edges"] = st.constrained_edges;
  j["cells"] = st.cells;
  j["volume_initial"] = run.volume_initial;
  j["volume_final"] = run.volume_final;
  j["volume_added"] = run.volume_added;
  j["volume_drift_rel"] =
      run.volume_initial != 0.0 ? (run.volume_final - run.volume_initial - run.volume_added) / run.volume_initial : 0.0;
  j["max_slope_excess_deg"] = std::max(0.0, run.max_slope_deg - crit);
  // Extras beyond the contract.
  j["max_slope_deg"] = run.max_slope_deg;
  j["settled"] = run.settled;
  j["time_s.detect"] = detect;
  j["time_s.remove"] = remove;
  j["time_s.relax"] = relax;
  j["relax_steps"] = relax_steps;
  j["relax_updates"] = relax_updates;
  j["volume_tracking_error"] = run.volume_tracking_error;
  j["volume_delta_tool"] = d_tool;
  j["volume_delta_erosion"] = d_erosion;
  j["volume_delta_simplify"] = d_simplify;
  j["elements_touched"] = touched;
  j["erosion_updates"] = updates;
  j["vertices_removed"] = removed;
  j["walk_steps"] = st.walk_steps;
  if (p.scene.output.energy) {
    // Erosion only moves sand downhill: a step whose erosion raised the energy oscillated.
    std::size_t rises = 0;
    for (const StepRecord& r : run.steps) rises += r.energy_delta_erosion_m4 > 1e-12 * std::abs(r.energy_m4);
    j["energy_rises"] = rises;
  }
  // Accuracy against the scene's analytic reference, when it names one.
  std::vector<std::string> warnings = run.warnings;
  const Json accuracy =
      accuracy_metrics(p.scene, p.schedule, p.initial, run.initial_raster, run.final_raster, &warnings);
  for (const auto& [key, value] : accuracy.items()) j[key] = value;
  j["warnings"] = warnings;  // also printed on stderr by the command line
  return j;
}

}  // namespace sb
