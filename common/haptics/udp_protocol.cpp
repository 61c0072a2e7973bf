#include "common/haptics/udp_protocol.hpp"

#include <bit>
#include <cmath>
#include <cstring>

namespace sb::haptics::udp {

static_assert(std::endian::native == std::endian::little, "the UDP protocol is little-endian; add byte swaps");

namespace {

template <class T>
void put(Packet& p, std::size_t at, T v) {
  std::memcpy(p.data() + at, &v, sizeof v);
}
template <class T>
T get(std::span<const std::uint8_t> b, std::size_t at) {
  T v;
  std::memcpy(&v, b.data() + at, sizeof v);
  return v;
}

}  // namespace

Packet encode(const PosePacket& p) {
  Packet out{};
  put(out, 0, kPoseMagic);
  put(out, 4, p.seq);
  put(out, 8, p.t_s);
  put(out, 16, p.position_m.x());
  put(out, 24, p.position_m.y());
  put(out, 32, p.position_m.z());
  put(out, 40, p.buttons);
  put(out, 44, std::uint32_t{0});
  return out;
}

Packet encode(const ForcePacket& p) {
  Packet out{};
  put(out, 0, kForceMagic);
  put(out, 4, p.seq);
  put(out, 8, p.t_s);
  put(out, 16, p.force_n.x());
  put(out, 24, p.force_n.y());
  put(out, 32, p.force_n.z());
  put(out, 40, p.flags);
  put(out, 44, p.max_force_n);
  return out;
}

std::optional<PosePacket> decode_pose(std::span<const std::uint8_t> b) {
  if (b.size() != kPacketBytes || get<std::uint32_t>(b, 0) != kPoseMagic) return std::nullopt;
  PosePacket p;
  p.seq = get<std::uint32_t>(b, 4);
  p.t_s = get<double>(b, 8);
  p.position_m = {get<double>(b, 16), get<double>(b, 24), get<double>(b, 32)};
  p.buttons = get<std::uint32_t>(b, 40);
  if (!std::isfinite(p.t_s) || !p.position_m.allFinite()) return std::nullopt;
  return p;
}

std::optional<ForcePacket> decode_force(std::span<const std::uint8_t> b) {
  if (b.size() != kPacketBytes || get<std::uint32_t>(b, 0) != kForceMagic) return std::nullopt;
  ForcePacket p;
  p.seq = get<std::uint32_t>(b, 4);
  p.t_s = get<double>(b, 8);
  p.force_n = {get<double>(b, 16), get<double>(b, 24), get<double>(b, 32)};
  p.flags = get<std::uint32_t>(b, 40);
  p.max_force_n = get<float>(b, 44);
  if (!std::isfinite(p.t_s) || !p.force_n.allFinite()) return std::nullopt;
  return p;
}

}  // namespace sb::haptics::udp
