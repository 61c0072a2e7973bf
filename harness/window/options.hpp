#pragma once
// Options of `sandbench interactive` (harness/cli/interactive.cpp parses them).
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace sb {

struct InteractiveOptions {
  std::string scene;
  std::string backend;                      // tin | grid | sparse, optionally grid:key=value:...
  std::string device = "mouse";             // mouse | replay:FILE | udp:PORT
  std::vector<std::string> overrides;       // --set
  std::optional<std::uint64_t> max_memory;  // --max-memory (default: the memory available)
  std::string record;                       // session file; recording starts at once
  std::string screenshot;                   // PNG of the last frame
  std::string stats;                        // haptic statistics JSON
  long frames = 0;                          // 0: until the window is closed
  double max_force_n = 8.0;
  double max_stiffness_n_per_m = 2000.0;
  double max_speed_m_s = 2.0;  // faster pose steps are faults, not motion (haptics/device.hpp)
  double rate_hz = 1000.0;
  double spin_us = 150.0;
  bool realtime = true;
  bool mesh_display = false;  // the terrain drawn as a whole mesh, not by changed tiles (for comparison)
  bool panel = true;          // false: the terrain and the tool alone (screenshots for figures, tests)
  int width = 1280, height = 800;
};

// Opens the window and runs until it is closed or `frames` frames were drawn. Throws
// InputError for bad options (before any window opens), std::runtime_error when no window
// can be opened.
void run_interactive(const InteractiveOptions& options);

}  // namespace sb
