#pragma once
// A finished picture of one surface: the renderer's image plus, with contours, a legend
// (height colour bar in metres and the contour step) in its lower-right corner. A surface
// without triangles (a run file that kept only its raster) is drawn from `raster`.
#include "common/raster.hpp"
#include "common/terrain.hpp"
#include "harness/render/renderer.hpp"

namespace sb {

Image render_picture(Renderer& renderer, const SurfaceMesh& mesh, const Raster& raster, const RenderFrame& frame,
                     const RenderOptions& options);

}  // namespace sb
