// `sandbench interactive` in a real window under Xvfb: the replay device on both back-ends
// (screenshot not blank, every force finite and within the device's limit, the recorded
// session replays through `sandbench run`), and the UDP bridge driven by the Python device
// client. Rates are printed, not asserted. Skipped when xvfb-run is not installed.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <png.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "harness/io/session_file.hpp"
#include "harness_test_support.hpp"

namespace sb {
namespace {

namespace fs = std::filesystem;

using Result = test::CliResult;

// `cmd` in the shell, its stdout and stderr together.
Result shell(const std::string& cmd) { return test::run_shell("{ " + cmd + "; } 2>&1"); }

using test::have_xvfb;
using test::xvfb;

std::string scene_path() { return test::shipped_scene("flat_stroke.toml"); }

nlohmann::json read_json(const fs::path& file) {
  std::ifstream in(file);
  return nlohmann::json::parse(in);
}

// Not blank: many distinct colours and a real spread of brightness.
void expect_not_blank(const fs::path& file) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  ASSERT_TRUE(png_image_begin_read_from_file(&image, file.c_str())) << file;
  image.format = PNG_FORMAT_RGB;
  std::vector<png_byte> rgb(PNG_IMAGE_SIZE(image));
  ASSERT_TRUE(png_image_finish_read(&image, nullptr, rgb.data(), 0, nullptr));
  EXPECT_GE(image.width, 64u);
  std::set<std::uint32_t> colours;
  double sum = 0.0, sum2 = 0.0;
  const std::size_t n = rgb.size() / 3;
  for (std::size_t i = 0; i < n; ++i) {
    colours.insert(rgb[3 * i] << 16 | rgb[3 * i + 1] << 8 | rgb[3 * i + 2]);
    const double y = 0.3 * rgb[3 * i] + 0.59 * rgb[3 * i + 1] + 0.11 * rgb[3 * i + 2];
    sum += y;
    sum2 += y * y;
  }
  const double sd = std::sqrt(std::max(0.0, sum2 / n - (sum / n) * (sum / n)));
  EXPECT_GT(colours.size(), 50u) << file;
  EXPECT_GT(sd, 10.0) << file;
}

void expect_safe_forces(const nlohmann::json& s) {
  for (const char* key : {"servo_hz", "tick_us.p50", "tick_us.p99", "tick_us.max", "missed_deadlines", "force_max_n"})
    ASSERT_TRUE(s.contains(key)) << key;
  for (const auto& [key, value] : s.items())
    if (value.is_number()) {
      EXPECT_TRUE(std::isfinite(value.get<double>())) << key;
    }
  const double limit = s["force_limit_n"].get<double>();
  EXPECT_EQ(s["forces_nonfinite"], 0);
  EXPECT_LE(s["force_max_n"].get<double>(), limit);
  EXPECT_LE(s["device_force_max_n"].get<double>(), limit);
  EXPECT_GT(s["ticks"].get<double>(), 0.0);
  // The renderer the frame figures were measured on (llvmpipe under Xvfb).
  EXPECT_FALSE(s.value("gl_renderer", std::string()).empty());
}

class Window : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!have_xvfb()) GTEST_SKIP() << "xvfb-run is not installed (Debian: xvfb, xauth; make deps)";
    dir_ = fs::temp_directory_path() / ("sb_window_" + std::to_string(::getpid()) + "_" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (!dir_.empty()) fs::remove_all(dir_);
  }
  fs::path dir_;
};

// A stroke on flat_stroke.toml: hover, press 1.2 cm into the sand, drag 5 cm, lift; 2 s.
void write_stroke(const fs::path& file) {
  std::ofstream out(file);
  out << "t,x,y,z,buttons\n";
  for (int i = 0; i <= 400; ++i) {
    const double t = i * 0.005, u = t / 2.0;
    const double z = u < 0.2 ? 0.11 - 0.022 * u / 0.2 : u > 0.9 ? 0.088 + 0.022 * (u - 0.9) / 0.1 : 0.088;
    const double s = std::clamp((u - 0.2) / 0.7, 0.0, 1.0) * 0.035;
    out << t << "," << 0.33 + s << "," << 0.33 + s << "," << z << ",0\n";
  }
}

