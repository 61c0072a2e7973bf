#pragma once
// The UDP bridge's wire format (README "Interactive mode and haptics"): fixed 48-byte
// little-endian datagrams on loopback. A device driver sends pose packets to sandbench's port;
// sandbench answers every servo tick with a force packet to the address of the latest pose.
//
//   pose  (driver -> sandbench)          force (sandbench -> driver)
//   0  u32  magic 0x31504253 "SBP1"      0  u32  magic 0x31464253 "SBF1"
//   4  u32  sequence number              4  u32  sequence of the pose it answers
//   8  f64  driver time, s               8  f64  servo time, s
//   16 f64  x, m  (world, tool bottom)   16 f64  fx, N
//   24 f64  y, m                         24 f64  fy, N
//   32 f64  z, m                         32 f64  fz, N
//   40 u32  buttons (bit 0 primary)      40 u32  flags: 1 in contact, 2 clamped, 4 stale
//   44 u32  reserved, 0                  44 f32  the force limit in use, N
// Encoding and decoding are a few memcpys; decode rejects wrong sizes, magics and non-finite
// numbers.
#include <array>
#include <cstdint>
#include <optional>
#include <span>

#include "common/geometry.hpp"

namespace sb::haptics::udp {

inline constexpr std::size_t kPacketBytes = 48;
inline constexpr std::uint32_t kPoseMagic = 0x31504253;   // "SBP1"
inline constexpr std::uint32_t kForceMagic = 0x31464253;  // "SBF1"
inline constexpr std::uint32_t kFlagContact = 1, kFlagClamped = 2, kFlagStale = 4;

struct PosePacket {
  std::uint32_t seq = 0;
  double t_s = 0.0;
  Vec3 position_m{0.0, 0.0, 0.0};
  std::uint32_t buttons = 0;
};

struct ForcePacket {
  std::uint32_t seq = 0;
  double t_s = 0.0;
  Vec3 force_n{0.0, 0.0, 0.0};
  std::uint32_t flags = 0;
  float max_force_n = 0.0f;
};

using Packet = std::array<std::uint8_t, kPacketBytes>;

Packet encode(const PosePacket& p);
Packet encode(const ForcePacket& p);
std::optional<PosePacket> decode_pose(std::span<const std::uint8_t> bytes);
std::optional<ForcePacket> decode_force(std::span<const std::uint8_t> bytes);

}  // namespace sb::haptics::udp
