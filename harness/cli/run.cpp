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
  std::string scene;
  std::string backend;
  std::string out;
  bool json = false;
  std::vector<std::string> overrides;
  std::vector<std::string> unset;
  std::string replay;  // a recorded session whose stamps replace the scene's stroke
  std::optional<std::uint64_t> max_memory;
};

void run_command(const RunOptions& o) {
  const Variant variant = parse_variant(o.backend, "--backend");
  PreparedScene prepared = prepare_input({o.scene, o.unset, o.overrides, o.replay, o.max_memory}, {variant});
  const std::filesystem::path out =
      o.out.empty() ? default_run_path(o.scene, variant.label) : std::filesystem::path(o.out);
  check_output_path(out, "--out", {o.scene, o.replay});  // the default name too; --out '' fails its validator
  VariantRun r = run_variant(variant, prepared, /*show_progress=*/true);
  if (!o.replay.empty()) r.summary["replay"] = o.replay;
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
  cmd->add_option("scene", opts->scene, "Scene file (TOML)")->required();
  cmd->add_option("--backend", opts->backend, backend_list() + " (optionally grid:key=value:...)")->required();
  cmd->add_option("--out", opts->out, "Run file to write (default: <scene>-<backend>.h5)")->check(output_file());
  cmd->add_flag("--json", opts->json, "Print the summary as JSON on stdout");
  cmd->add_option("--set", opts->overrides, "Override a scene key: --set tool.radius_m=0.03")->take_all();
  cmd->add_option("--unset", opts->unset, "Remove a scene key (before --set): --unset tool.radius_m")->take_all();
  cmd->add_option("--replay", opts->replay,
                  "Replay a session recorded by `sandbench interactive --record`: its stamps are the schedule");
  add_max_memory_option(*cmd, opts->max_memory);
  cmd->callback([opts] { run_command(*opts); });
}

}  // namespace sb::cli
