// run_interactive: the window (GLFW, OpenGL 3.3, Dear ImGui) around the servo loop and the
// simulation thread. The window thread draws at display rate (capped at 60 Hz when the
// display does not pace swaps, as under Xvfb), moves the mouse device, shows the panel, takes
// the surface's changes from the simulation's DisplayFeed and hands control changes back.
// In order: the input checks (prepare_interactive), the window and ImGui (open_window,
// GuiSession), the frame loop (WindowLoop: input, surface, panel, drawing), the outputs.
#include <epoxy/gl.h>  // before GLFW: libepoxy loads the window's GL entry points
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <iostream>
#include <memory>
#include <optional>
#include <thread>

#include "common/atomic_file.hpp"
#include "common/haptics/replay_device.hpp"
#include "common/haptics/shared_pose_device.hpp"
#include "common/haptics/udp_device.hpp"
#include "common/input_error.hpp"
#include "common/metrics.hpp"
#include "common/png_io.hpp"
#include "harness/interactive/device.hpp"
#include "harness/interactive/stats.hpp"
#include "harness/run/backends.hpp"
#include "harness/run/preflight.hpp"
#include "harness/run/variant.hpp"
#include "harness/window/gl_driver.hpp"
#include "harness/window/mouse.hpp"
#include "harness/window/options.hpp"
#include "harness/window/panel.hpp"
#include "harness/window/view.hpp"

