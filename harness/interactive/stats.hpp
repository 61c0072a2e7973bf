#pragma once
// The haptic statistics file of `sandbench interactive --stats FILE`: the contract keys of
// README "Interactive mode and haptics" (servo_hz, tick_us.p50, tick_us.p99, tick_us.max, missed_deadlines,
// force_max_n) first, then the limits, the simulation's figures and bookkeeping.
#include <filesystem>
#include <string>
#include <vector>

#include "common/haptics/servo_loop.hpp"
#include "harness/interactive/sim.hpp"
#include "harness/run/summary.hpp"

namespace sb {

struct InteractiveRunInfo {
  std::string scene, backend, device;
  std::string gl_renderer;  // GL_RENDERER of the window's context (e.g. llvmpipe under Xvfb)
  std::uint64_t frames = 0;
  double wall_s = 0.0;                    // window open time
  double device_force_max_n = -1.0;       // as the device saw it (replay, mouse); < 0: unknown
  std::vector<double> frame_ms;           // every frame: swap to swap
  std::vector<double> upload_ms;          // every surface upload the window made
  std::vector<double> stamp_to_frame_ms;  // every stamp: applied to the swap of the first frame showing it
  std::vector<double> stamp_to_take_ms;   // the same stamps: applied to the window taking it (its frame's start)
};

Json haptic_stats_json(const haptics::ServoStats& servo, const haptics::DeviceLimits& limits, const SimTotals& sim,
                       const InteractiveRunInfo& info);
// Whole or not at all.
void write_json_file(const std::filesystem::path& file, const Json& json);

}  // namespace sb
