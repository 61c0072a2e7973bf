#pragma once
// How the servo turns the force model's output into the force it sends (scene keys
// [haptics], README "Interactive mode and haptics"). Plain data: the scene reads it, the
// servo uses it.
//
// - Patch blending (Mark et al. 1996): a new height patch changes the model's force at the
//   tool's unchanged position; the servo carries that jump as an offset and fades it out
//   linearly over blend_s, so the surface the hand feels moves from the old patch to the new
//   one continuously instead of in one tick (the tool's own stamp then feels like sand giving
//   way, not like a click).
// - Force-rate limit, a fault guard: no tick changes the commanded force by more than
//   max_force_rate_n_per_s / servo rate. The force model is continuous in the tool's pose
//   (force_model.hpp) and the blend covers patch swaps, so on smooth motion the limit never
//   acts; it only catches what a fault would send (a corrupt patch, a pose jump). Losing the
//   pose still drops the force to zero at once.
// - Passivity (Hannaford and Ryu 2002): an observer sums the energy the device delivered to the
//   hand; a controller adds just enough damping (at most passivity_max_force_n) whenever the
//   next tick would make that sum positive.
// - Virtual coupling (Adams and Hannaford 1999), off by default: the force model acts on a
//   simulated tool (mass tool_mass_kg) tied to the device by a spring-damper, so the device
//   never renders more than coupling_stiffness_n_per_m whatever the sand's stiffness.
namespace sb::haptics {

struct RenderingOptions {
  double blend_s = 0.05;                       // haptics.blend_ms; 0: patches switch at once
  double max_force_rate_n_per_s = 2000.0;      // haptics.max_force_rate_n_per_s; 0: unlimited
  bool passivity = true;                       // haptics.passivity_control
  double passivity_max_force_n = 1.0;          // haptics.passivity_max_force_n
  bool coupling = false;                       // haptics.coupling
  double coupling_stiffness_n_per_m = 1000.0;  // haptics.coupling_stiffness_n_per_m
  double coupling_damping_n_s_per_m = 2.0;     // haptics.coupling_damping_n_s_per_m
  double tool_mass_kg = 0.02;                  // haptics.tool_mass_kg
};

}  // namespace sb::haptics
