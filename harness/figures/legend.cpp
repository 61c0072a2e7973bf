#include "harness/figures/legend.hpp"

#include <algorithm>
#include <cmath>

#include "harness/render/colour.hpp"

namespace sb {

namespace {
constexpr Rgb kInk{30, 30, 30};
constexpr int kPad = 6;

std::vector<double> ticks(const ColourBar& bar) {
  std::vector<double> out;
  if (!(bar.tick_step > 0.0) || !(bar.hi > bar.lo)) return out;
  for (double k = std::ceil(bar.lo / bar.tick_step - 1e-9); k * bar.tick_step <= bar.hi * (1 + 1e-12) + 1e-15; ++k)
    out.push_back(k * bar.tick_step);
  return out;
}

int bar_width(int scale) { return 8 * scale + 6; }
}  // namespace

BoxSize colour_bar_size(const ColourBar& bar, int bar_height, int scale) {
  int labels = 0;
  for (double t : ticks(bar))
    labels = std::max(labels, text_width(format_tick(t, bar.tick_step, bar.plus_sign), scale));
  const int line = text_height(scale) + 2 * scale;
  int width = bar_width(scale) + 4 * scale + labels;
  width = std::max({width, text_width(bar.title, scale), text_width(bar.note, scale)});
  int height = bar_height + line + text_height(scale);  // title above, half a label below
  if (!bar.note.empty()) height += line;
  return {width + 2 * kPad, height + 2 * kPad};
}

void draw_colour_bar(Canvas& image, int x, int y, const ColourBar& bar, int bar_height, int scale, bool backdrop) {
  const BoxSize box = colour_bar_size(bar, bar_height, scale);
  if (backdrop) {
    image.fill_rect(x, y, box.width, box.height, {255, 255, 255});
    image.draw_rect(x, y, box.width, box.height, {160, 160, 160});
  }
  const int line = text_height(scale) + 2 * scale;
  image.draw_text(x + kPad, y + kPad, bar.title, kInk, scale);
  const int bx = x + kPad, by = y + kPad + line + text_height(scale) / 2, bw = bar_width(scale);
  for (int row = 0; row < bar_height; ++row) {
    const double v = bar.hi - (bar.hi - bar.lo) * (row + 0.5) / bar_height;
    image.fill_rect(bx, by + row, bw, 1, bar.colour(v));
  }
  for (double m : bar.marks) {
    if (m < bar.lo || m > bar.hi) continue;
    const int my = by + static_cast<int>(std::lround((bar.hi - m) / (bar.hi - bar.lo) * (bar_height - 1)));
    image.fill_rect(bx, my, bw, 1, {40, 30, 20});
  }
  image.draw_rect(bx - 1, by - 1, bw + 2, bar_height + 2, kInk);
  for (double t : ticks(bar)) {
    const int ty = by + static_cast<int>(std::lround((bar.hi - t) / (bar.hi - bar.lo) * (bar_height - 1)));
    image.fill_rect(bx + bw, ty, 3 * scale, std::max(1, scale / 2), kInk);
    image.draw_text(bx + bw + 4 * scale, ty - 3 * scale, format_tick(t, bar.tick_step, bar.plus_sign), kInk, scale);
  }
  if (!bar.note.empty())
    image.draw_text(x + kPad, by + bar_height + text_height(scale) / 2 + 2 * scale, bar.note, kInk, scale);
}

}  // namespace sb
