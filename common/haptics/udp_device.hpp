#pragma once
// UdpDevice: the bridge a real device's driver process uses (protocol in udp_protocol.hpp).
// Binds 127.0.0.1:PORT (0: any free port), non-blocking. read() drains every pending
// datagram and keeps the newest valid pose; command_force() sends one force packet to the
// sender of that pose. A pose older than stale_after_s makes the state invalid (zero force).
// Each call is a few system calls, no waiting.
#include <atomic>
#include <cstdint>

#include "common/haptics/device.hpp"
#include "common/haptics/udp_protocol.hpp"

namespace sb::haptics {

class UdpDevice final : public HapticDevice {
 public:
  // Throws InputError naming `option` when the port cannot be bound.
  UdpDevice(int port, const DeviceLimits& limits, const std::string& option = "--device udp:PORT",
            double stale_after_s = 0.25);
  ~UdpDevice() override;
  UdpDevice(const UdpDevice&) = delete;
  UdpDevice& operator=(const UdpDevice&) = delete;

  std::string name() const override { return "udp"; }
  DeviceLimits limits() const override { return limits_; }
  DeviceState read(double now_s) override;
  void command_force(const ForceCommand& command) override;

  int port() const { return port_; }  // the bound port
  // Readable from any thread.
  std::uint64_t poses_received() const { return poses_.load(std::memory_order_relaxed); }
  std::uint64_t packets_rejected() const { return rejected_.load(std::memory_order_relaxed); }
  std::uint64_t forces_sent() const { return sent_.load(std::memory_order_relaxed); }

 private:
  int fd_ = -1;
  int port_ = 0;
  DeviceLimits limits_;
  double stale_after_s_;
  // Servo thread only.
  udp::PosePacket last_{};
  double last_at_s_ = -1.0;  // servo time the newest pose arrived; < 0: none yet
  bool have_peer_ = false;
  alignas(8) unsigned char peer_[16] = {};  // sockaddr_in of the driver
  std::atomic<std::uint64_t> poses_{0}, rejected_{0}, sent_{0};
};

}  // namespace sb::haptics
