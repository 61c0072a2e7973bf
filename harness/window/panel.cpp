#include "harness/window/panel.hpp"

#include <imgui.h>

#include <cmath>
#include <numbers>

namespace sb {

ToolSpec panel_tool(ToolChoice choice, double size_m, const ToolSpec& scene_tool) {
  if (choice == ToolChoice::Scene) return scene_tool;
  ToolSpec t;
  t.rim = scene_tool.rim;
  t.rim.width_m = 0.5 * size_m;
  t.depth_m = scene_tool.depth_m;
  t.radius_m = size_m;
  t.half_size_m = Vec2(size_m, 0.5 * size_m);
  switch (choice) {
    case ToolChoice::Disk:
      t.shape = ToolShape::Disk;
      break;
    case ToolChoice::Box:
      t.shape = ToolShape::Box;
      t.rim.width_m = 0.25 * size_m;
      break;
    case ToolChoice::Ellipse:
      t.shape = ToolShape::Ellipse;
      t.rim.width_m = 0.25 * size_m;
      break;
    case ToolChoice::Sphere:
      t.shape = ToolShape::Disk;
      t.profile = BottomProfile::SphereCap;
      t.sphere_radius_m = size_m;
      break;
    case ToolChoice::Pour:
      t.shape = ToolShape::Pour;
      t.pour_volume_m3 =
          scene_tool.shape == ToolShape::Pour ? scene_tool.pour_volume_m3 : std::numbers::pi * size_m * size_m * 0.002;
      break;
    case ToolChoice::Scene:
      break;
  }
  return t;
}

namespace {

bool slider(const char* label, double& value, double lo, double hi, const char* format) {
  float v = static_cast<float>(value);
  if (!ImGui::SliderFloat(label, &v, static_cast<float>(lo), static_cast<float>(hi), format)) return false;
  value = v;
  return true;
}

}  // namespace

PanelActions draw_panel(const PanelInput& in, SimControls& c, PanelState& state, const ToolSpec& scene_tool) {
  PanelActions act;
  const SimStatus& st = *in.status;
  const haptics::ServoState& sv = *in.servo;
  ImGui::SetNextWindowPos(ImVec2(10, 10), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(370, 0), ImGuiCond_FirstUseEver);
  ImGui::Begin("sandbench");
  ImGui::Text("back-end %s   device %s%s", in.backend.c_str(), in.device.c_str(), in.device_finished ? " (ended)" : "");
  ImGui::TextDisabled("%s", in.scene.c_str());

  if (ImGui::CollapsingHeader("Model", ImGuiTreeNodeFlags_DefaultOpen)) {
    ImGui::Text("vertices %zu  triangles %zu", st.stats.vertices, st.stats.triangles);
    ImGui::Text("cells %zu  constrained edges %zu", st.stats.cells, st.stats.constrained_edges);
    ImGui::Text("memory %.2f MB   active %zu", st.stats.bytes / 1048576.0, st.stats.active);
    const double drift = st.volume_initial_m3 != 0.0
                             ? (st.volume_m3 - st.volume_initial_m3 - st.volume_added_m3) / st.volume_initial_m3
                             : 0.0;
    ImGui::Text("volume %.6f m3   drift %.2e", st.volume_m3, drift);
    ImGui::Text("steps %llu  stamps %llu  patches %llu", static_cast<unsigned long long>(st.steps),
                static_cast<unsigned long long>(st.stamps), static_cast<unsigned long long>(st.patches));
    ImGui::Text("step ms: tool %.2f  erosion %.2f  simplify %.2f", st.tool_ms, st.erosion_ms, st.simplify_ms);
    ImGui::Text("step ms p50 %.2f  p95 %.2f   patch %.3f ms", st.step_ms_p50, st.step_ms_p95, st.patch_ms);
  }

  if (ImGui::CollapsingHeader("Haptics", ImGuiTreeNodeFlags_DefaultOpen)) {
    ImGui::Text("servo %.1f Hz   tick %.1f us (max %.1f)", sv.servo_hz, sv.tick_us, sv.tick_us_max);
    ImGui::Text("missed deadlines %llu", static_cast<unsigned long long>(sv.missed_deadlines));
    const Vec3& f = sv.force_n;
    ImGui::Text("force (%.2f, %.2f, %.2f) N", f.x(), f.y(), f.z());
    const double limit = in.limits->max_force_n;
    char label[64];
    std::snprintf(label, sizeof label, "|F| %.2f N of %.1f", f.norm(), limit);
    ImGui::ProgressBar(static_cast<float>(f.norm() / limit), ImVec2(-1, 0), label);
    ImGui::Text("penetration %.2f mm  contact %.0f%%%s", 1e3 * sv.model.penetration_m,
                100.0 * sv.model.contact_fraction, sv.clamped ? "  CLAMPED" : "");
    const Vec3& p = sv.device.position_m;
    ImGui::Text("tool (%.3f, %.3f, %.3f) m%s", p.x(), p.y(), p.z(), sv.device.valid ? "" : "  no pose");
    if (in.mouse) {
      ImGui::PushTextWrapPos(0.0f);
      ImGui::TextDisabled("mouse: depth %.1f mm (wheel, Up/Down); right-drag orbits, ctrl+wheel zooms",
                          1e3 * in.mouse_depth_m);
      ImGui::PopTextWrapPos();
    }
  }

  if (ImGui::CollapsingHeader("Material", ImGuiTreeNodeFlags_DefaultOpen)) {
    act.controls_changed |= slider("critical angle", c.material.critical_angle_deg, 5.0, 80.0, "%.1f deg");
    act.controls_changed |= slider("transfer", c.material.transfer_fraction, 0.05, 1.0, "%.2f");
    act.controls_changed |= slider("stiffness", c.material.stiffness_n_per_m, 0.0, 5000.0, "%.0f N/m");
    act.controls_changed |= slider("drag", c.material.drag_n_s_per_m, 0.0, 50.0, "%.1f N s/m");
    act.controls_changed |= slider("friction", c.material.friction, 0.0, 2.0, "%.2f");
  }

  if (ImGui::CollapsingHeader("Tool", ImGuiTreeNodeFlags_DefaultOpen)) {
    const char* names[] = {"scene tool", "disk", "box", "ellipse", "sphere tip", "pour"};
    int choice = static_cast<int>(state.tool);
    bool tool_changed = ImGui::Combo("tool", &choice, names, IM_ARRAYSIZE(names));
    state.tool = static_cast<ToolChoice>(choice);
    if (state.tool != ToolChoice::Scene)
      tool_changed |= ImGui::SliderFloat("size", &state.tool_size_m, 0.003f, 0.08f, "%.3f m");
    if (tool_changed) {
      c.tool = panel_tool(state.tool, state.tool_size_m, scene_tool);
      act.controls_changed = true;
    }
  }

  if (ImGui::CollapsingHeader("Simulation", ImGuiTreeNodeFlags_DefaultOpen)) {
    act.controls_changed |= ImGui::Checkbox("pause", &c.paused);
    ImGui::SameLine();
    act.controls_changed |= ImGui::Checkbox("erosion", &c.erosion);
    ImGui::SameLine();
    act.controls_changed |= ImGui::Checkbox("simplification", &c.simplify);
    int budget = static_cast<int>(c.erosion_updates);
    if (ImGui::SliderInt("erosion budget", &budget, 1000, 500000, "%d visits/step")) {
      c.erosion_updates = static_cast<std::size_t>(budget);
      act.controls_changed = true;
    }
    ImGui::Checkbox("wireframe", &state.wireframe);
    ImGui::SameLine();
    ImGui::Checkbox("follow tool", &state.follow_tool);
  }

  if (ImGui::Button(st.recording ? "Stop recording" : "Record")) act.toggle_recording = true;
  ImGui::SameLine();
  if (st.recording)
    ImGui::Text("%zu samples, %zu stamps", st.recorded_samples, st.recorded_stamps);
  else
    ImGui::TextDisabled("to %s", state.record_path.c_str());
  if (!st.message.empty()) ImGui::TextWrapped("%s", st.message.c_str());
  ImGui::End();
  return act;
}

}  // namespace sb
