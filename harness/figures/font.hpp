#pragma once
// A small hand-drawn bitmap font for labels: printable ASCII in 5x7 cells (plus two rows
// of descender), scaled by whole pixels. No font library, same pixels everywhere.
// Drawing costs O(characters * scale^2 * 45).
#include <string_view>

#include "harness/render/image.hpp"

namespace sb {

// Pixel size of a line of text at the given scale (height covers descenders).
int text_width(std::string_view text, int scale);
int text_height(int scale);
// Draws text with its top-left corner at (x, y); characters outside ASCII 32..126 show as '?'.
void draw_text(Image& image, int x, int y, std::string_view text, const Rgb& colour, int scale);

}  // namespace sb
