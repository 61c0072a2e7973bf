#pragma once
// The pictures `sandbench compare --out DIR` leaves beside its run files:
//   side_by_side.png  one column per back-end, labelled with the back-end, its vertex or
//                     cell count and its memory: an oblique smooth-shaded view above a top
//                     view with the mesh edges (constrained edges red); one camera, light
//                     and frame (the region where anything changed) for every column.
//   difference.png    heat maps of each back-end's height minus the first's on the common
//                     raster, over the same region, with a colour bar in metres.
// Cost: two renders per back-end (see render/renderer.hpp) plus O(picture pixels) for the heat map.
#include <filesystem>
#include <string>
#include <vector>

#include "common/raster.hpp"
#include "common/terrain.hpp"
#include "harness/render/renderer.hpp"
#include "harness/run/summary.hpp"

namespace sb {

struct PictureRun {
  std::string label;  // back-end or variant, e.g. "tin", "grid:grid.neighbours=4"
  const SurfaceMesh* mesh = nullptr;
  const Raster* initial = nullptr;  // the common raster before and after the stroke
  const Raster* final = nullptr;
  const Json* summary = nullptr;  // contract metrics: vertices, cells, memory_bytes, ...
};

// The frame all pictures of a comparison share (FrameRegion::Changed over every run).
RenderFrame comparison_frame(const std::vector<PictureRun>& runs);
// The label under a back-end's name: its model size and its memory, e.g.
// {"1 234 vertices, 2 301 triangles, 88 constrained edges", "memory 61.2 KiB"} or
// {"20 164 cells", "memory 198.9 KiB"}.
std::vector<std::string> run_caption_lines(const Json& summary);

Image side_by_side(Renderer& renderer, const std::vector<PictureRun>& runs, const RenderFrame& frame);
// Needs two runs or more (std::invalid_argument otherwise): runs[i] - runs[0], i >= 1.
Image difference_map(const std::vector<PictureRun>& runs, const RenderFrame& frame);

// Writes side_by_side.png, and difference.png when there are two runs or more, into dir
// (each whole or not at all). Returns the files written.
std::vector<std::filesystem::path> write_compare_pictures(const std::filesystem::path& dir,
                                                          const std::vector<PictureRun>& runs);

}  // namespace sb