namespace sb {

namespace {

namespace fs = std::filesystem;

std::string default_record_path() {
  char buf[64];
  const std::time_t now = std::time(nullptr);
  std::strftime(buf, sizeof buf, "session-%Y%m%d-%H%M%S.csv", std::localtime(&now));
  return buf;
}

// Window input the callbacks collect between frames.
struct WindowInput {
  double scroll = 0.0;  // wheel notches
  bool ctrl_scroll = false;
};

void scroll_callback(GLFWwindow* w, double, double dy) {
  if (ImGui::GetCurrentContext() && ImGui::GetIO().WantCaptureMouse) return;
  auto* in = static_cast<WindowInput*>(glfwGetWindowUserPointer(w));
  in->scroll += dy;
  in->ctrl_scroll =
      glfwGetKey(w, GLFW_KEY_LEFT_CONTROL) == GLFW_PRESS || glfwGetKey(w, GLFW_KEY_RIGHT_CONTROL) == GLFW_PRESS;
}

void add_line(std::vector<LineVertex>& out, const Vec3& a, const Vec3& b, const Vec3& rgb) {
  auto f = [](double v) { return static_cast<float>(v); };
  out.push_back({f(a.x()), f(a.y()), f(a.z()), f(rgb.x()), f(rgb.y()), f(rgb.z())});
  out.push_back({f(b.x()), f(b.y()), f(b.z()), f(rgb.x()), f(rgb.y()), f(rgb.z())});
}

// The tool (footprint at its bottom and 3 cm above) and the force arrow (1 cm per newton).
std::vector<LineVertex> tool_overlay(const ToolSpec& tool, double heading_rad, const haptics::ServoState& s) {
  std::vector<LineVertex> lines;
  if (!s.device.valid) return lines;
  const Vec3 p = s.device.position_m;
  std::vector<Vec2> poly = tool.footprint_local();
  if (poly.empty())
    for (int k = 0; k < 16; ++k)
      poly.emplace_back(tool.radius_m * std::cos(k * 0.3927), tool.radius_m * std::sin(k * 0.3927));
  const double c = std::cos(heading_rad), sn = std::sin(heading_rad);
  const Vec3 ring = s.model.in_contact ? Vec3(1.0, 0.85, 0.1) : Vec3(0.9, 0.9, 0.95);
  const Vec3 grey(0.6, 0.6, 0.65);
  auto world = [&](const Vec2& q, double dz) {
    return Vec3(p.x() + c * q.x() - sn * q.y(), p.y() + sn * q.x() + c * q.y(), p.z() + dz);
  };
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Vec2& a = poly[i];
    const Vec2& b = poly[(i + 1) % poly.size()];
    add_line(lines, world(a, 0.0), world(b, 0.0), ring);
    add_line(lines, world(a, 0.03), world(b, 0.03), grey);
    if (i % std::max<std::size_t>(1, poly.size() / 4) == 0) add_line(lines, world(a, 0.0), world(a, 0.03), grey);
  }
  const Vec3 f = s.force_n;
  if (f.norm() > 1e-6) {
    const Vec3 tip = p + 0.01 * f;
    const Vec3 red(1.0, 0.2, 0.15);
    add_line(lines, p, tip, red);
    const Vec3 side = f.cross(Vec3::UnitX()).norm() > 1e-9 ? f.cross(Vec3::UnitX()).normalized() : Vec3::UnitY();
    const Vec3 back = -0.2 * 0.01 * f;
    add_line(lines, tip, tip + back + 0.1 * 0.01 * f.norm() * side, red);
    add_line(lines, tip, tip + back - 0.1 * 0.01 * f.norm() * side, red);
  }
  return lines;
}

struct GlfwSession {
  GlfwSession() {
    glfwSetErrorCallback(
        [](int code, const char* what) { std::cerr << "glfw: error " << code << ": " << what << "\n"; });
    if (!glfwInit())
      throw InputError(
          "cannot open a window: GLFW found no display (is DISPLAY set? headless: xvfb-run -a sandbench "
          "interactive ...)");
  }
  ~GlfwSession() { glfwTerminate(); }
};

// Everything that can be wrong with the input, checked before a window opens: the options
// one by one by CLI11 (harness/cli/interactive.cpp), here what they say together; then the
// scene and its resource pre-flight, the device (which reads a replay file), a display to open a
// window on, and the model.
struct InteractiveSetup {
  Variant variant;
  PreparedScene prepared;
  haptics::DeviceLimits limits;
  std::unique_ptr<haptics::HapticDevice> device;
  std::unique_ptr<Terrain> terrain;
};

InteractiveSetup prepare_interactive(const InteractiveOptions& o) {
  if (!(o.spin_us <= 1e6 / o.rate_hz))
    throw InputError("--spin-us " + std::to_string(o.spin_us) +
                     " must be in [0, one period = " + std::to_string(1e6 / o.rate_hz) + "]");
  const std::pair<const char*, const std::string*> outputs[] = {
      {"--record", &o.record}, {"--screenshot", &o.screenshot}, {"--stats", &o.stats}};
  for (const auto& [option, path] : outputs)
    if (!path->empty()) check_output_path(*path, option, {o.scene});  // CLI11 checked all but the scene
  Variant variant = parse_variant(o.backend, "--backend");
  std::vector<std::string> overrides = o.overrides;
  overrides.insert(overrides.end(), variant.overrides.begin(), variant.overrides.end());
  Scene scene = load_scene(o.scene, overrides);
  // Before the model is allocated, as `run` does: the device takes the tool anywhere in the
  // domain for as long as the window is open, so the whole domain counts as disturbed (as for a
  // replayed session); the window keeps no step records.
  preflight(estimate_resources({{variant.backend, scene}}, 0, /*replay=*/true), o.max_memory);
  PreparedScene prepared = prepare_scene(std::move(scene));
  const DeviceSpec device_spec = parse_device_spec(o.device);
  const haptics::DeviceLimits limits =
      scene_device_limits(prepared.initial, o.max_force_n, o.max_stiffness_n_per_m, o.max_speed_m_s);
  std::unique_ptr<haptics::HapticDevice> device = make_device(device_spec, limits);
  const char* x11 = std::getenv("DISPLAY");
  const char* wayland = std::getenv("WAYLAND_DISPLAY");
  if ((!x11 || !*x11) && (!wayland || !*wayland))
    throw InputError(
        "interactive needs a display and neither DISPLAY nor WAYLAND_DISPLAY is set; without one, run it "
        "under a virtual display: xvfb-run -a sandbench interactive ...");
  if (auto* udp = dynamic_cast<haptics::UdpDevice*>(device.get()))
    std::cerr << "udp device: listening on 127.0.0.1:" << udp->port() << "\n";
  std::unique_ptr<Terrain> terrain = make_terrain(variant.backend, prepared.scene, prepared.initial);
  return InteractiveSetup{std::move(variant), std::move(prepared), limits, std::move(device), std::move(terrain)};
}

// An OpenGL 3.3 core window, its context current.
GLFWwindow* open_window(const InteractiveOptions& o, const std::string& title) {
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_SAMPLES, 0);
  GLFWwindow* window = glfwCreateWindow(o.width, o.height, title.c_str(), nullptr, nullptr);
  if (!window) throw InputError("cannot open an OpenGL 3.3 core window on this display (headless: xvfb-run -a)");
  glfwMakeContextCurrent(window);
  glfwSwapInterval(1);
  if (epoxy_gl_version() < 33) {
    glfwDestroyWindow(window);
    throw std::runtime_error("the window's OpenGL is " + std::to_string(epoxy_gl_version() / 10) + "." +
                             std::to_string(epoxy_gl_version() % 10) + "; OpenGL 3.3 is needed");
  }
  keep_gl_driver_loaded();  // for LeakSanitizer at exit (gl_driver.hpp)
  return window;
}

