// `sandbench export RUN.h5 --format ply|obj|png16 -o FILE`: a run's final surface for
// MeshLab, Blender (PLY, OBJ) and QGIS (PLY through MDAL, PNG16 with its GDAL sidecar).
#include "harness/io/export.hpp"

#include <iostream>
#include <memory>

#include "common/input_error.hpp"
#include "harness/cli/commands.hpp"
#include "harness/cli/validators.hpp"
#include "harness/io/run_file.hpp"
#include "harness/render/mesh.hpp"
#include "sandbench/version.hpp"

namespace sb::cli {

namespace {
struct ExportOptions {
  std::string run;
  ExportFormat format = ExportFormat::Ply;
  std::string out;
};

std::string attribute(const RunFile& r, const char* key) {
  const auto it = r.attributes.find(key);
  return it == r.attributes.end() ? std::string() : it->second;
}

void export_command(const ExportOptions& o) {
  const ExportFormat format = o.format;
  const std::filesystem::path out = o.out;
  const RunFile run = read_run_file(o.run);
  const std::string label = attribute(run, "label").empty() ? attribute(run, "backend") : attribute(run, "label");
  const std::vector<std::string> comments = {
      std::string("sandbench ") + kVersion + " export of " + std::filesystem::path(o.run).filename().string(),
      "backend " + label, "scene " + attribute(run, "scene_path")};
  if (format == ExportFormat::Png16) {
    const HeightmapKeys k = export_png16(out, run.final_raster, comments[0] + ", backend " + label);
    std::cerr << "wrote " << out.string() << " (" << run.final_raster.nx << " x " << run.final_raster.ny << ", step "
              << k.step_m() << " m) and " << out.string() << ".aux.xml\nreload it with:\n"
              << heightmap_scene_snippet(k, out.filename().string());
    return;
  }
  const SurfaceMesh mesh = run.mesh.triangles.empty() ? mesh_from_raster(run.final_raster) : run.mesh;
  if (run.mesh.triangles.empty()) std::cerr << "sandbench: " << o.run << " has no mesh; exporting its final raster\n";
  if (format == ExportFormat::Ply)
    export_ply(out, mesh, comments);
  else
    export_obj(out, mesh, comments);
  std::cerr << "wrote " << out.string() << " (" << mesh.vertices.size() << " vertices, " << mesh.triangles.size()
            << " triangles, " << mesh.constrained_edges.size() << " constrained edges)\n";
}
}  // namespace

void add_export_command(CLI::App& app) {
  auto opts = std::make_shared<ExportOptions>();
  CLI::App* cmd =
      app.add_subcommand("export", "Export a run file's final surface as PLY, OBJ or a 16-bit PNG heightmap");
  cmd->add_option("run", opts->run, "Run file (HDF5) written by sandbench run or compare")->required();
  cmd->add_option("--format", opts->format, "ply | obj | png16")->required()->transform(names(export_formats()));
  cmd->add_option("-o,--out", opts->out, "File to write")->required()->check(output_file());
  cmd->callback([opts] { export_command(*opts); });
}

}  // namespace sb::cli
