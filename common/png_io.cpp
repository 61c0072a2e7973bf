#include "common/png_io.hpp"

#include <png.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>

#include "common/atomic_file.hpp"
#include "common/input_error.hpp"

namespace sb {

namespace {
struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

[[noreturn]] void png_error_handler(png_structp, png_const_charp message) { throw std::runtime_error(message); }
void png_warning_handler(png_structp, png_const_charp) {}

void write_png_file(const std::filesystem::path& tmp, std::size_t width, std::size_t height, int color_type,
                    int bit_depth, const std::vector<std::vector<png_byte>>& rows,
                    const std::vector<std::pair<std::string, std::string>>& text);

// Writes one PNG with the given colour type and 8 or 16 bits per sample; rows big-endian.
void write_png(const std::filesystem::path& file, std::size_t width, std::size_t height, int color_type, int bit_depth,
               const std::vector<std::vector<png_byte>>& rows,
               const std::vector<std::pair<std::string, std::string>>& text) {
  write_atomically(file, [&](const std::filesystem::path& tmp) {
    try {
      write_png_file(tmp, width, height, color_type, bit_depth, rows, text);
    } catch (const std::runtime_error&) {
      // Disk full, quota, read-only: the user's to fix (exit 2); write_atomically removes tmp.
      throw InputError("cannot write " + file.string() + " (" + std::strerror(errno) + "); nothing was written");
    }
  });
}

void write_png_file(const std::filesystem::path& tmp, std::size_t width, std::size_t height, int color_type,
                    int bit_depth, const std::vector<std::vector<png_byte>>& rows,
                    const std::vector<std::pair<std::string, std::string>>& text) {
  {
    File f(std::fopen(tmp.c_str(), "wb"));
    if (!f) throw std::runtime_error("cannot write " + tmp.string());
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, png_error_handler, png_warning_handler);
    png_infop info = png_create_info_struct(png);
    try {
      png_init_io(png, f.get());
      png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), bit_depth, color_type,
                   PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
      std::vector<png_text> chunks(text.size());
      for (std::size_t i = 0; i < text.size(); ++i) {
        chunks[i].compression = PNG_TEXT_COMPRESSION_NONE;
        chunks[i].key = const_cast<char*>(text[i].first.c_str());
        chunks[i].text = const_cast<char*>(text[i].second.c_str());
      }
      if (!chunks.empty()) png_set_text(png, info, chunks.data(), static_cast<int>(chunks.size()));
      png_write_info(png, info);
      for (const auto& row : rows) png_write_row(png, row.data());
      png_write_end(png, nullptr);
    } catch (...) {
      png_destroy_write_struct(&png, &info);
      throw;
    }
    png_destroy_write_struct(&png, &info);
    if (std::fflush(f.get()) != 0) throw std::runtime_error("cannot write " + tmp.string());
    if (std::fclose(f.release()) != 0) throw std::runtime_error("cannot write " + tmp.string());
  }
}
}  // namespace

namespace {
// Deflate cannot compress better than about 1032:1, so a PNG whose declared pixels need more
// than that many times its file size is truncated or hostile: refuse it before allocating.
constexpr double kMaxDeflateRatio = 1032.0;
}  // namespace

