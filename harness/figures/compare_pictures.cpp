#include "harness/figures/compare_pictures.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "harness/figures/canvas.hpp"
#include "harness/figures/legend.hpp"
#include "harness/figures/picture.hpp"
#include "harness/render/colour.hpp"

namespace sb {

namespace {
constexpr Rgb kPaper{255, 255, 255};
constexpr Rgb kInk{25, 25, 25};
constexpr Rgb kGrey{90, 90, 90};
constexpr int kPanelW = 640, kPanelH = 480, kGap = 16, kMargin = 16;

long long count(const Json& s, const char* key) {
  return s.contains(key) && s.at(key).is_number() ? s.at(key).get<long long>() : 0;
}

std::string region_text(const RenderFrame& f) {
  const double step = nice_step((f.region.hi - f.region.lo).maxCoeff(), 20);
  return "x " + format_tick(f.region.lo.x(), step) + ".." + format_tick(f.region.hi.x(), step) + " m, y " +
         format_tick(f.region.lo.y(), step) + ".." + format_tick(f.region.hi.y(), step) + " m";
}

// Splits text at ", " so that each line fits max_width pixels at the given scale.
std::vector<std::string> wrap(const std::string& text, int max_width, int scale) {
  std::vector<std::string> lines;
  std::string line;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = text.find(", ", start);
    const std::string part = text.substr(start, comma == std::string::npos ? std::string::npos : comma + 1 - start);
    if (!line.empty() && text_width(line + " " + part, scale) > max_width) {
      lines.push_back(line);
      line.clear();
    }
    line += (line.empty() ? "" : " ") + part;
    if (comma == std::string::npos) break;
    start = comma + 2;
  }
  if (!line.empty()) lines.push_back(line);
  return lines;
}

std::string metres(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return std::string(buf) + " m";
}

// Hillshade factor of a raster at p, 1 on level ground: relief under the heat map.
double relief(const Raster& r, const Vec2& p, const Vec3& light) {
  const double h = r.spacing_m;
  const double dx = (r.interpolate(p + Vec2(h, 0)) - r.interpolate(p - Vec2(h, 0))) / (2 * h);
  const double dy = (r.interpolate(p + Vec2(0, h)) - r.interpolate(p - Vec2(0, h))) / (2 * h);
  const Vec3 n = Vec3(-dx, -dy, 1.0).normalized();
  return std::clamp(1.0 + 0.6 * (std::max(0.0, n.dot(light)) - light.z()), 0.55, 1.2);
}

// Draws a heat map of runs[a] - runs[b] over the frame's region into image at (x, y).
void heat_map(Canvas& image, int x, int y, int w, int h, const Raster& a, const Raster& b, const RenderFrame& f,
              double scale_m) {
  const Vec3 light = light_direction();
  const Vec2 size = f.region.hi - f.region.lo;
  Image map(w, h);
  for (int py = 0; py < h; ++py)
    for (int px = 0; px < w; ++px) {
      const Vec2 p(f.region.lo.x() + (px + 0.5) / w * size.x(), f.region.hi.y() - (py + 0.5) / h * size.y());
      const UnitRgb c = diverging_colour((a.interpolate(p) - b.interpolate(p)) / scale_m);
      const double k = relief(b, p, light);
      map.set(px, py, rgb_from_unit(c.r * k, c.g * k, c.b * k));
    }
  image.draw_image(map, x, y);
  image.draw_rect(x - 1, y - 1, w + 2, h + 2, kInk);
  // Axes in metres.
  const double step = nice_step(std::max(size.x(), size.y()), 4);
  for (double k = std::ceil(f.region.lo.x() / step - 1e-9); k * step <= f.region.hi.x() + 1e-12; ++k) {
    const int tx = x + static_cast<int>(std::lround((k * step - f.region.lo.x()) / size.x() * (w - 1)));
    image.fill_rect(tx, y + h + 1, 1, 6, kInk);
    const std::string label = format_tick(k * step, step);
    image.draw_text(tx - text_width(label, 2) / 2, y + h + 10, label, kInk, 2);
  }
  for (double k = std::ceil(f.region.lo.y() / step - 1e-9); k * step <= f.region.hi.y() + 1e-12; ++k) {
    const int ty = y + static_cast<int>(std::lround((f.region.hi.y() - k * step) / size.y() * (h - 1)));
    image.fill_rect(x - 7, ty, 6, 1, kInk);
    const std::string label = format_tick(k * step, step);
    image.draw_text(x - 10 - text_width(label, 2), ty - 6, label, kInk, 2);
  }
}
}  // namespace

