// `sandbench run SCENE --backend tin|grid [--out RUN.h5] [--json] [--set k=v ...] [--replay SESSION]`
#include <iostream>
#include <memory>

#include "common/atomic_file.hpp"
#include "common/input_error.hpp"
#include "harness/cli/commands.hpp"
#include "harness/cli/scene_input.hpp"
#include "harness/cli/validators.hpp"
#include "harness/io/run_file.hpp"
#include "harness/run/backends.hpp"
#include "harness/run/variant.hpp"

namespace sb::cli {

namespace {
struct RunOptions {
  SceneInput in;  // SCENE, --set, --unset, --replay
  std::string backend;
  std::string out;
  bool json = false;
};

void run_command(const RunOptions& o) {
  const Variant variant = parse_variant(o.backend, "--backend");
  PreparedScene prepared = prepare_input(o.in, {variant});
  const std::filesystem::path out =
      o.out.empty() ? default_run_path(o.in.scene, variant.label) : std::filesystem::path(o.out);
  check_output_path(out, "--out", {o.in.scene, o.in.replay});  // the default name too; --out '' fails its validator
  VariantRun r = run_variant(variant, prepared, /*show_progress=*/true);
  if (!o.in.replay.empty()) r.summary["replay"] = o.in.replay;
  write_run_file(out, r.run, r.prepared, r.summary);
  if (o.json) {
    std::cout << r.summary.dump(2) << "\n";
  } else {
    for (const auto& [k, v] : r.summary.items()) std::cout << k << " = " << v.dump() << "\n";
  }
  std::cerr << "wrote " << out.string() << "\n";
}
}  // namespace

void add_run_command(CLI::App& app) {
  auto opts = std::make_shared<RunOptions>();
  CLI::App* cmd = app.add_subcommand("run", "Run one back-end on a scene's stroke and write an HDF5 run file");
  add_scene_options(cmd, opts->in, ReplayOption::With);
  cmd->add_option("--backend", opts->backend, backend_list() + " (optionally grid:key=value:...)")->required();
  cmd->add_option("--out", opts->out, "Run file to write (default: <scene>-<backend>.h5)")->check(output_file());
  cmd->add_flag("--json", opts->json, "Print the summary as JSON on stdout");
  cmd->callback([opts] { run_command(*opts); });
}

}  // namespace sb::cli
