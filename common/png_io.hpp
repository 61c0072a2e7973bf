#pragma once
// PNG reading and writing through libpng: 16-bit grey heightmaps and 8-bit RGB images.
// Writers go through write_atomically, so a file appears whole or not at all.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace sb {

struct Png16 {
  std::size_t width = 0, height = 0;
  std::vector<std::uint16_t> values;  // row-major, row 0 at the top of the image
};

// Largest accepted side of a heightmap, in pixels (a 2^15 square is 2 GiB of samples).
constexpr std::uint32_t kMaxPngSide = 32768;

// Throws InputError naming `field` when the file is missing, not a regular file, not a PNG,
// not 16-bit grey, larger than kMaxPngSide, or declares more pixels than its size can hold
// (checked before any allocation). Interlaced (Adam7) files are read correctly.
// Cost: O(pixels) time, 2 bytes per pixel and channel of transient memory.
Png16 read_png16(const std::filesystem::path& file, const std::string& field);
// What read_png16 would read, from the header alone (the same checks, no pixels decoded):
// for estimating memory before reading. O(1).
struct Png16Size {
  std::size_t width = 0, height = 0;
  std::size_t channels = 1;  // 1 grey, 2 grey and alpha
};
Png16Size read_png16_size(const std::filesystem::path& file, const std::string& field);
// `text` entries become tEXt chunks (key, value).
void write_png16(const std::filesystem::path& file, const Png16& image,
                 const std::vector<std::pair<std::string, std::string>>& text = {});
// rgb: width * height * 3 bytes, row 0 at the top.
void write_png_rgb(const std::filesystem::path& file, std::size_t width, std::size_t height,
                   const std::vector<std::uint8_t>& rgb);

}  // namespace sb
