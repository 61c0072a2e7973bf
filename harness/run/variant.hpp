#pragma once
// Helpers shared by the subcommands: progress on a terminal, back-end variants, runs.
#include <filesystem>
#include <string>
#include <vector>

#include "harness/run/runner.hpp"
#include "harness/run/summary.hpp"

namespace sb {

// Progress on stderr, only when stderr is a terminal.
ProgressFn terminal_progress(const std::string& label);

// A back-end plus scene overrides, written "grid" or "grid:grid.storage=float:grid.neighbours=4".
struct Variant {
  std::string label;
  std::string backend;
  std::vector<std::string> overrides;
};
Variant parse_variant(const std::string& text);

// Runs one variant on the prepared scene's schedule (variant overrides change back-end
// parameters, never the stamps) and returns the run with its summary.
struct VariantRun {
  RunResult run;
  PreparedScene prepared;  // the variant's own scene, with the shared schedule
  Json summary;
};
VariantRun run_variant(const Variant& v, const PreparedScene& base, bool show_progress);

// Default run-file name for a scene and a label: "<scene stem>-<label>.h5", label made
// filename-safe.
std::filesystem::path default_run_path(const std::string& scene_path, const std::string& label);

}  // namespace sb
