// `sandbench compare SCENE [--backends tin,grid,sparse] [--out DIR] [--json] [--set k=v ...]
//  [--unset key ...] [--replay SESSION]`:
// the same schedule on each back-end (or back-end variant), a table, the summaries and pictures.
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include "common/atomic_file.hpp"
#include "common/input_error.hpp"
#include "harness/cli/commands.hpp"
#include "harness/cli/scene_input.hpp"
#include "harness/cli/validators.hpp"
#include "harness/figures/compare_pictures.hpp"
#include "harness/io/run_file.hpp"
#include "harness/run/backends.hpp"
#include "harness/run/variant.hpp"

namespace sb::cli {

namespace {
struct CompareOptions {
  SceneInput in;  // SCENE, --set, --unset, --replay
  std::string backends;
  std::string out;
  bool json = false;
};

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> parts;
  std::stringstream in(s);
  for (std::string part; std::getline(in, part, sep);)
    if (!part.empty()) parts.push_back(part);
  return parts;
}

std::string markdown_table(const std::vector<VariantRun>& runs) {
  static const char* rows[] = {"stamps",
                               "time_s.tool",
                               "time_s.erosion",
                               "time_s.simplify",
                               "time_s.total",
                               "step_ms.p50",
                               "step_ms.p95",
                               "step_ms.max",
                               "memory_bytes",
                               "memory_bytes_peak",
                               "vertices",
                               "triangles",
                               "constrained_edges",
                               "cells",
                               "volume_initial",
                               "volume_final",
                               "volume_added",
                               "volume_drift_rel",
                               "max_slope_excess_deg"};
  std::ostringstream t;
  t << "| metric |";
  for (const auto& r : runs) t << " " << r.run.label << " |";
  t << "\n|---|";
  for (std::size_t i = 0; i < runs.size(); ++i) t << "---:|";
  t << "\n";
  for (const char* row : rows) {
    t << "| " << row << " |";
    for (const auto& r : runs) {
      const Json& v = r.summary.at(row);
      std::ostringstream cell;
      if (v.is_number_float())
        cell << std::setprecision(6) << v.get<double>();
      else
        cell << v.dump();
      t << " " << cell.str() << " |";
    }
    t << "\n";
  }
  return t.str();
}

void compare_command(const CompareOptions& o) {
  std::vector<Variant> variants;
  for (const auto& item : split(o.backends.empty() ? "tin,grid,sparse" : o.backends, ','))
    variants.push_back(parse_variant(item, "--backends"));
  if (variants.empty()) throw InputError("--backends is empty; give e.g. tin,grid");
  const std::filesystem::path dir = o.out;
  if (!dir.empty()) check_output_directory(dir, "--out", {o.in.scene, o.in.replay});  // --out '' fails its validator

  PreparedScene prepared = prepare_input(o.in, variants);
  // A folder being written holds this marker until its last picture is there, so a killed
  // compare leaves a folder that says it is incomplete.
  const std::filesystem::path marker = dir / "INCOMPLETE";
  if (!dir.empty()) {
    std::filesystem::create_directories(dir);
    std::ofstream(marker) << "sandbench compare is writing this folder, or was stopped before finishing it\n";
  }

  std::vector<VariantRun> runs;
  for (const Variant& v : variants) runs.push_back(run_variant(v, prepared, /*show_progress=*/true));

  Json report;
  report["scene"] = prepared.scene.path;
  report["stamps"] = prepared.schedule.stamps.size();
  report["runs"] = Json::array();
  for (const auto& r : runs) report["runs"].push_back(r.summary);
  report["differences"] = Json::array();
  for (std::size_t i = 1; i < runs.size(); ++i) {
    const RasterDifference d = compare_rasters(runs[i].run.final_raster, runs[0].run.final_raster);
    report["differences"].push_back({{"a", runs[i].run.label},
                                     {"b", runs[0].run.label},
                                     {"rmse_m", d.rmse_m},
                                     {"max_abs_m", d.max_abs_m},
                                     {"mean_m", d.mean_m}});
  }

  const std::string table = markdown_table(runs);
  if (!dir.empty()) {
    for (const auto& r : runs)
      write_run_file(dir / default_run_path(o.in.scene, r.run.label).filename(), r.run, r.prepared, r.summary);
    write_text_atomically(dir / "summary.json", report.dump(2) + "\n");
    write_text_atomically(dir / "table.md", table);
    std::vector<PictureRun> pictures;
    std::vector<SurfaceMesh> meshes;
    meshes.reserve(runs.size());
    for (const auto& r : runs) {
      meshes.push_back(r.run.final_surface());
      pictures.push_back({r.run.label, &meshes.back(), &r.run.initial_raster, &r.run.final_raster, &r.summary});
    }
    write_compare_pictures(dir, pictures);
    std::filesystem::remove(marker);
    std::cerr << "wrote " << dir.string() << "/{*.h5,summary.json,table.md,side_by_side.png"
              << (runs.size() > 1 ? ",difference.png}\n" : "}\n");
  }
  if (o.json) {
    std::cout << report.dump(2) << "\n";
  } else {
    std::cout << table;
  }
}
}  // namespace

void add_compare_command(CLI::App& app) {
  auto opts = std::make_shared<CompareOptions>();
  CLI::App* cmd = app.add_subcommand("compare", "Run the same schedule on several back-ends and compare them");
  add_scene_options(cmd, opts->in, ReplayOption::With);
  cmd->add_option("--backends", opts->backends,
                  "Comma-separated back-ends or variants (default tin,grid,sparse), e.g. grid,grid:grid.storage=float");
  cmd->add_option("--out", opts->out,
                  "Directory for run files, summary.json, table.md, side_by_side.png and difference.png")
      ->check(output_directory());
  cmd->add_flag("--json", opts->json, "Print the report as JSON on stdout");
  cmd->callback([opts] { compare_command(*opts); });
}

}  // namespace sb::cli