// ImGui on the window; the GL objects and ImGui go before the context does, whatever happens.
struct GuiSession {
  GLFWwindow* window;
  GuiSession(GLFWwindow* w, WindowInput& input) : window(w) {
    glfwSetWindowUserPointer(window, &input);
    glfwSetScrollCallback(window, scroll_callback);  // before ImGui, which chains it
    IMGUI_CHECKVERSION();
    ImGui::CreateContext();
    ImGui::GetIO().IniFilename = nullptr;
    ImGui::StyleColorsDark();
    ImGui_ImplGlfw_InitForOpenGL(window, true);
    ImGui_ImplOpenGL3_Init("#version 330 core");
  }
  ~GuiSession() {
    ImGui_ImplOpenGL3_Shutdown();
    ImGui_ImplGlfw_Shutdown();
    ImGui::DestroyContext();
    glfwDestroyWindow(window);
  }
  GuiSession(const GuiSession&) = delete;
  GuiSession& operator=(const GuiSession&) = delete;
};

double steady_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// The frame loop and what it needs: input (camera, mouse device), the surface from the
// simulation's feed, the panel, the drawing; frame and latency figures for the statistics.
class WindowLoop {
 public:
  WindowLoop(const InteractiveOptions& o, const InteractiveSetup& setup, GLFWwindow* window, WindowInput& input,
             Simulation& sim, haptics::ServoLoop& servo)
      : o_(o), setup_(setup), window_(window), input_(input), sim_(sim), servo_(servo) {
    const Aabb2 box = setup.prepared.scene.domain.box();
    const Vec2 centre = 0.5 * (box.lo + box.hi);
    const double z0 = setup.prepared.initial(centre);
    view_ = std::make_unique<TerrainView>(Vec3(centre.x(), centre.y(), z0), setup.limits.workspace.lo.z() + 0.1 - 0.02,
                                          setup.limits.workspace.hi.z() - 0.1);
    if (const auto& lattice = sim.display().lattice()) view_->use_lattice(*lattice, sim.display().z_ref());
    if (const std::size_t tiles = sim.display().mesh_tiles()) view_->use_mesh_tiles(tiles, sim.display().origin());
    camera_.target = Vec3(centre.x(), centre.y(), z0);
    camera_.distance_m = std::clamp(0.6 * (box.hi - box.lo).norm(), 0.1, 50.0);
    mouse_device_ = dynamic_cast<haptics::SharedPoseDevice*>(setup.device.get());
    replay_ = dynamic_cast<haptics::ReplayDevice*>(setup.device.get());
    if (mouse_device_) mouse_.emplace(*mouse_device_, setup.prepared.initial);
    panel_.record_path = o.record.empty() ? default_record_path() : o.record;
    panel_.tool_size_m = static_cast<float>(setup.prepared.scene.tool.radius_m);
    controls_ = sim.controls();
    if (mouse_) mouse_->update(std::nullopt, false);
  }