RenderFrame comparison_frame(const std::vector<PictureRun>& runs) {
  std::vector<FrameSurface> surfaces;
  for (const PictureRun& r : runs) surfaces.push_back({r.initial, r.final});
  return make_frame(surfaces, FrameRegion::Changed);
}

std::vector<std::string> run_caption_lines(const Json& s) {
  std::string text;
  auto add = [&](long long n, const char* what) {
    if (n <= 0) return;
    if (!text.empty()) text += ", ";
    text += format_count(n) + " " + what;
  };
  add(count(s, "vertices"), "vertices");
  add(count(s, "triangles"), "triangles");
  add(count(s, "constrained_edges"), "constrained edges");
  add(count(s, "cells"), "cells");
  return {text, "memory " + format_bytes(static_cast<double>(count(s, "memory_bytes")))};
}

Image side_by_side(Renderer& renderer, const std::vector<PictureRun>& runs, const RenderFrame& frame) {
  if (runs.empty()) throw std::invalid_argument("side_by_side: no runs");
  const int n = static_cast<int>(runs.size());
  std::vector<std::vector<std::string>> captions;
  std::size_t caption_lines = 0;
  for (const PictureRun& r : runs) {
    captions.emplace_back();
    for (const std::string& line : run_caption_lines(*r.summary))
      for (const std::string& part : wrap(line, kPanelW, 2)) captions.back().push_back(part);
    caption_lines = std::max(caption_lines, captions.back().size());
  }
  const int line_h = text_height(2) + 4;
  const int title_h = text_height(2) + 12;
  const int header_h = text_height(3) + 10 + static_cast<int>(caption_lines) * line_h + 6;
  const int footer_h = 2 * (text_height(2) + 6) + 8;
  const int width = 2 * kMargin + n * kPanelW + (n - 1) * kGap;
  const int height = kMargin + title_h + header_h + 2 * kPanelH + kGap + footer_h + kMargin;
  Canvas image(width, height, kPaper);

  const Json& first = *runs.front().summary;
  std::string title = "sandbench compare";
  if (first.contains("scene") && first.at("scene").is_string())
    title += ": " + std::filesystem::path(first.at("scene").get<std::string>()).filename().string();
  if (first.contains("stamps")) title += ", " + std::to_string(count(first, "stamps")) + " stamps";
  image.draw_text(kMargin, kMargin, title, kGrey, 2);

  RenderOptions oblique;
  oblique.width = kPanelW;
  oblique.height = kPanelH;
  RenderOptions top = oblique;
  top.view = View::Top;
  top.wireframe = true;
  for (int i = 0; i < n; ++i) {
    const PictureRun& r = runs[static_cast<std::size_t>(i)];
    const int x = kMargin + i * (kPanelW + kGap);
    int y = kMargin + title_h;
    image.draw_text(x, y, r.label, kInk, 3);
    const std::vector<std::string>& caption = captions[static_cast<std::size_t>(i)];
    for (std::size_t k = 0; k < caption.size(); ++k)
      image.draw_text(x, y + text_height(3) + 10 + static_cast<int>(k) * line_h, caption[k], kInk, 2);
    y += header_h;
    image.draw_image(render_picture(renderer, *r.mesh, *r.final, frame, oblique), x, y);
    image.draw_image(render_picture(renderer, *r.mesh, *r.final, frame, top), x, y + kPanelH + kGap);
  }
  const int fy = height - kMargin - footer_h + 8;
  image.draw_text(kMargin, fy, "Top row: oblique view, smooth shaded; one camera, light and sand for all.", kGrey, 2);
  image.draw_text(kMargin, fy + text_height(2) + 6,
                  "Bottom row: top view with mesh edges (red: constrained). Region " + region_text(frame) + ".", kGrey,
                  2);
  return image.image();
}

