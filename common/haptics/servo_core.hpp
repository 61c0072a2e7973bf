#pragma once
// ServoCore: one servo tick without the clock -- read the device, estimate its velocity (a
// pose step faster than the device's max_speed_m_s restarts the rendering there, as a pose
// lost and found again: it is not motion, so it moves no velocity estimate and books no work), take
// the newest height patch, compute the force, render it (rendering.hpp: blend across patches,
// optional virtual coupling, passivity control, force-rate limit), make it safe (finite,
// within the device's force limit) and command it. ServoLoop calls it at 1 kHz; tests and
// benchmarks call it directly. A tick costs two virtual calls, one atomic load (two atomic
// exchanges when a patch arrives) and the force model (twice when a patch arrives: once on
// each patch, for the blend).
#include <cstdint>

#include "common/haptics/device.hpp"
#include "common/haptics/force_blend.hpp"
#include "common/haptics/force_model.hpp"
#include "common/haptics/height_patch.hpp"
#include "common/haptics/passivity.hpp"
#include "common/haptics/rendering.hpp"
#include "common/haptics/virtual_coupling.hpp"

namespace sb::haptics {

// What one tick produced; the servo publishes it to the simulation and the display.
struct ServoState {
  std::uint64_t tick = 0;
  double t_s = 0.0;
  DeviceState device;
  Vec3 velocity_m_s{0.0, 0.0, 0.0};
  Vec3 force_n{0.0, 0.0, 0.0};  // as commanded
  ForceOutput model;            // the model's view (its force before rendering and limiting)
  // The model's force at this pose on the patches the servo holds, the blend's offset
  // included: what would be sent without coupling, rate limit, passivity control and the
  // device's force limit. The force sent is judged against it.
  Vec3 model_force_n{0.0, 0.0, 0.0};
  bool clamped = false;
  bool nonfinite = false;  // the model's force was not finite; zero was sent
  std::uint64_t patch_version = 0;
  // Rendering (rendering.hpp).
  Vec3 tool_position_m{0.0, 0.0, 0.0};    // where the model was evaluated: the device, or the coupled tool
  Vec3 tool_velocity_m_s{0.0, 0.0, 0.0};  // the velocity it was evaluated with (that point's)
  Vec3 blend_offset_n{0.0, 0.0, 0.0};     // what is left of earlier patches' forces
  bool patch_switched = false;            // a new patch arrived this tick
  bool rate_limited = false;              // the force-rate limit held the force back
  bool passivity_active = false;          // the passivity controller added damping
  bool passivity_bounded = false;         // its energy bound scaled the force down
  bool pose_jump = false;                 // the pose moved faster than the device's max_speed_m_s: rendering restarted
  double passivity_energy_j = 0.0;        // the observer's energy so far (> 0: energy created)
  double force_step_n = 0.0;              // |force - force of the previous tick|
  // Running counters of the loop (filled by ServoLoop).
  std::uint64_t missed_deadlines = 0;
  double tick_us = 0.0, tick_us_max = 0.0, servo_hz = 0.0, force_max_n = 0.0;
};

class ServoCore {
 public:
  // velocity_cutoff_hz: first-order low-pass on the differentiated position. period_s: the
  // servo's nominal period; the force-rate limit allows rate * period per tick, and the fades
  // advance by at most one period per tick (a late tick does not jump).
  ServoCore(HapticDevice& device, PatchBuffer& patches, double velocity_cutoff_hz = 40.0,
            const RenderingOptions& rendering = {}, double period_s = 0.001);

  void start() { device_.start(); }
  ServoState step(double now_s);
  const DeviceLimits& limits() const { return limits_; }
  const RenderingOptions& rendering() const { return rendering_; }
  const PassivityController& passivity() const { return passivity_; }
  HapticDevice& device() { return device_; }

 private:
  Vec3 render(ServoState& s, double dt);
  void restart_rendering();  // no pose, or a pose jump: every rendering state starts afresh

  HapticDevice& device_;
  PatchBuffer& patches_;
  DeviceLimits limits_;
  double cutoff_hz_;
  RenderingOptions rendering_;
  double period_s_;
  std::uint64_t tick_ = 0;
  bool have_prev_ = false;
  Vec3 prev_position_{0.0, 0.0, 0.0};
  double prev_t_s_ = 0.0;
  Vec3 velocity_{0.0, 0.0, 0.0};
  Vec3 last_force_{0.0, 0.0, 0.0};     // commanded last tick
  Vec3 last_rendered_{0.0, 0.0, 0.0};  // last tick's force before passivity control
  ForceBlend blend_;
  PassivityController passivity_;
  VirtualCoupling coupling_;
};

}  // namespace sb::haptics
