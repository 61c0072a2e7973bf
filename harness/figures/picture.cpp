#include "harness/figures/picture.hpp"

#include <algorithm>
#include <cmath>

#include "harness/figures/legend.hpp"
#include "harness/render/colour.hpp"
#include "harness/render/mesh.hpp"

namespace sb {

Image render_picture(Renderer& renderer, const SurfaceMesh& mesh, const Raster& raster, const RenderFrame& frame,
                     const RenderOptions& options) {
  Image image = mesh.triangles.empty() ? renderer.render(mesh_from_raster(raster), frame, options)
                                       : renderer.render(mesh, frame, options);
  if (!options.contours) return image;
  const double span = frame.z_max_m - frame.z_min_m;
  ColourBar bar;
  bar.lo = frame.z_min_m;
  bar.hi = frame.z_max_m;
  bar.colour = [&](double v) { return to_rgb(height_colour((v - frame.z_min_m) / span)); };
  bar.tick_step = nice_step(span, 4);
  bar.title = "height (m)";
  bar.note = "contours " + format_tick(frame.contour_step_m, frame.contour_step_m) + " m apart";
  for (double k = std::floor(frame.z_min_m / frame.contour_step_m); (k + 0.5) * frame.contour_step_m <= frame.z_max_m;
       ++k)
    bar.marks.push_back((k + 0.5) * frame.contour_step_m);
  const int scale = image.height() >= 600 ? 2 : 1;
  const int bar_h = std::max(40, image.height() / 4);
  const BoxSize box = colour_bar_size(bar, bar_h, scale);
  if (box.width + 8 > image.width() || box.height + 8 > image.height()) return image;  // too small for a legend
  Canvas canvas(image);
  draw_colour_bar(canvas, image.width() - box.width - 8, image.height() - box.height - 8, bar, bar_h, scale, true);
  return canvas.image();
}

}  // namespace sb
