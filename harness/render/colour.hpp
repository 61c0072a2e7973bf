#pragma once
// Colour maps and tick arithmetic shared by the renderer and the comparison pictures:
// a height map for contour pictures, a diverging map for differences, and "nice" steps
// (1, 2, 2.5, 5 x 10^k) for contours, colour bars and axes. All O(1).
#include <string>

#include "harness/render/image.hpp"

namespace sb {

struct UnitRgb {
  double r = 0, g = 0, b = 0;  // linear components in [0, 1]
};

// Heights: t = 0 lowest (deep blue) ... t = 1 highest (pale sand); clamped.
UnitRgb height_colour(double t);
// Differences: t = -1 blue, 0 white, +1 red; clamped.
UnitRgb diverging_colour(double t);
Rgb to_rgb(const UnitRgb& c);

// The smallest nice step (1, 2, 2.5 or 5 times a power of ten) that cuts range into at
// most `count` intervals; range <= 0 gives 0.
double nice_step(double range, int count);
// The smallest nice number >= v (v > 0).
double nice_ceil(double v);
// The smallest of 1, 1.5, 2, 2.5, 3, 4, 5, 6, 8 times a power of ten >= v (v > 0): a colour
// scale that uses most of its range.
double fine_ceil(double v);
// A tick value with the decimals that write `step` exactly ("0.105", "-0.002"); `plus`
// prefixes positive values with '+'. Exact zero prints "0".
std::string format_tick(double value, double step, bool plus = false);
// Bytes as "123 B", "45.6 KiB", "7.89 MiB".
std::string format_bytes(double bytes);
// An integer with thin grouping: 1234567 -> "1 234 567".
std::string format_count(long long n);

}  // namespace sb
