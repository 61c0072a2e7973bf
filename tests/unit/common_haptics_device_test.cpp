// Devices: the replay file and its player, the UDP protocol and bridge on loopback.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <limits>
#include <thread>

#include "common/haptics/replay_device.hpp"
#include "common/haptics/shared_pose_device.hpp"
#include "common/haptics/udp_device.hpp"
#include "common/input_error.hpp"

namespace sb::haptics {
namespace {

DeviceLimits roomy() {
  DeviceLimits l;
  l.workspace.lo = Vec3(-1.0, -1.0, -1.0);
  l.workspace.hi = Vec3(1.0, 1.0, 1.0);
  return l;
}

std::string input_error(const std::string& text) {
  try {
    trajectory_from(parse_csv_tables(text, "traj.csv"));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(HapticsTrajectory, ParsesTheReplayFormatWithCommentsAndLaterTables) {
  const Trajectory t = trajectory_from(
      parse_csv_tables("# a comment\n\nt,x,y,z,buttons\n0,0.1,0.2,0.3,0\n0.5, 0.2 ,0.2,0.25,1\n1.0,0.3,0.2,0.2,3\n"
                       "stamp,t,x\n0,1,2\n",
                       "traj.csv"));
  ASSERT_EQ(t.samples.size(), 3u);
  EXPECT_EQ(t.samples[1].position_m, Vec3(0.2, 0.2, 0.25));
  EXPECT_EQ(t.samples[2].buttons, 3u);
  EXPECT_DOUBLE_EQ(t.duration_s(), 1.0);
}

TEST(HapticsTrajectory, BadFilesNameFileLineAndColumn) {
  EXPECT_NE(input_error("time,x,y,z,buttons\n0,0,0,0,0\n").find("t,x,y,z,buttons"), std::string::npos);
  EXPECT_NE(input_error("t,x,y,z,buttons\n").find("no rows"), std::string::npos);
  const std::string nan = input_error("t,x,y,z,buttons\n0,0,0,0,0\n1,nan,0,0,0\n");
  EXPECT_NE(nan.find("traj.csv:3"), std::string::npos) << nan;
  EXPECT_NE(nan.find("column x"), std::string::npos) << nan;
  EXPECT_NE(input_error("t,x,y,z,buttons\n1,0,0,0,0\n0.5,0,0,0,0\n").find("back in time"), std::string::npos);
  EXPECT_NE(input_error("t,x,y,z,buttons\n0,0,0,0\n").find("has 4 fields"), std::string::npos);
  EXPECT_NE(input_error("t,x,y,z,buttons\n0,0,0,0,-1\n").find("column buttons"), std::string::npos);
  EXPECT_NE(input_error("0,0,0,0,0\n").find("before any header"), std::string::npos);
  EXPECT_THROW(load_trajectory("/nonexistent/replay.csv"), InputError);
}

TEST(HapticsReplay, InterpolatesHoldsTheEndAndClampsToTheWorkspace) {
  Trajectory t;
  t.samples = {{10.0, Vec3(0.0, 0.0, 0.0), 0}, {11.0, Vec3(1.0, 0.5, -0.5), 1}, {12.0, Vec3(5.0, 0.5, -0.5), 2}};
  DeviceLimits limits = roomy();
  ReplayDevice d(t, limits);
  d.start();
  DeviceState s = d.read(0.0);  // time 0 plays the first sample, whatever its t
  EXPECT_TRUE(s.valid);
  EXPECT_EQ(s.position_m, Vec3::Zero());
  s = d.read(0.25);
  EXPECT_TRUE(s.position_m.isApprox(Vec3(0.25, 0.125, -0.125)));
  EXPECT_EQ(s.buttons, 0u);
  s = d.read(1.0);
  EXPECT_EQ(s.buttons, 1u);
  EXPECT_FALSE(d.finished());
  s = d.read(1.5);
  EXPECT_DOUBLE_EQ(s.position_m.x(), 1.0);  // 3.0 clamped to the workspace
  s = d.read(7.0);
  EXPECT_TRUE(d.finished());
  EXPECT_EQ(s.buttons, 2u);
  EXPECT_EQ(s.position_m, Vec3(1.0, 0.5, -0.5));
  ForceCommand c;
  c.force_n = Vec3(0.0, 3.0, 4.0);
  d.command_force(c);
  EXPECT_DOUBLE_EQ(d.max_commanded_force_n(), 5.0);
}

TEST(HapticsSharedPose, HandsThePoseOverAndClampsIt) {
  SharedPoseDevice d("mouse", roomy());
  EXPECT_FALSE(d.read(0.0).valid);
  d.set_pose(Vec3(0.1, 2.0, 0.3), 1);
  const DeviceState s = d.read(0.5);
  EXPECT_TRUE(s.valid);
  EXPECT_EQ(s.position_m, Vec3(0.1, 1.0, 0.3));
  EXPECT_EQ(s.buttons, 1u);
  EXPECT_DOUBLE_EQ(s.t_s, 0.5);
}

TEST(HapticsUdpProtocol, RoundTripsAndRejectsMalformedPackets) {
  udp::PosePacket p;
  p.seq = 42;
  p.t_s = 1.5;
  p.position_m = Vec3(0.1, -0.2, 0.3);
  p.buttons = 5;
  const udp::Packet bytes = udp::encode(p);
  EXPECT_EQ(bytes[0], 'S');
  EXPECT_EQ(bytes[1], 'B');
  EXPECT_EQ(bytes[2], 'P');
  EXPECT_EQ(bytes[3], '1');
  const auto q = udp::decode_pose(bytes);
  ASSERT_TRUE(q);
  EXPECT_EQ(q->seq, 42u);
  EXPECT_EQ(q->position_m, p.position_m);
  EXPECT_EQ(q->buttons, 5u);
  EXPECT_FALSE(udp::decode_force(bytes));  // a pose is not a force
  EXPECT_FALSE(udp::decode_pose(std::span(bytes.data(), 40)));
  udp::PosePacket bad = p;
  bad.position_m.y() = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(udp::decode_pose(udp::encode(bad)));

  udp::ForcePacket f;
  f.seq = 9;
  f.force_n = Vec3(1.0, 2.0, 3.0);
  f.flags = udp::kFlagContact | udp::kFlagClamped;
  f.max_force_n = 8.0f;
  const auto g = udp::decode_force(udp::encode(f));
  ASSERT_TRUE(g);
  EXPECT_EQ(g->force_n, f.force_n);
  EXPECT_EQ(g->flags, 3u);
  EXPECT_EQ(g->max_force_n, 8.0f);
}

// A driver on loopback: sends poses to the device, receives its forces.
class Driver {
 public:
  explicit Driver(int port) {
    fd_ = ::socket(AF_INET, SOCK_DGRAM, 0);
    to_.sin_family = AF_INET;
    to_.sin_port = htons(static_cast<std::uint16_t>(port));
    to_.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    timeval tv{1, 0};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  }
  ~Driver() { ::close(fd_); }
  void send(const std::uint8_t* data, std::size_t n) {
    ::sendto(fd_, data, n, 0, reinterpret_cast<sockaddr*>(&to_), sizeof to_);
  }
  void send(const udp::PosePacket& p) {
    const udp::Packet b = udp::encode(p);
    send(b.data(), b.size());
  }
  std::optional<udp::ForcePacket> receive() {
    udp::Packet b;
    const ssize_t n = ::recv(fd_, b.data(), b.size(), 0);
    if (n != static_cast<ssize_t>(b.size())) return std::nullopt;
    return udp::decode_force(b);
  }

 private:
  int fd_ = -1;
  sockaddr_in to_{};
};

// Polls the device until a pose arrives (loopback delivery is not instantaneous).
DeviceState read_until_valid(UdpDevice& d, double now_s) {
  DeviceState s;
  for (int i = 0; i < 2000 && !s.valid; ++i) {
    s = d.read(now_s);
    if (!s.valid) std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
  return s;
}

TEST(HapticsUdpDevice, PosesInForcesOutOnLoopback) {
  UdpDevice device(0, roomy());
  ASSERT_GT(device.port(), 0);
  EXPECT_FALSE(device.read(0.0).valid);
  Driver driver(device.port());

  const std::uint8_t junk[7] = {1, 2, 3, 4, 5, 6, 7};
  driver.send(junk, sizeof junk);
  udp::PosePacket p;
  p.seq = 17;
  p.position_m = Vec3(0.2, 0.3, 0.05);
  p.buttons = 1;
  driver.send(p);
  const DeviceState s = read_until_valid(device, 0.01);
  ASSERT_TRUE(s.valid);
  EXPECT_EQ(s.position_m, p.position_m);
  EXPECT_EQ(s.buttons, 1u);
  EXPECT_EQ(device.packets_rejected(), 1u);

  ForceCommand c;
  c.force_n = Vec3(0.5, -0.25, 3.0);
  c.t_s = 0.01;
  c.in_contact = true;
  device.command_force(c);
  const auto f = driver.receive();
  ASSERT_TRUE(f);
  EXPECT_EQ(f->seq, 17u);
  EXPECT_EQ(f->force_n, c.force_n);
  EXPECT_EQ(f->flags, udp::kFlagContact);
  EXPECT_EQ(f->max_force_n, 8.0f);
  EXPECT_EQ(device.forces_sent(), 1u);

  // No pose for longer than the stale time: no valid pose, so the servo sends no force.
  EXPECT_FALSE(device.read(0.01 + 1.0).valid);
}

TEST(HapticsUdpDevice, PortInUseIsAnInputErrorNamingTheOption) {
  UdpDevice first(0, roomy());
  try {
    UdpDevice second(first.port(), roomy(), "--device udp:" + std::to_string(first.port()));
    FAIL() << "bound twice";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--device udp:"), std::string::npos) << e.what();
  }
  EXPECT_THROW(UdpDevice(70000, roomy()), InputError);
}

}  // namespace
}  // namespace sb::haptics
