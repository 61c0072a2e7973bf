#pragma once
// The interactive simulation thread. It owns the terrain (nobody else touches it) and loops:
// read the servo's newest state; stamp when the tool penetrates the sand and has moved at
// least the stroke spacing (or gone deeper) since the last stamp; erode within a per-step
// budget; simplify; republish the height patch for the servo; hand what changed of the surface
// to the window's DisplayFeed (display_feed.hpp: the changed tiles of a grid or of the TIN's
// domain up to 60 times a second, a whole mesh up to 30) and every 1/30 s the counters. Nothing per display
// update costs the size of the terrain: the volume shown is kept from the phases' reported
// changes, as the runner does. Controls from the window and the counters go through a mutex
// that the servo never sees. Optionally records the session (device samples drained from the
// servo's queue, every stamp applied).
#include <atomic>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "common/haptics/servo_loop.hpp"
#include "harness/interactive/display_feed.hpp"
#include "harness/io/session_file.hpp"
#include "harness/run/runner.hpp"

namespace sb {

struct SimControls {
  Material material;
  ToolSpec tool;
  bool paused = false;
  bool erosion = true;
  bool simplify = true;
  int erosion_passes = 4;               // per step
  std::size_t erosion_updates = 20000;  // per step: element visits
};

// What the window shows; copied out under the mutex at display rate.
struct SimStatus {
  ModelStats stats;
  double volume_m3 = 0.0, volume_initial_m3 = 0.0, volume_added_m3 = 0.0;
  std::uint64_t steps = 0, stamps = 0, patches = 0;
  double tool_ms = 0.0, erosion_ms = 0.0, simplify_ms = 0.0, patch_ms = 0.0;  // last working step
  double step_ms_p50 = 0.0, step_ms_p95 = 0.0;                                // last 256 working steps
  double tool_heading_rad = 0.0;                                              // footprint rotation of the current tool
  bool recording = false;
  std::size_t recorded_samples = 0, recorded_stamps = 0;
  std::string message;  // e.g. "wrote session.csv"
};

// Whole-run figures for the statistics file.
struct SimTotals {
  std::uint64_t steps = 0, stamps = 0, patches = 0;
  std::uint64_t erosion_updates = 0;  // element visits of every erosion call (ErosionReport::updates)
  std::vector<double> step_ms;        // every working step: stamp + erode + simplify
  std::vector<double> step_cpu_ms;    // the same steps on the simulation thread's CPU clock (no waiting for a core)
  std::vector<double> patch_ms;       // every publication
  std::vector<double> display_ms;     // every surface publication to the window (DisplayFeed::publish)
  ModelStats final_stats;
  double volume_initial_m3 = 0.0, volume_final_m3 = 0.0, volume_added_m3 = 0.0;
  double volume_tracked_m3 = 0.0;  // initial plus the phases' reported changes (what the panel showed)
};

class Simulation {
 public:
  // Publishes a first patch (at the domain's centre) and the whole surface before returning, so
  // the servo and the window have something from their first tick and frame.
  // tiles: the display is fed by changed tiles, a lattice's or the domain's (false: by whole meshes).
  Simulation(const PreparedScene& prepared, std::unique_ptr<Terrain> terrain, haptics::PatchBuffer& patches,
             haptics::ServoLoop& servo, std::string backend, bool tiles = true);
  ~Simulation();

  void start();
  void stop();  // joins, finishes a recording in progress (writes its file), publishes the final surface

  // Window thread.
  SimControls controls() const;
  void set_controls(const SimControls& c);
  SimStatus status() const;
  DisplayFeed& display() { return *feed_; }
  // Recording into `file` (written when stopped, whole or not at all).
  void start_recording(const std::filesystem::path& file);
  void stop_recording();

  // After stop().
  SimTotals totals() const;
  const Terrain& terrain() const { return *terrain_; }
  std::string recording_error() const;  // empty when every recording was written

 private:
  void run();
  void step();
  bool maybe_stamp(const haptics::ServoState& s);
  void publish_patch(const Vec2& centre);
  void publish_display(bool force);
  void add_volume(double change_m3);
  void drain_samples();
  void begin_recording();
  void end_recording();

  const PreparedScene& prepared_;
  std::unique_ptr<Terrain> terrain_;
  haptics::PatchBuffer& patches_;
  haptics::ServoLoop& servo_;
  std::string backend_;

  // Simulation thread only.
  SimControls active_;
  ErosionRule rule_;
  haptics::ForceParams params_;
  haptics::PatchLayout layout_;
  std::uint64_t patch_version_ = 0;
  Vec2 patch_centre_{0.0, 0.0};
  bool have_stamp_ = false;
  Vec2 last_stamp_xy_{0.0, 0.0};
  double last_stamp_z_ = 0.0, last_stamp_t_ = 0.0, heading_rad_ = 0.0;
  std::uint32_t generation_ = 0;
  bool dirty_ = false;          // terrain changed since the last surface publication
  std::size_t active_set_ = 1;  // erosion active set after the last erode (1: unknown)
  double last_surface_s_ = -1.0, last_status_s_ = -1.0;
  double volume_m3_ = 0.0;             // initial volume plus every phase's reported change
  std::vector<double> stamp_times_s_;  // steady-clock times of stamps not yet published
  std::unique_ptr<DisplayFeed> feed_;
  std::vector<double> recent_ms_;  // ring of the last working steps
  std::size_t recent_next_ = 0;
  SimTotals totals_;
  Session session_;
  std::filesystem::path record_file_;
  bool recording_ = false;
  Stopwatch clock_;

  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> controls_changed_{false};
  std::atomic<int> record_request_{0};  // 1 start, -1 stop

  mutable std::mutex mutex_;  // guards the members below (never taken by the servo)
  SimControls controls_;
  SimStatus status_;
  std::filesystem::path requested_file_;
  std::string record_error_;
};

}  // namespace sb