  // Until the window closes or o.frames frames were drawn.
  void run() {
    const auto opened = std::chrono::steady_clock::now();
    auto last_frame = opened;
    const auto frame_period = std::chrono::microseconds(16667);
    while (true) {
      glfwPollEvents();
      const bool last = glfwWindowShouldClose(window_) || (o_.frames > 0 && frames_ + 1 >= o_.frames);
      const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - last_frame).count();
      frame(last, dt);
      ++frames_;
      // Pace at 60 Hz when swaps are not paced by the display.
      const auto next = last_frame + frame_period;
      if (std::chrono::steady_clock::now() < next) std::this_thread::sleep_until(next);
      const auto now = std::chrono::steady_clock::now();
      frame_ms_.push_back(1e3 * std::chrono::duration<double>(now - last_frame).count());
      last_frame = now;
      if (last) break;
    }
    wall_s_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - opened).count();
  }

  void write_outputs(const haptics::ServoStats& servo_stats) const {
    if (!o_.screenshot.empty())
      write_png_rgb(o_.screenshot, static_cast<std::size_t>(shot_w_), static_cast<std::size_t>(shot_h_), screenshot_);
    InteractiveRunInfo info;
    info.scene = o_.scene;
    info.backend = setup_.variant.label;
    info.device = o_.device;
    if (const auto* r = glGetString(GL_RENDERER)) info.gl_renderer = reinterpret_cast<const char*>(r);
    info.frames = static_cast<std::uint64_t>(frames_);
    info.wall_s = wall_s_;
    info.frame_ms = frame_ms_;
    info.upload_ms = upload_ms_;
    info.stamp_to_frame_ms = stamp_to_frame_ms_;
    info.stamp_to_take_ms = stamp_to_take_ms_;
    if (replay_) info.device_force_max_n = replay_->max_commanded_force_n();
    if (mouse_device_) info.device_force_max_n = mouse_device_->max_commanded_force_n();
    if (!o_.stats.empty())
      write_json_file(o_.stats, haptic_stats_json(servo_stats, setup_.limits, sim_.totals(), info));
  }

 private:
  void frame(bool last, double dt) {
    int fb_w = 0, fb_h = 0;
    glfwGetFramebufferSize(window_, &fb_w, &fb_h);
    handle_input(dt);
    // What the other threads published.
    if (servo_.to_display().update()) shown_ = servo_.to_display().front();
    take_surface();
    const SimStatus status = sim_.status();
    if (panel_.follow_tool && shown_.device.valid) {
      const Vec3 goal(shown_.device.position_m.x(), shown_.device.position_m.y(), shown_.model.surface_z_m);
      camera_.target += std::min(1.0, 4.0 * dt) * (goal - camera_.target);
    }
    if (o_.panel) show_panel(status);
    const Vec2 focus = shown_.device.valid ? Vec2(shown_.device.position_m.head<2>()) : Vec2(camera_.target.head<2>());
    view_->draw(camera_, fb_w, fb_h, panel_.wireframe, tool_overlay(controls_.tool, status.tool_heading_rad, shown_),
                focus);
    if (o_.panel) ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    if (last && !o_.screenshot.empty()) {
      screenshot_ = view_->read_pixels(fb_w, fb_h);
      shot_w_ = fb_w;
      shot_h_ = fb_h;
    }
    glfwSwapBuffers(window_);
    const double shown_s = steady_seconds();
    for (const double t : unshown_stamps_s_) stamp_to_frame_ms_.push_back(1e3 * (shown_s - t));
    unshown_stamps_s_.clear();
  }

  // Camera (right-drag orbits, wheel with ctrl or +/- zooms) and the mouse device.
  void handle_input(double dt) {
    int win_w = 0, win_h = 0;
    glfwGetWindowSize(window_, &win_w, &win_h);
    const ImGuiIO& io = ImGui::GetIO();
    double cx = 0.0, cy = 0.0;
    glfwGetCursorPos(window_, &cx, &cy);
    const bool right = glfwGetMouseButton(window_, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS && !io.WantCaptureMouse;
    if (right && dragging_) {
      camera_.yaw_rad -= 0.006 * (cx - last_x_);
      camera_.pitch_rad = std::clamp(camera_.pitch_rad + 0.006 * (cy - last_y_), 0.05, 1.55);
    }
    dragging_ = right;
    last_x_ = cx;
    last_y_ = cy;
    if (input_.scroll != 0.0) {
      if (input_.ctrl_scroll || !mouse_) {
        camera_.distance_m = std::clamp(camera_.distance_m * std::pow(0.9, input_.scroll), 0.02, 50.0);
      } else {
        mouse_->adjust_depth(-0.001 * input_.scroll);
      }
      input_.scroll = 0.0;
    }
    if (!io.WantCaptureKeyboard) {
      if (glfwGetKey(window_, GLFW_KEY_EQUAL) == GLFW_PRESS) camera_.distance_m *= std::pow(0.3, dt);
      if (glfwGetKey(window_, GLFW_KEY_MINUS) == GLFW_PRESS) camera_.distance_m /= std::pow(0.3, dt);
      if (mouse_ && glfwGetKey(window_, GLFW_KEY_DOWN) == GLFW_PRESS) mouse_->adjust_depth(0.01 * dt);
      if (mouse_ && glfwGetKey(window_, GLFW_KEY_UP) == GLFW_PRESS) mouse_->adjust_depth(-0.01 * dt);
    }
    if (mouse_) {
      std::optional<Ray> ray;
      if (!io.WantCaptureMouse && !right) ray = camera_.pixel_ray(cx, cy, win_w, win_h);
      mouse_->update(ray, glfwGetMouseButton(window_, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS && !io.WantCaptureMouse);
    }
  }

  // The feed's changed tiles (a lattice's or a mesh's) or its newest mesh, uploaded; the stamps they show.
  void take_surface() {
    DisplayFeed& feed = sim_.display();
    Stopwatch sw;
    bool uploaded = false;
    const std::vector<double>* stamp_times_s = &update_.stamp_times_s;
    if (feed.mesh_tiles() > 0) {
      uploaded = feed.take(mesh_update_);
      if (uploaded) view_->upload_mesh_tiles(mesh_update_);
      stamp_times_s = &mesh_update_.stamp_times_s;
    } else if (feed.take(update_)) {
      view_->upload_lattice(update_);
      uploaded = true;
    } else if (auto m = feed.mesh(); !feed.lattice() && m && m->version != mesh_version_) {
      view_->upload_mesh(m->mesh);
      mesh_version_ = m->version;
      uploaded = true;
    }
    if (uploaded) upload_ms_.push_back(1e3 * sw.seconds());
    const double taken_s = steady_seconds();
    for (const double t : *stamp_times_s) stamp_to_take_ms_.push_back(1e3 * (taken_s - t));
    unshown_stamps_s_.insert(unshown_stamps_s_.end(), stamp_times_s->begin(), stamp_times_s->end());
  }

  void show_panel(const SimStatus& status) {
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    PanelInput pin;
    pin.backend = setup_.variant.label;
    pin.device = setup_.device->name();
    pin.scene = o_.scene;
    if (replay_) pin.device_finished = replay_->finished();
    pin.mouse = mouse_.has_value();
    pin.mouse_depth_m = mouse_ ? mouse_->depth_m() : 0.0;
    pin.servo = &shown_;
    pin.limits = &setup_.limits;
    pin.status = &status;
    const PanelActions act = draw_panel(pin, controls_, panel_, setup_.prepared.scene.tool);
    if (act.controls_changed) sim_.set_controls(controls_);
    if (act.toggle_recording) {
      if (status.recording) {
        sim_.stop_recording();
      } else {
        sim_.start_recording(panel_.record_path);
      }
    }
    ImGui::Render();
  }

  const InteractiveOptions& o_;
  const InteractiveSetup& setup_;
  GLFWwindow* window_;
  WindowInput& input_;
  Simulation& sim_;
  haptics::ServoLoop& servo_;
  std::unique_ptr<TerrainView> view_;
  Camera camera_;
  haptics::SharedPoseDevice* mouse_device_ = nullptr;
  haptics::ReplayDevice* replay_ = nullptr;
  std::optional<MouseTool> mouse_;
  PanelState panel_;
  SimControls controls_;
  haptics::ServoState shown_;
  LatticeUpdate update_;
  MeshTileUpdate mesh_update_;
  std::uint64_t mesh_version_ = ~0ull;
  long frames_ = 0;
  double wall_s_ = 0.0;
  double last_x_ = 0.0, last_y_ = 0.0;
  bool dragging_ = false;
  std::vector<std::uint8_t> screenshot_;
  int shot_w_ = 0, shot_h_ = 0;
  std::vector<double> frame_ms_, upload_ms_, stamp_to_frame_ms_, stamp_to_take_ms_, unshown_stamps_s_;
};

}  // namespace

