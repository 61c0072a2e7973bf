#pragma once
// The interactive window's Dear ImGui panel: back-end, model counts and memory, step times,
// the servo's rate and the force (vector and magnitude), material sliders, the tool choice,
// pause / erosion / simplification toggles and the record button. Draws and edits; the app
// applies what changed. ImGui calls only: O(1) per frame.
#include <string>

#include "common/haptics/servo_core.hpp"
#include "harness/interactive/sim.hpp"

namespace sb {

enum class ToolChoice { Scene, Disk, Box, Ellipse, Sphere, Pour };

// The window's own state that the panel edits.
struct PanelState {
  ToolChoice tool = ToolChoice::Scene;
  float tool_size_m = 0.02f;  // radius, or half the box/ellipse length
  bool wireframe = false;
  bool follow_tool = false;
  std::string record_path;  // where the record button writes
};

struct PanelInput {
  std::string backend, device, scene;
  bool device_finished = false;  // a replay that reached its end
  double mouse_depth_m = 0.0;
  bool mouse = false;
  const haptics::ServoState* servo = nullptr;
  const haptics::DeviceLimits* limits = nullptr;
  const SimStatus* status = nullptr;
};

struct PanelActions {
  bool controls_changed = false;
  bool toggle_recording = false;
};

// Builds the tool for a panel choice from the scene's tool (Scene keeps it as it is).
ToolSpec panel_tool(ToolChoice choice, double size_m, const ToolSpec& scene_tool);

PanelActions draw_panel(const PanelInput& in, SimControls& controls, PanelState& state, const ToolSpec& scene_tool);

}  // namespace sb
