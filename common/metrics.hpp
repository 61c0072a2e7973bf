#pragma once
// Timers and per-step records: what the runner measures every step, and the summary
// statistics computed from them.
#include <chrono>
#include <cstdint>
#include <limits>
#include <vector>

namespace sb {

class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  double seconds() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }
  void restart() { start_ = std::chrono::steady_clock::now(); }

 private:
  std::chrono::steady_clock::time_point start_;
};

// One row of the step series (HDF5 /steps/*). A step is stamp + erode + simplify; the
// relaxation after the stroke is recorded as steps with stamp = -1.
struct StepRecord {
  std::int64_t stamp = -1;
  double time_tool_s = 0.0, time_erosion_s = 0.0, time_simplify_s = 0.0;
  double time_detect_s = 0.0, time_remove_s = 0.0;  // the two parts of simplify
  double volume_m3 = 0.0;                           // after the step
  double volume_delta_tool = 0.0, volume_delta_erosion = 0.0, volume_delta_simplify = 0.0;
  double volume_added = 0.0;  // poured in this step
  std::uint64_t vertices = 0, triangles = 0, constrained_edges = 0, cells = 0, bytes = 0;
  std::uint64_t active = 0, erosion_updates = 0, erosion_transfers = 0;
  std::uint64_t elements_touched = 0, removed = 0, walk_steps = 0;
  // Potential energy per unit weight, sum of z^2 / 2 dA on the comparison raster (m^4);
  // NaN unless the scene asks for it (output.energy).
  double energy_m4 = std::numeric_limits<double>::quiet_NaN();
  double energy_delta_erosion_m4 = std::numeric_limits<double>::quiet_NaN();  // > 0: oscillation
  double total_s() const { return time_tool_s + time_erosion_s + time_simplify_s; }
};

// Percentile by linear interpolation between order statistics; q in [0, 1]. 0 when empty.
double percentile(std::vector<double> values, double q);
// CPU seconds the calling thread has run (CLOCK_THREAD_CPUTIME_ID): a span's work without the
// time it waited for a core on a shared machine.
double thread_cpu_seconds();

}  // namespace sb
