#pragma once
// Test support for the harness tests: shell commands and the sandbench binary run as
// processes (in a window under Xvfb too), the shipped scenes, whole files, and a fixture with
// its own temporary folder.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <utility>

namespace sb::test {

struct CliResult {
  int code = -1;    // exit code; -1 when the process did not exit normally
  std::string out;  // what the command wrote to its stdout (and stderr, where it redirects it)
};

// Runs `command` through the shell (popen) and collects its stdout and exit code; the
// caller redirects stderr inside the command if it wants it too.
inline CliResult run_shell(const std::string& command) {
  CliResult r;
  FILE* pipe = ::popen(command.c_str(), "r");
  std::array<char, 4096> buf{};
  while (std::fgets(buf.data(), buf.size(), pipe)) r.out += buf.data();
  const int status = ::pclose(pipe);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// Runs `sandbench ARGS` (SB_CLI_PATH) and collects its output (stdout and stderr together)
// and exit code.
inline CliResult sandbench(const std::string& args) {
  return run_shell(std::string(SB_CLI_PATH) + " " + args + " 2>&1");
}

// Whether xvfb-run is installed (windows under a virtual display).
inline bool have_xvfb() { return run_shell("command -v xvfb-run >/dev/null 2>&1").code == 0; }

// The prefix that runs a command in a window under Xvfb. Under AddressSanitizer, the GL and X
// libraries' own allocations at exit are not ours.
inline std::string xvfb() {
  return "ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0 xvfb-run -a -s '-screen 0 1024x768x24' ";
}

// The path of a scene shipped in experiments/scenes, e.g. "flat_stroke.toml".
inline std::string shipped_scene(const std::string& name) {
  return std::string(SB_SOURCE_DIR) + "/experiments/scenes/" + name;
}

// A file's bytes; "" when it cannot be read.
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// A test with its own empty folder dir_ in the temporary directory, named `prefix`, the
// process id and the test's name (tests run in parallel processes), removed after the test.
// Fixtures that set up more call TempDirTest::SetUp() first.
class TempDirTest : public ::testing::Test {
 protected:
  explicit TempDirTest(std::string prefix) : prefix_(std::move(prefix)) {}
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / (prefix_ + std::to_string(::getpid()) + "_" +
                                                     ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  std::filesystem::path dir_;

 private:
  std::string prefix_;
};

}  // namespace sb::test
