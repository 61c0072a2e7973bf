#include "harness/render/image.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/png_io.hpp"

namespace sb {

namespace {
std::uint8_t to_byte(double v) { return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0)); }
}  // namespace

Rgb rgb_from_unit(double r, double g, double b) { return {to_byte(r), to_byte(g), to_byte(b)}; }

Image::Image(int width, int height, Rgb fill) : width_(width), height_(height) {
  if (width <= 0 || height <= 0) throw std::invalid_argument("Image: size must be positive");
  rgb_.resize(static_cast<std::size_t>(width) * height * 3);
  for (std::size_t i = 0; i < rgb_.size(); i += 3) {
    rgb_[i] = fill.r;
    rgb_[i + 1] = fill.g;
    rgb_[i + 2] = fill.b;
  }
}

Rgb Image::at(int x, int y) const {
  const std::size_t i = (static_cast<std::size_t>(y) * width_ + x) * 3;
  return {rgb_[i], rgb_[i + 1], rgb_[i + 2]};
}

void Image::set(int x, int y, const Rgb& c) {
  if (x < 0 || y < 0 || x >= width_ || y >= height_) return;
  const std::size_t i = (static_cast<std::size_t>(y) * width_ + x) * 3;
  rgb_[i] = c.r;
  rgb_[i + 1] = c.g;
  rgb_[i + 2] = c.b;
}

double Image::luminance(int x, int y) const {
  const Rgb c = at(x, y);
  return (0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b) / 255.0;
}

Image downsample(const Image& src, int factor) {
  if (factor <= 1) return src;
  if (src.width() % factor != 0 || src.height() % factor != 0)
    throw std::invalid_argument("downsample: size is not a multiple of the factor");
  Image out(src.width() / factor, src.height() / factor);
  const int n = factor * factor;
  const auto& in = src.bytes();
  auto& dst = out.bytes();
  for (int y = 0; y < out.height(); ++y)
    for (int x = 0; x < out.width(); ++x)
      for (int ch = 0; ch < 3; ++ch) {
        int sum = 0;
        for (int dy = 0; dy < factor; ++dy)
          for (int dx = 0; dx < factor; ++dx)
            sum += in[((static_cast<std::size_t>(y) * factor + dy) * src.width() + x * factor + dx) * 3 + ch];
        dst[(static_cast<std::size_t>(y) * out.width() + x) * 3 + ch] = static_cast<std::uint8_t>((sum + n / 2) / n);
      }
  return out;
}

void write_png(const std::filesystem::path& file, const Image& image) {
  write_png_rgb(file, static_cast<std::size_t>(image.width()), static_cast<std::size_t>(image.height()), image.bytes());
}

}  // namespace sb
