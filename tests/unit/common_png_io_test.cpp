// read_png16 on files the writer never produces: Adam7-interlaced heightmaps and headers that
// declare far more pixels than the file holds.
#include <gtest/gtest.h>
#include <png.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "common/input_error.hpp"
#include "common/png_io.hpp"

namespace sb {
namespace {

namespace fs = std::filesystem;

fs::path temp_dir() {
  const fs::path dir = fs::temp_directory_path() / ("sb_png_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir;
}

// A 16-bit grey PNG written by libpng directly, interlaced or not.
void write_grey16(const fs::path& file, std::size_t w, std::size_t h, const std::vector<std::uint16_t>& v,
                  bool interlaced) {
  std::FILE* f = std::fopen(file.c_str(), "wb");
  ASSERT_NE(f, nullptr);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  png_init_io(png, f);
  png_set_IHDR(png, info, static_cast<png_uint_32>(w), static_cast<png_uint_32>(h), 16, PNG_COLOR_TYPE_GRAY,
               interlaced ? PNG_INTERLACE_ADAM7 : PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  std::vector<std::vector<png_byte>> rows(h, std::vector<png_byte>(w * 2));
  std::vector<png_bytep> pointers(h);
  for (std::size_t r = 0; r < h; ++r) {
    for (std::size_t c = 0; c < w; ++c) {
      rows[r][2 * c] = static_cast<png_byte>(v[r * w + c] >> 8);
      rows[r][2 * c + 1] = static_cast<png_byte>(v[r * w + c] & 0xff);
    }
    pointers[r] = rows[r].data();
  }
  png_write_image(png, pointers.data());  // handles the seven passes when interlaced
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  std::fclose(f);
}

std::string error_of(const fs::path& file) {
  try {
    read_png16(file, "terrain.path");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(PngIo, InterlacedHeightmapReadsLikeTheProgressiveOne) {
  const fs::path dir = temp_dir();
  const std::size_t w = 37, h = 23;  // not multiples of 8: partial Adam7 blocks
  std::vector<std::uint16_t> v(w * h);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = static_cast<std::uint16_t>((i * 7919u) % 65536u);
  write_grey16(dir / "progressive.png", w, h, v, false);
  write_grey16(dir / "interlaced.png", w, h, v, true);
  const Png16 a = read_png16(dir / "progressive.png", "terrain.path");
  const Png16 b = read_png16(dir / "interlaced.png", "terrain.path");
  EXPECT_EQ(a.values, v);
  EXPECT_EQ(b.width, w);
  EXPECT_EQ(b.height, h);
  EXPECT_EQ(b.values, v);
  fs::remove_all(dir);
}

// The PNG chunk CRC (ISO 3309), bit by bit: the test needs only one.
std::uint32_t png_crc(const std::vector<unsigned char>& data) {
  std::uint32_t c = 0xffffffffu;
  for (unsigned char b : data) {
    c ^= b;
    for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xedb88320u ^ (c >> 1) : c >> 1;
  }
  return c ^ 0xffffffffu;
}

// A valid PNG signature and IHDR claiming width x height, followed by nothing useful.
void write_header_only(const fs::path& file, std::uint32_t width, std::uint32_t height) {
  std::vector<unsigned char> bytes = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  const unsigned char ihdr_len[4] = {0, 0, 0, 13};
  bytes.insert(bytes.end(), ihdr_len, ihdr_len + 4);
  std::vector<unsigned char> chunk = {'I', 'H', 'D', 'R'};
  for (std::uint32_t v : {width, height})
    for (int s = 24; s >= 0; s -= 8) chunk.push_back(static_cast<unsigned char>(v >> s));
  chunk.insert(chunk.end(), {16, 0, 0, 0, 0});  // 16-bit grey, deflate, adaptive, progressive
  const std::uint32_t crc = png_crc(chunk);
  bytes.insert(bytes.end(), chunk.begin(), chunk.end());
  for (int s = 24; s >= 0; s -= 8) bytes.push_back(static_cast<unsigned char>(crc >> s));
  // A two-byte IDAT (a zlib header): the header is read up to here before any pixel.
  const std::vector<unsigned char> idat = {'I', 'D', 'A', 'T', 0x78, 0x9c};
  const unsigned char idat_len[4] = {0, 0, 0, 2};
  bytes.insert(bytes.end(), idat_len, idat_len + 4);
  bytes.insert(bytes.end(), idat.begin(), idat.end());
  const std::uint32_t idat_crc = png_crc(idat);
  for (int s = 24; s >= 0; s -= 8) bytes.push_back(static_cast<unsigned char>(idat_crc >> s));
  const unsigned char iend[12] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xae, 0x42, 0x60, 0x82};
  bytes.insert(bytes.end(), iend, iend + 12);
  std::ofstream(file, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

TEST(PngIo, HeaderClaimingHugeImageIsRefusedBeforeAllocation) {
  const fs::path dir = temp_dir();
  write_header_only(dir / "bomb.png", 20000, 20000);
  const std::string e = error_of(dir / "bomb.png");
  EXPECT_NE(e.find("terrain.path"), std::string::npos) << e;
  EXPECT_NE(e.find("20000x20000"), std::string::npos) << e;
  write_header_only(dir / "huge.png", 65535, 65535);
  EXPECT_NE(error_of(dir / "huge.png").find("terrain.path"), std::string::npos);
  fs::remove_all(dir);
}

TEST(PngIo, DirectoryAndMissingFileNameTheField) {
  const fs::path dir = temp_dir();
  EXPECT_NE(error_of(dir).find("not a regular file"), std::string::npos);
  EXPECT_NE(error_of(dir / "missing.png").find("cannot be opened"), std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace sb
