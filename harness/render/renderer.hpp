#pragma once
// Renderer: offscreen OpenGL through OSMesa (llvmpipe; no GPU or display). One camera, one
// light and one sand material for every back-end, so pictures differ only by the terrain:
// smooth-shaded sand (per-pixel Lambert), optional wireframe with constrained edges in red,
// optional height colour map with contour lines. Each image is drawn at `supersample` times
// its size and box-filtered down. The same mesh, frame and options give the same pixels.
// Cost: O(V + T log T) to prepare (edges), then GPU-side O(T + pixels * supersample^2);
// a context costs a few megabytes and some milliseconds to create, so reuse a Renderer.
#include <memory>

#include "common/terrain.hpp"
#include "harness/render/camera.hpp"
#include "harness/render/frame.hpp"
#include "harness/render/image.hpp"

namespace sb {

enum class View {
  Oblique,  // perspective, from the south-south-east, 40 degrees above the horizon, framing the region
  Top,      // orthographic, straight down, +y up; frame.region fills the image exactly when aspects agree
};

struct RenderOptions {
  View view = View::Oblique;
  bool wireframe = false;
  bool contours = false;  // height colour map; contour lines at (k + 1/2) * frame.contour_step_m
  int width = 1024, height = 768;
  int supersample = 2;  // lowered when the drawn size would exceed the GL limit or 48 Mpixel
};

class Renderer {
 public:
  Renderer();  // throws std::runtime_error when no OSMesa context can be made
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Throws std::invalid_argument for sizes outside [1, max_size()] or a bad mesh.
  Image render(const SurfaceMesh& mesh, const RenderFrame& frame, const RenderOptions& options);
  int max_size() const;  // the largest width or height the context can draw

 private:
  struct Gl;
  std::unique_ptr<Gl> gl_;
};

}  // namespace sb
