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
// Settling progress on stderr, only when stderr is a terminal.
std::function<void(long long, long long, std::size_t)> terminal_settling(const std::string& label);

// A back-end plus scene overrides, written "grid" or "grid:grid.storage=float:grid.neighbours=4".
struct Variant {
  std::string label;
  std::string backend;
  std::vector<std::string> overrides;
};
// `option` ("--backend" or "--backends") names the option in errors, which list the back-ends
// of the factory table.
Variant parse_variant(const std::string& text, const std::string& option);

// The variant's own scene: the base scene with its overrides applied (validated as a scene).
Scene variant_scene(const Variant& v, const Scene& base);

// Runs one variant on the prepared scene's schedule (variant overrides change back-end
// parameters, never the stamps) and returns the run with its summary. A TIN variant stops
// (InputError) when it grows past the pre-flight's vertex allowance (tin_vertex_allowance).
struct VariantRun {
  RunResult run;
  PreparedScene prepared;  // the variant's own scene, with the shared schedule
  Json summary;
};
VariantRun run_variant(const Variant& v, const PreparedScene& base, bool show_progress);

// What run_variant says on stderr before building a model that takes long to build (a TIN of
// at least 2e6 tin.initial_points: its estimated time and memory), or "" when it is quick.
std::string build_notice(const std::string& backend, const Scene& scene);

// The scene overrides of --unset KEY ... then --set KEY=VALUE ... (removals first, so that
// `--unset tool.radius_m --set tool.shape=box --set tool.size_m=[0.04,0.02]` switches a tool).
std::vector<std::string> scene_overrides(const std::vector<std::string>& unset, const std::vector<std::string>& set);

// Default run-file name for a scene and a label: "<scene stem>-<label>.h5", label made
// filename-safe.
std::filesystem::path default_run_path(const std::string& scene_path, const std::string& label);

}  // namespace sb
