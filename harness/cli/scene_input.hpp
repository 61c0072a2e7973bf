#pragma once
// The scene a command works on, from its options: the positional SCENE, --set, --unset and
// --max-memory for every command that takes a scene (`run`, `compare`, `interactive`), and
// --replay for those that run a schedule (`run`, `compare`). Defined here once, so the commands
// accept the same scene options.
#include <CLI/CLI.hpp>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "harness/run/runner.hpp"
#include "harness/run/variant.hpp"

namespace sb::cli {

struct SceneInput {
  std::string scene;
  std::vector<std::string> unset;           // --unset: keys removed before the --sets
  std::vector<std::string> overrides;       // --set key=value
  std::string replay;                       // --replay: a recorded session (empty: the scene's stroke)
  std::optional<std::uint64_t> max_memory;  // --max-memory, or the available memory
};

enum class ReplayOption { Without, With };

// Adds SCENE, --set, --unset and --max-memory (and --replay with ReplayOption::With) to CMD,
// filling IN.
void add_scene_options(CLI::App* cmd, SceneInput& in, ReplayOption replay);

// The scene file with --unset and --set applied; with --replay (non-empty), the session's stamps
// replace the scene's stroke, its own overrides (its material) come before --set so that --set
// still wins, its tools are validated against the scene, and the analytic references are off
// (they follow the scene's stroke). The resource pre-flight of `variants` run one after
// another runs before the initial surface is built (harness/run/preflight.hpp). Throws
// InputError naming the option or the scene keys on bad input.
PreparedScene prepare_input(const SceneInput& in, const std::vector<Variant>& variants);

}  // namespace sb::cli
