#pragma once
// The scene a `run` or `compare` works on, from its options.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "harness/run/runner.hpp"
#include "harness/run/variant.hpp"

namespace sb::cli {

struct SceneInput {
  std::string scene;
  std::vector<std::string> unset;
  std::vector<std::string> overrides;
  std::string replay;                       // a recorded session, or empty
  std::optional<std::uint64_t> max_memory;  // --max-memory, or the available memory
};

// The scene file with --unset and --set applied; with --replay (non-empty), the session's stamps
// replace the scene's stroke, its own overrides (its material) come before --set so that --set
// still wins, its tools are validated against the scene, and the analytic references are off
// (they follow the scene's stroke). The resource pre-flight of `variants` run one after
// another runs before the initial surface is built (harness/run/preflight.hpp). Throws
// InputError naming the option or the scene keys on bad input.
PreparedScene prepare_input(const SceneInput& input, const std::vector<Variant>& variants);

}  // namespace sb::cli
