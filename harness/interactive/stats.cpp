#include "harness/interactive/stats.hpp"

#include <algorithm>
#include <fstream>
#include <numeric>

#include "common/atomic_file.hpp"
#include "common/metrics.hpp"

namespace sb {

Json haptic_stats_json(const haptics::ServoStats& s, const haptics::DeviceLimits& limits, const SimTotals& sim,
                       const InteractiveRunInfo& info) {
  Json j;
  j["servo_hz"] = s.servo_hz;
  j["tick_us.p50"] = s.tick_us_p50;
  j["tick_us.p99"] = s.tick_us_p99;
  j["tick_us.max"] = s.tick_us_max;
  j["missed_deadlines"] = s.missed_deadlines;
  j["force_max_n"] = s.force_max_n;
  // Extras beyond the contract.
  j["force_limit_n"] = limits.max_force_n;
  j["stiffness_limit_n_per_m"] = limits.max_stiffness_n_per_m;
  j["speed_limit_m_s"] = limits.max_speed_m_s;
  j["device_force_max_n"] = info.device_force_max_n;
  j["forces_clamped"] = s.forces_clamped;
  j["forces_nonfinite"] = s.forces_nonfinite;
  j["ticks"] = s.ticks;
  j["duration_s"] = s.duration_s;
  j["late_us.p50"] = s.late_us_p50;
  j["late_us.p99"] = s.late_us_p99;
  j["late_us.max"] = s.late_us_max;
  j["ticks_in_contact"] = s.ticks_in_contact;
  j["ticks_without_pose"] = s.ticks_without_pose;
  j["ticks_outside_patch"] = s.ticks_outside_patch;
  j["samples_dropped"] = s.samples_dropped;
  j["realtime"] = s.realtime;
  // Rendering (common/haptics/rendering.hpp): per-tick force change and passivity.
  j["force_step_n.p99"] = s.force_step_n_p99;
  j["force_step_n.p999"] = s.force_step_n_p999;
  j["force_step_n.max"] = s.force_step_n_max;
  j["patch_switches"] = s.patch_switches;
  j["ticks_rate_limited"] = s.ticks_rate_limited;
  j["pose_jumps"] = s.pose_jumps;
  // Fidelity: the force sent against the model's force at the same pose (servo_loop.hpp).
  j["force_error_n.p50"] = s.force_error_n_p50;
  j["force_error_n.p99"] = s.force_error_n_p99;
  j["force_error_n.max"] = s.force_error_n_max;
  j["force_error_unblended_n.p50"] = s.force_error_unblended_n_p50;
  j["force_error_unblended_n.p99"] = s.force_error_unblended_n_p99;
  j["force_error_unblended_n.max"] = s.force_error_unblended_n_max;
  j["onsets"] = s.onsets;
  j["onset_lag_ms.max"] = s.onset_lag_ms_max;
  j["onset_held_force_n"] = s.onset_held_force_n;
  j["passivity.energy_j"] = s.passivity_energy_j;
  j["passivity.energy_max_j"] = s.passivity_energy_max_j;
  j["passivity.dissipated_j"] = s.passivity_dissipated_j;
  j["passivity.ticks_active"] = s.passivity_ticks_active;
  j["passivity.energy_bound_j"] = s.passivity_energy_bound_j;
  j["passivity.ticks_bounded"] = s.passivity_ticks_bounded;
  j["sim.steps"] = sim.steps;
  j["sim.stamps"] = sim.stamps;
  j["sim.erosion_updates"] = sim.erosion_updates;
  j["sim.step_cpu_s.total"] = std::accumulate(sim.step_cpu_ms.begin(), sim.step_cpu_ms.end(), 0.0) * 1e-3;
  j["sim.step_ms.p50"] = percentile(sim.step_ms, 0.5);
  j["sim.step_ms.p95"] = percentile(sim.step_ms, 0.95);
  j["sim.step_ms.max"] = sim.step_ms.empty() ? 0.0 : *std::max_element(sim.step_ms.begin(), sim.step_ms.end());
  j["sim.step_cpu_ms.p50"] = percentile(sim.step_cpu_ms, 0.5);
  j["sim.step_cpu_ms.p95"] = percentile(sim.step_cpu_ms, 0.95);
  j["patches"] = sim.patches;
  j["patch_ms.p50"] = percentile(sim.patch_ms, 0.5);
  j["patch_ms.p95"] = percentile(sim.patch_ms, 0.95);
  j["vertices"] = sim.final_stats.vertices;
  j["triangles"] = sim.final_stats.triangles;
  j["cells"] = sim.final_stats.cells;
  j["memory_bytes"] = sim.final_stats.bytes;
  j["volume_initial"] = sim.volume_initial_m3;
  j["volume_final"] = sim.volume_final_m3;
  j["volume_added"] = sim.volume_added_m3;
  j["volume_tracked"] = sim.volume_tracked_m3;
  j["frames"] = info.frames;
  j["fps"] = info.wall_s > 0.0 ? static_cast<double>(info.frames) / info.wall_s : 0.0;
  // The display path: frame times, the simulation's publication of the surface's changes, the
  // window's uploads, and how long a stamp takes to show.
  j["frame_ms.p50"] = percentile(info.frame_ms, 0.5);
  j["frame_ms.p99"] = percentile(info.frame_ms, 0.99);
  j["display_updates"] = sim.display_ms.size();
  j["display_ms.p50"] = percentile(sim.display_ms, 0.5);
  j["display_ms.p95"] = percentile(sim.display_ms, 0.95);
  j["upload_ms.p50"] = percentile(info.upload_ms, 0.5);
  j["upload_ms.p95"] = percentile(info.upload_ms, 0.95);
  j["stamp_to_frame_ms.p50"] = percentile(info.stamp_to_frame_ms, 0.5);
  j["stamp_to_frame_ms.p95"] = percentile(info.stamp_to_frame_ms, 0.95);
  j["stamp_to_frame_ms.max"] = percentile(info.stamp_to_frame_ms, 1.0);
  // The part of it spent before the frame that shows it began (the rest is that frame's drawing).
  j["stamp_to_take_ms.p50"] = percentile(info.stamp_to_take_ms, 0.5);
  j["stamp_to_take_ms.p95"] = percentile(info.stamp_to_take_ms, 0.95);
  j["backend"] = info.backend;
  j["device"] = info.device;
  j["gl_renderer"] = info.gl_renderer;
  j["scene"] = info.scene;
  return j;
}

void write_json_file(const std::filesystem::path& file, const Json& json) {
  write_text_atomically(file, json.dump(2) + "\n");
}

}  // namespace sb