namespace {

// The whole image, or (header_only) its size and channels with no pixels decoded.
Png16 read_png16_file(const std::filesystem::path& file, const std::string& field, bool header_only,
                      std::size_t* channels_out) {
  const std::string what = "scene: " + field + " = \"" + file.string() + "\"";
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) {
    if (std::filesystem::exists(file, ec)) throw InputError(what + " is not a regular file");
    throw InputError(what + " cannot be opened");
  }
  const auto file_bytes = static_cast<double>(std::filesystem::file_size(file, ec));
  File f(std::fopen(file.c_str(), "rb"));
  if (!f) throw InputError(what + " cannot be opened");
  png_byte sig[8];
  if (std::fread(sig, 1, 8, f.get()) != 8 || png_sig_cmp(sig, 0, 8) != 0) throw InputError(what + " is not a PNG file");
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, png_error_handler, png_warning_handler);
  png_infop info = png_create_info_struct(png);
  Png16 out;
  try {
    png_init_io(png, f.get());
    png_set_sig_bytes(png, 8);
    png_set_user_limits(png, kMaxPngSide, kMaxPngSide);
    png_read_info(png, info);
    const int depth = png_get_bit_depth(png, info);
    const int type = png_get_color_type(png, info);
    if (depth != 16 || (type != PNG_COLOR_TYPE_GRAY && type != PNG_COLOR_TYPE_GRAY_ALPHA))
      throw InputError(what + " must be a 16-bit greyscale PNG (got " + std::to_string(depth) + "-bit, colour type " +
                       std::to_string(type) + ")");
    out.width = png_get_image_width(png, info);
    out.height = png_get_image_height(png, info);
    if (out.width < 2 || out.height < 2) throw InputError(what + " must be at least 2x2 pixels");
    const std::size_t channels = type == PNG_COLOR_TYPE_GRAY ? 1 : 2;
    if (channels_out) *channels_out = channels;
    const std::size_t row_bytes = out.width * channels * 2;
    if (static_cast<double>(row_bytes) * static_cast<double>(out.height) > kMaxDeflateRatio * file_bytes)
      throw InputError(what + " declares " + std::to_string(out.width) + "x" + std::to_string(out.height) +
                       " pixels, more than its " + std::to_string(static_cast<long long>(file_bytes)) +
                       " bytes can hold: the file is truncated or corrupt");
    if (header_only) {
      png_destroy_read_struct(&png, &info, nullptr);
      return out;
    }
    // Adam7-interlaced files are stored in seven passes; libpng reassembles them when asked.
    const int passes = png_set_interlace_handling(png);
    png_read_update_info(png, info);
    std::vector<png_byte> pixels(row_bytes * out.height);
    for (int pass = 0; pass < passes; ++pass)
      for (std::size_t r = 0; r < out.height; ++r) png_read_row(png, pixels.data() + r * row_bytes, nullptr);
    out.values.resize(out.width * out.height);
    for (std::size_t r = 0; r < out.height; ++r) {
      const png_byte* row = pixels.data() + r * row_bytes;
      for (std::size_t c = 0; c < out.width; ++c)
        out.values[r * out.width + c] =
            static_cast<std::uint16_t>((row[c * channels * 2] << 8) | row[c * channels * 2 + 1]);
    }
  } catch (const InputError&) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw;
  } catch (const std::exception& e) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw InputError(what + " is not a readable PNG: " + e.what());
  }
  png_destroy_read_struct(&png, &info, nullptr);
  return out;
}

}  // namespace

Png16 read_png16(const std::filesystem::path& file, const std::string& field) {
  return read_png16_file(file, field, /*header_only=*/false, nullptr);
}

Png16Size read_png16_size(const std::filesystem::path& file, const std::string& field) {
  std::size_t channels = 1;
  const Png16 header = read_png16_file(file, field, /*header_only=*/true, &channels);
  return {header.width, header.height, channels};
}

void write_png16(const std::filesystem::path& file, const Png16& image,
                 const std::vector<std::pair<std::string, std::string>>& text) {
  std::vector<std::vector<png_byte>> rows(image.height, std::vector<png_byte>(image.width * 2));
  for (std::size_t r = 0; r < image.height; ++r)
    for (std::size_t c = 0; c < image.width; ++c) {
      const std::uint16_t v = image.values[r * image.width + c];
      rows[r][2 * c] = static_cast<png_byte>(v >> 8);
      rows[r][2 * c + 1] = static_cast<png_byte>(v & 0xff);
    }
  write_png(file, image.width, image.height, PNG_COLOR_TYPE_GRAY, 16, rows, text);
}

void write_png_rgb(const std::filesystem::path& file, std::size_t width, std::size_t height,
                   const std::vector<std::uint8_t>& rgb) {
  std::vector<std::vector<png_byte>> rows(height);
  for (std::size_t r = 0; r < height; ++r)
    rows[r].assign(rgb.begin() + static_cast<std::ptrdiff_t>(r * width * 3),
                   rgb.begin() + static_cast<std::ptrdiff_t>((r + 1) * width * 3));
  write_png(file, width, height, PNG_COLOR_TYPE_RGB, 8, rows, {});
}

}  // namespace sb