Image difference_map(const std::vector<PictureRun>& runs, const RenderFrame& frame) {
  if (runs.size() < 2) throw std::invalid_argument("difference_map: needs two runs or more");
  const Raster& base = *runs.front().final;
  const Vec2 size = frame.region.hi - frame.region.lo;
  int map_w = 560, map_h = static_cast<int>(std::lround(map_w * size.y() / size.x()));
  if (map_h > 640) {
    map_h = 640;
    map_w = static_cast<int>(std::lround(map_h * size.x() / size.y()));
  }
  map_h = std::max(map_h, 120);
  map_w = std::max(map_w, 120);

  // One symmetric scale for every panel: the largest difference inside the region.
  double largest = 0.0;
  for (std::size_t i = 1; i < runs.size(); ++i)
    for (std::size_t iy = 0; iy < base.ny; ++iy)
      for (std::size_t ix = 0; ix < base.nx; ++ix)
        if (frame.region.contains(base.point(ix, iy)))
          largest = std::max(largest, std::abs(runs[i].final->at(ix, iy) - base.at(ix, iy)));
  const double scale_m = largest > 0.0 ? fine_ceil(largest) : 1e-4;

  ColourBar bar;
  bar.lo = -scale_m;
  bar.hi = scale_m;
  bar.colour = [&](double v) { return to_rgb(diverging_colour(v / scale_m)); };
  bar.tick_step = scale_m / 2.0;
  bar.plus_sign = true;
  bar.title = "difference (m)";
  bar.note = "red: higher than " + runs.front().label;
  const BoxSize bar_box = colour_bar_size(bar, map_h * 3 / 4, 2);

  const int panels = static_cast<int>(runs.size()) - 1;
  const int left = 10 * 12, title_h = text_height(2) + 14, head_h = text_height(3) + text_height(2) + 18;
  const int bottom = 2 * text_height(2) + 30, footer_h = text_height(2) + 12;
  const int panel_w = left + map_w + kGap;
  const int width = 2 * kMargin + panels * panel_w + bar_box.width + kGap;
  const int height = kMargin + title_h + head_h + map_h + bottom + footer_h + kMargin;
  Canvas image(width, height, kPaper);
  image.draw_text(kMargin, kMargin, "Height difference on the common raster (" + metres(base.spacing_m) + " spacing)",
                  kGrey, 2);
  const int map_y = kMargin + title_h + head_h;
  for (int i = 0; i < panels; ++i) {
    const PictureRun& a = runs[static_cast<std::size_t>(i) + 1];
    const RasterDifference d = compare_rasters(*a.final, base);
    const int x = kMargin + i * panel_w + left;
    image.draw_text(x, kMargin + title_h, a.label + " - " + runs.front().label, kInk, 3);
    image.draw_text(x, kMargin + title_h + text_height(3) + 6,
                    "RMSE " + metres(d.rmse_m) + ", max |d| " + metres(d.max_abs_m), kInk, 2);
    heat_map(image, x, map_y, map_w, map_h, *a.final, base, frame, scale_m);
    image.draw_text(x + map_w / 2 - text_width("x (m)", 2) / 2, map_y + map_h + text_height(2) + 16, "x (m)", kGrey, 2);
    image.draw_text(x - left + 4, map_y - text_height(2) - 4, "y (m)", kGrey, 2);
  }
  draw_colour_bar(image, kMargin + panels * panel_w, map_y, bar, map_h * 3 / 4, 2, false);
  image.draw_text(kMargin, height - kMargin - text_height(2),
                  "RMSE and max |d| over the whole raster; grey relief: " + runs.front().label + "'s surface.", kGrey,
                  2);
  return image.image();
}

std::vector<std::filesystem::path> write_compare_pictures(const std::filesystem::path& dir,
                                                          const std::vector<PictureRun>& runs) {
  std::vector<std::filesystem::path> written;
  if (runs.empty()) return written;
  const RenderFrame frame = comparison_frame(runs);
  Renderer renderer;
  const Image sides = side_by_side(renderer, runs, frame);
  write_png(dir / "side_by_side.png", sides);
  written.push_back(dir / "side_by_side.png");
  if (runs.size() >= 2) {
    write_png(dir / "difference.png", difference_map(runs, frame));
    written.push_back(dir / "difference.png");
  }
  return written;
}

}  // namespace sb
