#pragma once
// Image: an 8-bit RGB picture, row 0 at the top: what the renderer reads back, box
// downsampling and PNG output. Figures are composed on a Canvas (harness/figures/canvas.hpp).
// Every operation is O(pixels touched); nothing depends on time or locale.
#include <cstdint>
#include <filesystem>
#include <vector>

namespace sb {

struct Rgb {
  std::uint8_t r = 0, g = 0, b = 0;
  friend bool operator==(const Rgb&, const Rgb&) = default;
};

// Rgb from linear components in [0, 1] (clamped, rounded).
Rgb rgb_from_unit(double r, double g, double b);

class Image {
 public:
  Image() = default;
  Image(int width, int height, Rgb fill = {255, 255, 255});

  int width() const { return width_; }
  int height() const { return height_; }
  Rgb at(int x, int y) const;
  void set(int x, int y, const Rgb& c);  // ignored outside the image
  // Luminance (Rec. 709 weights on the stored values), in [0, 1].
  double luminance(int x, int y) const;
  const std::vector<std::uint8_t>& bytes() const { return rgb_; }
  std::vector<std::uint8_t>& bytes() { return rgb_; }

 private:
  int width_ = 0, height_ = 0;
  std::vector<std::uint8_t> rgb_;
};

// Averages factor x factor blocks (the image's size must be a multiple of factor).
Image downsample(const Image& src, int factor);
// Writes a PNG (no time chunk: same image, same bytes), whole or not at all.
void write_png(const std::filesystem::path& file, const Image& image);

}  // namespace sb
