#pragma once
// HapticDevice: what the servo loop talks to. Pose and buttons in, force out, and the
// device's limits. read() and command_force() are called from the 1 kHz servo thread: they
// must never block and should cost microseconds. One virtual call each per tick.
#include <algorithm>
#include <cstdint>
#include <string>

#include "common/geometry.hpp"

namespace sb::haptics {

struct Aabb3 {
  Vec3 lo{0.0, 0.0, 0.0};
  Vec3 hi{0.0, 0.0, 0.0};
  bool contains(const Vec3& p) const { return (p.array() >= lo.array()).all() && (p.array() <= hi.array()).all(); }
  Vec3 clamp(const Vec3& p) const { return p.cwiseMax(lo).cwiseMin(hi); }
};

struct DeviceLimits {
  double max_force_n = 8.0;               // largest force magnitude the device may be sent
  double max_stiffness_n_per_m = 2000.0;  // largest spring constant it renders stably
  Aabb3 workspace;                        // reachable tool positions, world metres
  // The fastest the tool can physically move (a hand on a desktop device). A pose that moved
  // farther within one servo tick is a fault of the pose stream (dropped, reordered or corrupt
  // packets), not motion: the servo restarts its rendering at the new pose (servo_core.hpp).
  double max_speed_m_s = 2.0;
};

// One reading of the device. The position is the tool's lowest point (the bottom of its
// footprint) in world coordinates, already clamped to the workspace.
struct DeviceState {
  double t_s = 0.0;  // device time of the pose, seconds
  Vec3 position_m{0.0, 0.0, 0.0};
  std::uint32_t buttons = 0;  // bit mask; bit 0 is the primary button
  bool valid = false;         // false while the device has no pose (no force is sent)
};

// One force command: the force in newtons (world axes), already finite and within the
// device's limits, and what the servo knew when it computed it.
struct ForceCommand {
  Vec3 force_n{0.0, 0.0, 0.0};
  double t_s = 0.0;         // servo time
  bool in_contact = false;  // the tool displaces sand
  bool clamped = false;     // the force model asked for more than max_force_n
  bool stale = false;       // no valid pose: the force is zero
};

class HapticDevice {
 public:
  virtual ~HapticDevice() = default;
  virtual std::string name() const = 0;
  virtual DeviceLimits limits() const = 0;
  // Called by the servo thread when it starts; now_s = 0 from then on.
  virtual void start() {}
  // The newest pose at servo time now_s (seconds since start()). Never blocks.
  virtual DeviceState read(double now_s) = 0;
  // Sends a force to the device. Never blocks.
  virtual void command_force(const ForceCommand& command) = 0;
};

}  // namespace sb::haptics
