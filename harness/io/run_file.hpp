#pragma once
// HDF5 run files (contract: README "Run files (HDF5)"): one file per back-end run, written under a temporary
// name and renamed when whole.
//   /                   attributes: scene_text, scene_resolved, scene_path, overrides,
//                       backend, label, parameters, version, commit, build_id (the binary;
//                       see version.hpp), compiler, date, summary (JSON)
//   /steps/<field>      one row per step (StepRecord fields; stamp = -1 for relaxation)
//   /summary            one attribute per metric (contract names)
//   /initial/raster, /final/raster
//                       2-D, rows along y, attributes origin_m = [x0, y0], spacing_m
//   /final/mesh/vertices (n x 3, m), triangles (m x 3), constrained_edges (k x 2)
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "harness/run/summary.hpp"

namespace sb {

// Assembled in memory (about the file's size), then written whole under a temporary name and
// renamed; a failed write (disk full) throws InputError and leaves nothing.
void write_run_file(const std::filesystem::path& file, const RunResult& run, const PreparedScene& prepared,
                    const Json& summary);

struct RunFile {
  std::map<std::string, std::string> attributes;  // the root's string attributes
  Json summary;
  std::map<std::string, std::vector<double>> steps;
  Raster initial_raster;
  Raster final_raster;
  SurfaceMesh mesh;
};

// Throws InputError when the file cannot be opened or is not a sandbench run file.
RunFile read_run_file(const std::filesystem::path& file);

}  // namespace sb
