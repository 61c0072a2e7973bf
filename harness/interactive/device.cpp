#include "harness/interactive/device.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "common/haptics/replay_device.hpp"
#include "common/haptics/shared_pose_device.hpp"
#include "common/haptics/udp_device.hpp"
#include "common/input_error.hpp"

namespace sb {

DeviceSpec parse_device_spec(const std::string& text) {
  DeviceSpec s;
  s.text = text;
  const std::string allowed = "; must be mouse, replay:FILE or udp:PORT";
  if (text == "mouse") {
    s.kind = DeviceSpec::Kind::Mouse;
  } else if (text.rfind("replay:", 0) == 0) {
    s.kind = DeviceSpec::Kind::Replay;
    s.file = text.substr(7);
    if (s.file.empty()) throw InputError("--device " + text + ": no replay file given" + allowed);
  } else if (text.rfind("udp:", 0) == 0) {
    s.kind = DeviceSpec::Kind::Udp;
    const std::string port = text.substr(4);
    char* end = nullptr;
    const long p = std::strtol(port.c_str(), &end, 10);
    if (port.empty() || *end != '\0' || p < 1 || p > 65535)
      throw InputError("--device " + text + ": port '" + port + "' is not an integer in [1, 65535]");
    s.port = static_cast<int>(p);
  } else {
    throw InputError("--device " + text + " is not a device" + allowed);
  }
  return s;
}

haptics::DeviceLimits scene_device_limits(const HeightField& initial, double max_force_n, double max_stiffness_n_per_m,
                                          double max_speed_m_s) {
  if (!(max_force_n > 0.0) || !std::isfinite(max_force_n))
    throw InputError("--max-force-n " + std::to_string(max_force_n) + " must be a finite number > 0");
  if (!(max_stiffness_n_per_m > 0.0) || !std::isfinite(max_stiffness_n_per_m))
    throw InputError("--max-stiffness " + std::to_string(max_stiffness_n_per_m) + " must be a finite number > 0");
  if (!(max_speed_m_s > 0.0) || !std::isfinite(max_speed_m_s))
    throw InputError("--max-speed " + std::to_string(max_speed_m_s) + " must be a finite number > 0");
  haptics::DeviceLimits l;
  l.max_force_n = max_force_n;
  l.max_speed_m_s = max_speed_m_s;
  l.max_stiffness_n_per_m = max_stiffness_n_per_m;
  const Aabb2 box = initial.domain().box();
  double zlo = 1e300, zhi = -1e300;
  const int n = 64;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const Vec2 p = box.lo + (box.hi - box.lo).cwiseProduct(Vec2(double(i) / n, double(j) / n));
      const double z = initial(p);
      zlo = std::min(zlo, z);
      zhi = std::max(zhi, z);
    }
  const double margin = 0.05;
  l.workspace.lo = Vec3(box.lo.x() - margin, box.lo.y() - margin, zlo - 0.1);
  l.workspace.hi = Vec3(box.hi.x() + margin, box.hi.y() + margin, zhi + 0.1);
  return l;
}

std::unique_ptr<haptics::HapticDevice> make_device(const DeviceSpec& spec, const haptics::DeviceLimits& limits) {
  switch (spec.kind) {
    case DeviceSpec::Kind::Mouse:
      return std::make_unique<haptics::SharedPoseDevice>("mouse", limits);
    case DeviceSpec::Kind::Replay: {
      haptics::Trajectory t;
      try {
        t = haptics::load_trajectory(spec.file);
      } catch (const InputError& e) {
        throw InputError("--device " + spec.text + ": " + e.what());
      }
      return std::make_unique<haptics::ReplayDevice>(std::move(t), limits);
    }
    case DeviceSpec::Kind::Udp:
      return std::make_unique<haptics::UdpDevice>(spec.port, limits, "--device " + spec.text);
  }
  return nullptr;
}

}  // namespace sb
