#pragma once
// The scene a `run` or `compare` works on, from its options.
#include <string>
#include <vector>

#include "harness/run/runner.hpp"

namespace sb::cli {

// The scene file with --unset and --set applied; with --replay (non-empty), the session's stamps
// replace the scene's stroke, its own overrides (its material) come before --set so that --set
// still wins, its tools are validated against the scene, and the analytic references are off
// (they follow the scene's stroke). Throws InputError naming the option on bad input.
PreparedScene prepare_input(const std::string& scene, const std::vector<std::string>& unset,
                            const std::vector<std::string>& overrides, const std::string& replay);

}  // namespace sb::cli
