#pragma once
// The interactive app's devices: parsing --device (mouse | replay:FILE | udp:PORT), the
// default limits for a scene, and making the device. GL-free: the mouse is a
// SharedPoseDevice that the window's input code moves.
#include <memory>
#include <string>

#include "common/haptics/device.hpp"
#include "common/height_field.hpp"

namespace sb {

struct DeviceSpec {
  enum class Kind { Mouse, Replay, Udp } kind = Kind::Mouse;
  std::string file;  // replay
  int port = 0;      // udp
  std::string text;  // as given
};

// Throws InputError naming --device.
DeviceSpec parse_device_spec(const std::string& text);

// Limits for a scene: the given force, stiffness and speed limits, and a workspace covering the
// domain (plus 5 cm) from 10 cm below the lowest initial surface to 10 cm above the highest.
// Throws InputError naming --max-force-n / --max-stiffness / --max-speed for non-positive values.
haptics::DeviceLimits scene_device_limits(const HeightField& initial, double max_force_n, double max_stiffness_n_per_m,
                                          double max_speed_m_s = haptics::DeviceLimits{}.max_speed_m_s);

// Loads the replay file or binds the UDP port (InputError naming --device on failure).
std::unique_ptr<haptics::HapticDevice> make_device(const DeviceSpec& spec, const haptics::DeviceLimits& limits);

}  // namespace sb
