#pragma once
// Canvas: a Cairo image surface on which the figures are composed -- rectangles, rendered
// images and text in DejaVu Sans (anti-aliased in grey, unhinted, so the same drawing calls
// give the same pixels with the same Cairo and FreeType). Text sizes are given as a `scale`:
// the font is 8 * scale pixels high (em), a line text_height(scale). The font is
// /usr/share/fonts/truetype/dejavu/DejaVuSans.ttf (Debian: fonts-dejavu-core); without it,
// drawing or measuring text throws std::runtime_error saying so.
// Costs: O(pixels touched) per call; making a canvas or taking its image() is O(pixels).
#include <string_view>

#include "harness/render/image.hpp"

typedef struct _cairo cairo_t;
typedef struct _cairo_surface cairo_surface_t;

namespace sb {

class Canvas {
 public:
  Canvas(int width, int height, Rgb fill);
  explicit Canvas(const Image& background);
  ~Canvas();
  Canvas(const Canvas&) = delete;
  Canvas& operator=(const Canvas&) = delete;

  int width() const { return width_; }
  int height() const { return height_; }
  void fill_rect(int x, int y, int w, int h, const Rgb& c);  // clipped to the canvas
  void draw_rect(int x, int y, int w, int h, const Rgb& c);  // 1-pixel outline, inside the box
  void draw_image(const Image& image, int x, int y);         // clipped to the canvas
  // Text with the top-left corner of its line box at (x, y).
  void draw_text(int x, int y, std::string_view text, const Rgb& c, int scale);
  Image image() const;  // the pixels as RGB

 private:
  int width_, height_;
  cairo_surface_t* surface_;
  cairo_t* cr_;
};

// Width in pixels of a line of text (rounded up) and height of a line at the given scale.
int text_width(std::string_view text, int scale);
int text_height(int scale);

}  // namespace sb
