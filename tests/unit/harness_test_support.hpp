#pragma once
// Test support for the harness tests: the sandbench binary run as a process.
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace sb::test {

struct CliResult {
  int code = -1;    // exit code; -1 when the process did not exit normally
  std::string out;  // stdout and stderr together
};

// Runs `sandbench ARGS` (SB_CLI_PATH) and collects its output and exit code.
inline CliResult sandbench(const std::string& args) {
  const std::string cmd = std::string(SB_CLI_PATH) + " " + args + " 2>&1";
  CliResult r;
  FILE* pipe = ::popen(cmd.c_str(), "r");
  std::array<char, 4096> buf{};
  while (std::fgets(buf.data(), buf.size(), pipe)) r.out += buf.data();
  const int status = ::pclose(pipe);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

}  // namespace sb::test