TEST_F(Window, ReplayDeviceOnBothBackEndsRecordsASessionThatRunReplays) {
  const fs::path stroke = dir_ / "stroke.csv";
  write_stroke(stroke);
  for (const std::string backend : {"grid", "tin"}) {
    const fs::path shot = dir_ / (backend + ".png"), stats = dir_ / (backend + ".json"),
                   session = dir_ / (backend + "-session.csv");
    const Result r = shell(xvfb() + SB_CLI_PATH + " interactive " + scene_path() + " --backend " + backend +
                           " --device replay:" + stroke.string() + " --frames 150 --size 800 500" + " --screenshot " +
                           shot.string() + " --stats " + stats.string() + " --record " + session.string());
    ASSERT_EQ(r.code, 0) << r.out;
    std::cout << "[" << backend << "] " << r.out;
    expect_not_blank(shot);
    const auto s = read_json(stats);
    expect_safe_forces(s);
    EXPECT_EQ(s["backend"], backend);
    EXPECT_EQ(s["frames"], 150);
    EXPECT_GT(s["ticks_in_contact"].get<double>(), 0.0) << backend;
    EXPECT_GT(s["sim.stamps"].get<double>(), 0.0) << backend;
    EXPECT_GT(s["sim.step_cpu_s.total"].get<double>(), 0.0) << backend;
    EXPECT_GT(s["sim.erosion_updates"].get<double>(), 0.0) << backend;
    // A stamp is taken by the window at the start of the frame that shows it: never after that frame's swap.
    for (const char* q : {"p50", "p95"}) {
      EXPECT_GE(s[std::string("stamp_to_take_ms.") + q].get<double>(), 0.0) << backend;
      EXPECT_LE(s[std::string("stamp_to_take_ms.") + q].get<double>(),
                s[std::string("stamp_to_frame_ms.") + q].get<double>())
          << backend;
    }

    const Session recorded = read_session(session, "--replay");
    EXPECT_EQ(recorded.stamps.size(), s["sim.stamps"].get<std::size_t>());
    for (const std::string replay_on : {"grid", "tin"}) {
      const Result run =
          shell(std::string(SB_CLI_PATH) + " run " + scene_path() + " --backend " + replay_on + " --replay " +
                session.string() + " --json --out " + (dir_ / (backend + "-on-" + replay_on + ".h5")).string());
      ASSERT_EQ(run.code, 0) << run.out;
      const auto a = run.out.find('{'), b = run.out.rfind('}');
      const auto j = nlohmann::json::parse(run.out.substr(a, b - a + 1));
      EXPECT_EQ(j["stamps"].get<std::size_t>(), recorded.stamps.size()) << backend << " on " << replay_on;
    }
  }
}

int free_udp_port() {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
  socklen_t len = sizeof a;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  ::close(fd);
  return ntohs(a.sin_port);
}

TEST_F(Window, UdpBridgeDrivenByThePythonDevice) {
  const int port = free_udp_port();
  const fs::path client = dir_ / "client.json", stats = dir_ / "stats.json";
  const std::string py = "/usr/bin/python3 " + std::string(SB_SOURCE_DIR) + "/experiments/udp_device.py --port " +
                         std::to_string(port) + " --scene " + scene_path() +
                         " --duration 2.5 --wait-for-answer 60 --extra-depth 0.002 --out " + client.string();
  const std::string app =
      xvfb() + SB_CLI_PATH + " interactive " + scene_path() + " --backend grid --device udp:" + std::to_string(port) +
      " --frames 300 --size 640 400 --stats " + stats.string() + " --record " + (dir_ / "udp.csv").string();
  const Result r = shell("(" + py + ") & pid=$!; " + app + "; rc=$?; wait $pid || exit 9; exit $rc");
  ASSERT_EQ(r.code, 0) << r.out;
  std::cout << "[udp] " << r.out;
  const auto c = read_json(client);
  EXPECT_GT(c["poses_sent"].get<double>(), 100.0);
  EXPECT_GT(c["forces_received"].get<double>(), 100.0) << c.dump();
  EXPECT_TRUE(c["all_finite"].get<bool>());
  EXPECT_TRUE(c["within_limit"].get<bool>());
  EXPECT_GT(c["ticks_in_contact"].get<double>(), 0.0) << c.dump();
  EXPECT_LE(c["force_max_n"].get<double>(), c["force_limit_n"].get<double>());
  const auto s = read_json(stats);
  expect_safe_forces(s);
  EXPECT_GT(s["ticks_without_pose"].get<double>(), 0.0);  // before the driver's first pose
  EXPECT_GT(s["sim.stamps"].get<double>(), 0.0);
  // What the UDP device recorded replays (its coordinates may be denormal, e.g. 5e-324).
  const Result replay = shell(std::string(SB_CLI_PATH) + " run " + scene_path() + " --backend grid --replay " +
                              (dir_ / "udp.csv").string() + " --out " + (dir_ / "udp.h5").string());
  EXPECT_EQ(replay.code, 0) << replay.out;
}

}  // namespace
}  // namespace sb
