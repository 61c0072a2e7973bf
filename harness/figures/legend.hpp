#pragma once
// Colour bars with ticks and a title, for the contour legend and the difference heat map.
// Drawing is O(bar pixels + text).
#include <functional>
#include <string>
#include <vector>

#include "harness/figures/canvas.hpp"

namespace sb {

struct ColourBar {
  double lo = 0.0, hi = 1.0;  // values at the bottom and the top of the bar
  std::function<Rgb(double value)> colour;
  double tick_step = 0.0;     // ticks at the multiples of this inside [lo, hi]
  bool plus_sign = false;     // "+0.002" for positive ticks
  std::string title;          // above the bar
  std::string note;           // below the bar; may be empty
  std::vector<double> marks;  // values drawn as dark lines across the bar
};

struct BoxSize {
  int width = 0, height = 0;
};

// The box a bar of `bar_height` pixels takes with its labels, text at `scale`.
BoxSize colour_bar_size(const ColourBar& bar, int bar_height, int scale);
// Draws the bar's box with its top-left corner at (x, y); `backdrop` fills it with white first.
void draw_colour_bar(Canvas& image, int x, int y, const ColourBar& bar, int bar_height, int scale, bool backdrop);

}  // namespace sb
