// `sandbench interactive SCENE --backend tin|grid [--device mouse|replay:FILE|udp:PORT]
//   [--record FILE] [--frames N --screenshot IMAGE.png --stats STATS.json] [--set k=v ...] [--unset k ...]
//   [--max-memory SIZE]`
#include <memory>

#include "harness/cli/commands.hpp"
#include "harness/cli/scene_input.hpp"
#include "harness/cli/validators.hpp"
#include "harness/run/backends.hpp"
#include "harness/run/variant.hpp"
#include "harness/window/options.hpp"

namespace sb::cli {

void add_interactive_command(CLI::App& app) {
  auto o = std::make_shared<InteractiveOptions>();
  auto in = std::make_shared<SceneInput>();  // no --replay: the device replays (--device replay:FILE)
  CLI::App* cmd = app.add_subcommand(
      "interactive", "Touch the sand: a window, a tool driven by a haptic device (or the mouse), forces at 1 kHz");
  add_scene_options(cmd, *in, ReplayOption::Without);
  cmd->add_option("--backend", o->backend, backend_list() + " (optionally grid:key=value:...)")->required();
  cmd->add_option("--device", o->device, "mouse | replay:FILE (CSV t,x,y,z,buttons) | udp:PORT (loopback bridge)")
      ->capture_default_str();
  cmd->add_option("--record", o->record, "Record the session (trajectory, forces, tools, stamps) to this CSV file")
      ->check(output_file());
  cmd->add_option("--frames", o->frames, "Draw this many frames, then exit (0: until the window is closed)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--screenshot", o->screenshot, "Write the last frame to this PNG file")->check(output_file());
  cmd->add_option("--stats", o->stats, "Write the haptic statistics (servo_hz, tick_us.*, ...) to this JSON file")
      ->check(output_file());
  cmd->add_option("--max-force-n", o->max_force_n, "Device force limit, N")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--max-stiffness", o->max_stiffness_n_per_m, "Device stiffness limit, N/m")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--max-speed", o->max_speed_m_s,
                  "Fastest the device's tool moves, m/s: a pose step beyond it is a fault of the pose stream, "
                  "not motion (the force restarts from zero there and no work is booked)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--rate-hz", o->rate_hz, "Servo rate")->capture_default_str()->check(CLI::Range(100.0, 10000.0));
  cmd->add_option("--spin-us", o->spin_us, "Servo: spin this long before each deadline (at most one period)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--mesh-display", o->mesh_display,
                "Draw the terrain as one mesh rebuilt and uploaded whole whenever it changes, "
                "not from its changed tiles: for comparison");
  cmd->add_flag("!--no-panel", o->panel,
                "Draw the terrain and the tool without the control panel (screenshots for figures; its "
                "controls keep the scene's values)");
  cmd->add_flag("!--no-realtime", o->realtime, "Do not ask for real-time (SCHED_FIFO) priority for the servo thread");
  auto size = std::make_shared<std::vector<int>>();
  cmd->add_option("--size", *size, "Window size: --size 1280 800")->expected(2)->check(CLI::Range(64, 8192));
  cmd->callback([o, in, size] {
    o->scene = in->scene;
    o->overrides = scene_overrides(in->unset, in->overrides);
    o->max_memory = in->max_memory;
    if (size->size() == 2) {
      o->width = (*size)[0];
      o->height = (*size)[1];
    }
    run_interactive(*o);
  });
}

}  // namespace sb::cli