void run_interactive(const InteractiveOptions& o) {
  InteractiveSetup setup = prepare_interactive(o);
  GlfwSession glfw;
  GLFWwindow* window = open_window(o, "sandbench interactive - " + setup.variant.label + " - " + o.scene);
  WindowInput input;
  GuiSession gui(window, input);

  haptics::PatchBuffer patches;
  haptics::ServoOptions servo_options;
  servo_options.rate_hz = o.rate_hz;
  servo_options.spin_us = o.spin_us;
  servo_options.realtime = o.realtime;
  servo_options.rendering = setup.prepared.scene.haptics;
  haptics::ServoLoop servo(*setup.device, patches, servo_options);
  Simulation sim(setup.prepared, std::move(setup.terrain), patches, servo, setup.variant.label, !o.mesh_display);
  WindowLoop loop(o, setup, window, input, sim, servo);
  if (!o.record.empty()) sim.start_recording(o.record);
  servo.start();
  sim.start();
  try {
    loop.run();
  } catch (...) {
    servo.stop();
    sim.stop();
    throw;
  }
  servo.stop();  // first: the simulation then drains every recorded sample
  sim.stop();

  const haptics::ServoStats servo_stats = servo.stats();
  loop.write_outputs(servo_stats);
  std::cerr << "servo " << servo_stats.servo_hz << " Hz, tick p50 " << servo_stats.tick_us_p50 << " us, p99 "
            << servo_stats.tick_us_p99 << " us, max " << servo_stats.tick_us_max << " us, missed "
            << servo_stats.missed_deadlines << ", force max " << servo_stats.force_max_n << " N"
            << (servo_stats.realtime ? "" : " (no real-time priority)") << "\n";
  if (const std::string e = sim.recording_error(); !e.empty()) throw std::runtime_error("recording: " + e);
}

}  // namespace sb
