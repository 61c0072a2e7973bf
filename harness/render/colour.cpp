#include "harness/render/colour.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>

namespace sb {

namespace {
struct Stop {
  double t;
  UnitRgb c;
};

template <std::size_t N>
UnitRgb ramp(const std::array<Stop, N>& stops, double t) {
  t = std::clamp(t, stops.front().t, stops.back().t);
  for (std::size_t i = 1; i < N; ++i) {
    if (t <= stops[i].t) {
      const double u = (t - stops[i - 1].t) / (stops[i].t - stops[i - 1].t);
      const UnitRgb& a = stops[i - 1].c;
      const UnitRgb& b = stops[i].c;
      return {a.r + (b.r - a.r) * u, a.g + (b.g - a.g) * u, a.b + (b.b - a.b) * u};
    }
  }
  return stops.back().c;
}

constexpr std::array<Stop, 5> kHeight = {{{0.00, {0.15, 0.22, 0.48}},
                                          {0.25, {0.16, 0.48, 0.62}},
                                          {0.50, {0.38, 0.68, 0.44}},
                                          {0.75, {0.86, 0.79, 0.42}},
                                          {1.00, {0.99, 0.95, 0.84}}}};
constexpr std::array<Stop, 5> kDiverging = {{{-1.0, {0.12, 0.28, 0.64}},
                                             {-0.5, {0.47, 0.66, 0.88}},
                                             {0.00, {0.97, 0.97, 0.97}},
                                             {0.50, {0.94, 0.58, 0.44}},
                                             {1.00, {0.68, 0.09, 0.14}}}};
}  // namespace

UnitRgb height_colour(double t) { return ramp(kHeight, t); }
UnitRgb diverging_colour(double t) { return ramp(kDiverging, t); }
Rgb to_rgb(const UnitRgb& c) { return rgb_from_unit(c.r, c.g, c.b); }

double nice_step(double range, int count) {
  if (!(range > 0.0) || count < 1) return 0.0;
  const double raw = range / count;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 2.5, 5.0, 10.0})
    if (m * p >= raw * (1.0 - 1e-9)) return m * p;
  return 10.0 * p;
}

double nice_ceil(double v) { return nice_step(v, 1); }

double fine_ceil(double v) {
  if (!(v > 0.0)) return 0.0;
  const double p = std::pow(10.0, std::floor(std::log10(v)));
  for (double m : {1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0})
    if (m * p >= v * (1.0 - 1e-9)) return m * p;
  return 10.0 * p;
}

std::string format_tick(double value, double step, bool plus) {
  if (std::abs(value) < 1e-12 * std::max(1.0, std::abs(step))) return "0";
  // Enough decimals to write the step itself exactly (0.0025 needs 4, 0.0015 needs 4).
  int decimals = 0;
  if (step > 0.0) {
    decimals = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
    while (decimals < 12) {
      const double scaled = step * std::pow(10.0, decimals);
      if (std::abs(scaled - std::round(scaled)) < 1e-6 * scaled) break;
      ++decimals;
    }
  }
  char buf[64];
  std::snprintf(buf, sizeof buf, plus ? "%+.*f" : "%.*f", decimals, value);
  return buf;
}

std::string format_count(long long n) {
  std::string digits = std::to_string(n < 0 ? -n : n);
  std::string out;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ' ';
    out += digits[i];
  }
  return n < 0 ? "-" + out : out;
}

}  // namespace sb
