#include "harness/figures/canvas.hpp"

#include <cairo-ft.h>
#include <cairo.h>
#include <ft2build.h>
#include FT_FREETYPE_H

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>

namespace sb {

namespace {
constexpr const char* kFontFile = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

// DejaVu Sans as a Cairo font face, loaded once for the process (the FreeType library and
// face live as long as it).
cairo_font_face_t* dejavu_sans() {
  static cairo_font_face_t* const face = [] {
    if (!std::filesystem::exists(kFontFile))
      throw std::runtime_error(std::string("figures need the DejaVu Sans font, not found at ") + kFontFile +
                               " (Debian package fonts-dejavu-core; `make deps` installs it)");
    FT_Library library = nullptr;
    FT_Face ft_face = nullptr;
    if (FT_Init_FreeType(&library) != 0 || FT_New_Face(library, kFontFile, 0, &ft_face) != 0)
      throw std::runtime_error(std::string("FreeType cannot read the font ") + kFontFile);
    return cairo_ft_font_face_create_for_ft_face(ft_face, 0);
  }();
  return face;
}

double font_px(int scale) { return 8.0 * scale; }

// Selects the font at `scale` with fixed options (grey anti-aliasing, no hinting), whatever
// the machine's fontconfig says.
void use_font(cairo_t* cr, int scale) {
  cairo_set_font_face(cr, dejavu_sans());
  cairo_set_font_size(cr, font_px(scale));
  cairo_font_options_t* options = cairo_font_options_create();
  cairo_font_options_set_antialias(options, CAIRO_ANTIALIAS_GRAY);
  cairo_font_options_set_hint_style(options, CAIRO_HINT_STYLE_NONE);
  cairo_font_options_set_hint_metrics(options, CAIRO_HINT_METRICS_OFF);
  cairo_set_font_options(cr, options);
  cairo_font_options_destroy(options);
}

void set_colour(cairo_t* cr, const Rgb& c) { cairo_set_source_rgb(cr, c.r / 255.0, c.g / 255.0, c.b / 255.0); }

// A 1x1 context for measuring text without a canvas (one per thread).
cairo_t* measuring_context() {
  thread_local struct Measure {
    cairo_surface_t* surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, 1, 1);
    cairo_t* cr = cairo_create(surface);
    ~Measure() {
      cairo_destroy(cr);
      cairo_surface_destroy(surface);
    }
  } measure;
  return measure.cr;
}

std::uint32_t pack(const Rgb& c) {
  return 0xff000000u | (std::uint32_t{c.r} << 16) | (std::uint32_t{c.g} << 8) | std::uint32_t{c.b};
}
}  // namespace

Canvas::Canvas(int width, int height, Rgb fill)
    : width_(width),
      height_(height),
      surface_(cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height)),
      cr_(cairo_create(surface_)) {
  fill_rect(0, 0, width, height, fill);
}

Canvas::Canvas(const Image& background) : Canvas(background.width(), background.height(), {255, 255, 255}) {
  draw_image(background, 0, 0);
}

Canvas::~Canvas() {
  cairo_destroy(cr_);
  cairo_surface_destroy(surface_);
}

void Canvas::fill_rect(int x, int y, int w, int h, const Rgb& c) {
  set_colour(cr_, c);
  cairo_rectangle(cr_, x, y, w, h);
  cairo_fill(cr_);
}

void Canvas::draw_rect(int x, int y, int w, int h, const Rgb& c) {
  set_colour(cr_, c);
  cairo_set_line_width(cr_, 1.0);
  cairo_rectangle(cr_, x + 0.5, y + 0.5, w - 1, h - 1);  // on pixel centres: crisp lines
  cairo_stroke(cr_);
}

void Canvas::draw_image(const Image& image, int x, int y) {
  cairo_surface_flush(surface_);
  unsigned char* data = cairo_image_surface_get_data(surface_);
  const int stride = cairo_image_surface_get_stride(surface_);
  for (int sy = std::max(0, -y); sy < image.height() && y + sy < height_; ++sy) {
    auto* row = reinterpret_cast<std::uint32_t*>(data + static_cast<std::ptrdiff_t>(y + sy) * stride);
    for (int sx = std::max(0, -x); sx < image.width() && x + sx < width_; ++sx) row[x + sx] = pack(image.at(sx, sy));
  }
  cairo_surface_mark_dirty(surface_);
}

void Canvas::draw_text(int x, int y, std::string_view text, const Rgb& c, int scale) {
  use_font(cr_, scale);
  cairo_font_extents_t font;
  cairo_font_extents(cr_, &font);
  set_colour(cr_, c);
  cairo_move_to(cr_, x, y + font.ascent);
  cairo_show_text(cr_, std::string(text).c_str());
  cairo_new_path(cr_);
}

Image Canvas::image() const {
  cairo_surface_flush(surface_);
  const unsigned char* data = cairo_image_surface_get_data(surface_);
  const int stride = cairo_image_surface_get_stride(surface_);
  Image out(width_, height_);
  for (int y = 0; y < height_; ++y) {
    const auto* row = reinterpret_cast<const std::uint32_t*>(data + static_cast<std::ptrdiff_t>(y) * stride);
    for (int x = 0; x < width_; ++x)
      out.set(x, y,
              {static_cast<std::uint8_t>(row[x] >> 16), static_cast<std::uint8_t>(row[x] >> 8),
               static_cast<std::uint8_t>(row[x])});
  }
  return out;
}

int text_width(std::string_view text, int scale) {
  if (text.empty()) return 0;
  cairo_t* cr = measuring_context();
  use_font(cr, scale);
  cairo_text_extents_t extents;
  cairo_text_extents(cr, std::string(text).c_str(), &extents);
  return static_cast<int>(std::ceil(extents.x_advance));
}

int text_height(int scale) {
  cairo_t* cr = measuring_context();
  use_font(cr, scale);
  cairo_font_extents_t font;
  cairo_font_extents(cr, &font);
  return static_cast<int>(std::ceil(font.ascent + font.descent));
}

}  // namespace sb
