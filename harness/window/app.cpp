// run_interactive: the window (GLFW, OpenGL 3.3, Dear ImGui) around the servo loop and the
// simulation thread. The window thread draws at display rate (capped at 60 Hz when the
// display does not pace swaps, as under Xvfb), moves the mouse device, shows the panel and
// hands control changes to the simulation.
#include <epoxy/gl.h>  // before GLFW: libepoxy loads the window's GL entry points
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <imgui.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <ctime>
#include <iostream>
#include <memory>
#include <optional>
#include <thread>

#include "common/haptics/replay_device.hpp"
#include "common/haptics/shared_pose_device.hpp"
#include "common/haptics/udp_device.hpp"
#include "common/input_error.hpp"
#include "common/png_io.hpp"
#include "harness/interactive/device.hpp"
#include "harness/interactive/stats.hpp"
#include "harness/run/backends.hpp"
#include "harness/run/variant.hpp"
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
      throw std::runtime_error("cannot open a window: GLFW found no display (is DISPLAY set? headless: xvfb-run -a)");
  }
  ~GlfwSession() { glfwTerminate(); }
};

}  // namespace

void run_interactive(const InteractiveOptions& o) {
  // Everything that can be wrong with the input is checked before a window opens: the
  // options one by one by CLI11 (harness/cli/interactive.cpp), here what they say together.
  if (!(o.spin_us <= 1e6 / o.rate_hz))
    throw InputError("--spin-us " + std::to_string(o.spin_us) +
                     " must be in [0, one period = " + std::to_string(1e6 / o.rate_hz) + "]");
  const Variant variant = parse_variant(o.backend);
  std::vector<std::string> overrides = o.overrides;
  overrides.insert(overrides.end(), variant.overrides.begin(), variant.overrides.end());
  const PreparedScene prepared = prepare_scene(load_scene(o.scene, overrides));
  const DeviceSpec device_spec = parse_device_spec(o.device);
  const haptics::DeviceLimits limits = scene_device_limits(prepared.initial, o.max_force_n, o.max_stiffness_n_per_m);
  std::unique_ptr<haptics::HapticDevice> device = make_device(device_spec, limits);
  if (auto* udp = dynamic_cast<haptics::UdpDevice*>(device.get()))
    std::cerr << "udp device: listening on 127.0.0.1:" << udp->port() << "\n";
  std::unique_ptr<Terrain> terrain = make_terrain(variant.backend, prepared.scene, prepared.initial);

  GlfwSession glfw;
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_SAMPLES, 0);
  const std::string title = "sandbench interactive - " + variant.label + " - " + o.scene;
  GLFWwindow* window = glfwCreateWindow(o.width, o.height, title.c_str(), nullptr, nullptr);
  if (!window) throw std::runtime_error("cannot open an OpenGL 3.3 core window");
  glfwMakeContextCurrent(window);
  glfwSwapInterval(1);
  if (epoxy_gl_version() < 33)
    throw std::runtime_error("the window's OpenGL is " + std::to_string(epoxy_gl_version() / 10) + "." +
                             std::to_string(epoxy_gl_version() % 10) + "; OpenGL 3.3 is needed");
  WindowInput input;
  glfwSetWindowUserPointer(window, &input);
  glfwSetScrollCallback(window, scroll_callback);  // before ImGui, which chains it

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;
  ImGui::StyleColorsDark();
  ImGui_ImplGlfw_InitForOpenGL(window, true);
  ImGui_ImplOpenGL3_Init("#version 330 core");

  // The GL objects and ImGui must go before the context does, whatever happens.
  struct Cleanup {
    GLFWwindow* w;
    ~Cleanup() {
      ImGui_ImplOpenGL3_Shutdown();
      ImGui_ImplGlfw_Shutdown();
      ImGui::DestroyContext();
      glfwDestroyWindow(w);
    }
  } cleanup{window};

  const Aabb2 box = prepared.scene.domain.box();
  const Vec2 centre = 0.5 * (box.lo + box.hi);
  const double z0 = prepared.initial(centre);
  auto view = std::make_unique<TerrainView>(Vec3(centre.x(), centre.y(), z0), limits.workspace.lo.z() + 0.1 - 0.02,
                                            limits.workspace.hi.z() - 0.1);
  Camera camera;
  camera.target = Vec3(centre.x(), centre.y(), z0);
  camera.distance_m = std::clamp(0.6 * (box.hi - box.lo).norm(), 0.1, 50.0);

  haptics::PatchBuffer patches;
  haptics::ServoOptions servo_options;
  servo_options.rate_hz = o.rate_hz;
  servo_options.spin_us = o.spin_us;
  servo_options.realtime = o.realtime;
  servo_options.rendering = prepared.scene.haptics;
  haptics::ServoLoop servo(*device, patches, servo_options);
  Simulation sim(prepared, std::move(terrain), patches, servo, variant.label);
  auto* mouse_device = dynamic_cast<haptics::SharedPoseDevice*>(device.get());
  std::optional<MouseTool> mouse;
  if (mouse_device) mouse.emplace(*mouse_device, prepared.initial);

  PanelState panel;
  panel.record_path = o.record.empty() ? default_record_path() : o.record;
  panel.tool_size_m = static_cast<float>(prepared.scene.tool.radius_m);
  SimControls controls = sim.controls();
  if (!o.record.empty()) sim.start_recording(o.record);
  if (mouse) mouse->update(std::nullopt, false);
  servo.start();
  sim.start();

  std::uint64_t mesh_version = ~0ull;
  long frame = 0;
  std::vector<std::uint8_t> screenshot;
  int shot_w = 0, shot_h = 0;
  double last_x = 0.0, last_y = 0.0;
  bool dragging = false;
  const auto opened = std::chrono::steady_clock::now();
  auto last_frame = opened;
  const auto frame_period = std::chrono::microseconds(16667);
  haptics::ServoState shown;
  try {
    while (true) {
      glfwPollEvents();
      const bool last = glfwWindowShouldClose(window) || (o.frames > 0 && frame + 1 >= o.frames);
      int fb_w = 0, fb_h = 0, win_w = 0, win_h = 0;
      glfwGetFramebufferSize(window, &fb_w, &fb_h);
      glfwGetWindowSize(window, &win_w, &win_h);
      const ImGuiIO& io = ImGui::GetIO();

      // Camera and mouse-device input.
      double cx = 0.0, cy = 0.0;
      glfwGetCursorPos(window, &cx, &cy);
      const bool right = glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS && !io.WantCaptureMouse;
      if (right && dragging) {
        camera.yaw_rad -= 0.006 * (cx - last_x);
        camera.pitch_rad = std::clamp(camera.pitch_rad + 0.006 * (cy - last_y), 0.05, 1.55);
      }
      dragging = right;
      last_x = cx;
      last_y = cy;
      const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - last_frame).count();
      if (input.scroll != 0.0) {
        if (input.ctrl_scroll || !mouse) {
          camera.distance_m = std::clamp(camera.distance_m * std::pow(0.9, input.scroll), 0.02, 50.0);
        } else {
          mouse->adjust_depth(-0.001 * input.scroll);
        }
        input.scroll = 0.0;
      }
      if (!io.WantCaptureKeyboard) {
        if (glfwGetKey(window, GLFW_KEY_EQUAL) == GLFW_PRESS) camera.distance_m *= std::pow(0.3, dt);
        if (glfwGetKey(window, GLFW_KEY_MINUS) == GLFW_PRESS) camera.distance_m /= std::pow(0.3, dt);
        if (mouse && glfwGetKey(window, GLFW_KEY_DOWN) == GLFW_PRESS) mouse->adjust_depth(0.01 * dt);
        if (mouse && glfwGetKey(window, GLFW_KEY_UP) == GLFW_PRESS) mouse->adjust_depth(-0.01 * dt);
      }
      if (mouse) {
        std::optional<Ray> ray;
        if (!io.WantCaptureMouse && !right) ray = camera.pixel_ray(cx, cy, win_w, win_h);
        mouse->update(ray, glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS && !io.WantCaptureMouse);
      }

      // What the other threads published.
      if (servo.to_display().update()) shown = servo.to_display().front();
      if (auto m = sim.mesh(); m && m->version != mesh_version) {
        view->upload_mesh(m->mesh);
        mesh_version = m->version;
      }
      const SimStatus status = sim.status();
      if (panel.follow_tool && shown.device.valid) {
        const Vec3 goal(shown.device.position_m.x(), shown.device.position_m.y(), shown.model.surface_z_m);
        camera.target += std::min(1.0, 4.0 * dt) * (goal - camera.target);
      }

      ImGui_ImplOpenGL3_NewFrame();
      ImGui_ImplGlfw_NewFrame();
      ImGui::NewFrame();
      PanelInput pin;
      pin.backend = variant.label;
      pin.device = device->name();
      pin.scene = o.scene;
      if (auto* replay = dynamic_cast<haptics::ReplayDevice*>(device.get())) pin.device_finished = replay->finished();
      pin.mouse = mouse.has_value();
      pin.mouse_depth_m = mouse ? mouse->depth_m() : 0.0;
      pin.servo = &shown;
      pin.limits = &limits;
      pin.status = &status;
      const PanelActions act = draw_panel(pin, controls, panel, prepared.scene.tool);
      if (act.controls_changed) sim.set_controls(controls);
      if (act.toggle_recording) {
        if (status.recording) {
          sim.stop_recording();
        } else {
          sim.start_recording(panel.record_path);
        }
      }
      ImGui::Render();

      view->draw(camera, fb_w, fb_h, panel.wireframe, tool_overlay(controls.tool, status.tool_heading_rad, shown));
      ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
      if (last && !o.screenshot.empty()) {
        screenshot = view->read_pixels(fb_w, fb_h);
        shot_w = fb_w;
        shot_h = fb_h;
      }
      glfwSwapBuffers(window);
      ++frame;
      // Pace at 60 Hz when swaps are not paced by the display.
      const auto next = last_frame + frame_period;
      if (std::chrono::steady_clock::now() < next) std::this_thread::sleep_until(next);
      last_frame = std::chrono::steady_clock::now();
      if (last) break;
    }
  } catch (...) {
    servo.stop();
    sim.stop();
    throw;
  }
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - opened).count();
  servo.stop();  // first: the simulation then drains every recorded sample
  sim.stop();

  if (!o.screenshot.empty())
    write_png_rgb(o.screenshot, static_cast<std::size_t>(shot_w), static_cast<std::size_t>(shot_h), screenshot);
  const haptics::ServoStats servo_stats = servo.stats();
  InteractiveRunInfo info;
  info.scene = o.scene;
  info.backend = variant.label;
  info.device = o.device;
  info.frames = static_cast<std::uint64_t>(frame);
  info.wall_s = wall_s;
  if (auto* replay = dynamic_cast<haptics::ReplayDevice*>(device.get()))
    info.device_force_max_n = replay->max_commanded_force_n();
  if (mouse_device) info.device_force_max_n = mouse_device->max_commanded_force_n();
  const Json stats = haptic_stats_json(servo_stats, limits, sim.totals(), info);
  if (!o.stats.empty()) write_json_file(o.stats, stats);
  std::cerr << "servo " << servo_stats.servo_hz << " Hz, tick p50 " << servo_stats.tick_us_p50 << " us, p99 "
            << servo_stats.tick_us_p99 << " us, max " << servo_stats.tick_us_max << " us, missed "
            << servo_stats.missed_deadlines << ", force max " << servo_stats.force_max_n << " N"
            << (servo_stats.realtime ? "" : " (no real-time priority)") << "\n";
  if (const std::string e = sim.recording_error(); !e.empty()) throw std::runtime_error("recording: " + e);
}

}  // namespace sb
