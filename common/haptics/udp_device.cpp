#include "common/haptics/udp_device.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "common/input_error.hpp"

namespace sb::haptics {

static_assert(sizeof(sockaddr_in) <= 16);

UdpDevice::UdpDevice(int port, const DeviceLimits& limits, const std::string& option, double stale_after_s)
    : limits_(limits), stale_after_s_(stale_after_s) {
  if (port < 0 || port > 65535) throw InputError(option + ": port " + std::to_string(port) + " is not in [0, 65535]");
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw InputError(option + ": cannot create a UDP socket: " + std::strerror(errno));
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    const std::string why = std::strerror(errno);
    ::close(fd_);
    throw InputError(option + ": cannot bind 127.0.0.1:" + std::to_string(port) + ": " + why);
  }
  socklen_t len = sizeof addr;
  ::getsockname(fd_, reinterpret_cast<sockaddr*>(&addr), &len);
  port_ = ntohs(addr.sin_port);
}

UdpDevice::~UdpDevice() {
  if (fd_ >= 0) ::close(fd_);
}

DeviceState UdpDevice::read(double now_s) {
  udp::Packet buf;
  sockaddr_in from{};
  // Drain: keep the newest valid pose (loopback delivers in order).
  for (int i = 0; i < 4096; ++i) {
    socklen_t len = sizeof from;
    const ssize_t n =
        ::recvfrom(fd_, buf.data(), buf.size(), MSG_DONTWAIT | MSG_TRUNC, reinterpret_cast<sockaddr*>(&from), &len);
    if (n < 0) break;  // EAGAIN: nothing more (other errors: try again next tick)
    const auto pose = static_cast<std::size_t>(n) == buf.size() ? udp::decode_pose(buf) : std::nullopt;
    if (!pose) {
      rejected_.fetch_add(1, std::memory_order_relaxed);
      continue;
    }
    last_ = *pose;
    last_at_s_ = now_s;
    std::memcpy(peer_, &from, sizeof from);
    have_peer_ = true;
    poses_.fetch_add(1, std::memory_order_relaxed);
  }
  DeviceState s;
  s.t_s = now_s;
  s.valid = last_at_s_ >= 0.0 && now_s - last_at_s_ <= stale_after_s_;
  s.position_m = limits_.workspace.clamp(last_.position_m);
  s.buttons = last_.buttons;
  return s;
}

void UdpDevice::command_force(const ForceCommand& c) {
  if (!have_peer_) return;
  udp::ForcePacket f;
  f.seq = last_.seq;
  f.t_s = c.t_s;
  f.force_n = c.force_n;
  f.flags =
      (c.in_contact ? udp::kFlagContact : 0u) | (c.clamped ? udp::kFlagClamped : 0u) | (c.stale ? udp::kFlagStale : 0u);
  f.max_force_n = static_cast<float>(limits_.max_force_n);
  const udp::Packet p = udp::encode(f);
  if (::sendto(fd_, p.data(), p.size(), MSG_DONTWAIT, reinterpret_cast<const sockaddr*>(peer_), sizeof(sockaddr_in)) ==
      static_cast<ssize_t>(p.size()))
    sent_.fetch_add(1, std::memory_order_relaxed);
}

}  // namespace sb::haptics
