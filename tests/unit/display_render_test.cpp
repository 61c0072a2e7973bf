// The grid and the TIN drawn from their changed tiles look as the whole mesh did: `sandbench interactive` in
// a window under Xvfb, a tool hovering still above the sand (no stamp, so both runs show the
// same surface) over dunes, screenshots without the panel (its timings differ from run to run)
// with and without --mesh-display compared pixel by pixel.
// flat_stroke.toml's 142 x 142 nodes are drawn whole, the same triangles as the mesh, so the
// images agree up to rounding at a few edges; 1 m at 2.5 mm (401 x 401 nodes) is drawn in
// levels of detail around the tool, coarser far from it, so the bounds are looser. Wrong
// heights, normals or colours differ far more (a tile of the TIN missing: its background) (a flat surface against these
// dunes: a mean difference of tens of levels). Skipped when xvfb-run is not installed.
#include <gtest/gtest.h>
#include <png.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include "harness_test_support.hpp"

namespace sb {
namespace {

namespace fs = std::filesystem;

struct Image {
  unsigned width = 0, height = 0;
  std::vector<png_byte> rgb;
};

Image read_rgb(const fs::path& file) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  Image out;
  if (!png_image_begin_read_from_file(&image, file.c_str())) return out;
  image.format = PNG_FORMAT_RGB;
  out.rgb.resize(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, out.rgb.data(), 0, nullptr)) return {};
  out.width = image.width;
  out.height = image.height;
  return out;
}

// Mean absolute difference per channel (0-255), and the fraction of pixels whose largest
// channel difference exceeds `far`.
std::pair<double, double> image_difference(const Image& a, const Image& b, int far) {
  double sum = 0.0;
  std::size_t far_pixels = 0;
  for (std::size_t i = 0; i + 2 < a.rgb.size(); i += 3) {
    int worst = 0;
    for (std::size_t c = 0; c < 3; ++c) {
      const int d = std::abs(int{a.rgb[i + c]} - int{b.rgb[i + c]});
      sum += d;
      worst = std::max(worst, d);
    }
    if (worst > far) ++far_pixels;
  }
  return {sum / static_cast<double>(a.rgb.size()), 3.0 * static_cast<double>(far_pixels) / a.rgb.size()};
}

// Standard deviation of the brightness: a blank image has none.
double brightness_spread(const Image& a) {
  double sum = 0.0, sum2 = 0.0;
  const std::size_t n = a.rgb.size() / 3;
  for (std::size_t i = 0; i < n; ++i) {
    const double y = 0.3 * a.rgb[3 * i] + 0.59 * a.rgb[3 * i + 1] + 0.11 * a.rgb[3 * i + 2];
    sum += y;
    sum2 += y * y;
  }
  return std::sqrt(std::max(0.0, sum2 / n - (sum / n) * (sum / n)));
}

class DisplayRender : public test::TempDirTest {
 protected:
  DisplayRender() : TempDirTest("sb_display_render_") {}
  void SetUp() override {
    TempDirTest::SetUp();
    if (!test::have_xvfb()) GTEST_SKIP() << "xvfb-run is not installed (Debian: xvfb, xauth; make deps)";
  }
};

TEST_F(DisplayRender, TilesLookAsTheWholeMesh) {
  const fs::path hover = dir_ / "hover.csv";
  {
    std::ofstream out(hover);
    // Still: the frame screenshotted depends on the clock, so a moving tool would be drawn
    // (and the lattice refined around it) in different places in the two runs.
    out << "t,x,y,z,buttons\n0,0.35,0.35,0.2,0\n60,0.35,0.35,0.2,0\n";
  }
  struct Case {
    std::string sets;
    double mean, far_fraction;
    std::string backend = "grid";
  };
  // The levelled case (400 cells a side) draws the far field in cells up to 8 times the
  // lattice's (64-cell patches, lattice_lod.hpp), which point-sample the dunes' ripples there:
  // bounded here to under 10 levels on average and an eighth of the pixels.
  const Case cases[] = {
      {"", 0.5, 0.005},
      {" --set 'domain.size_m=[1.0,1.0]' --set grid.cell_m=0.0025", 10.0, 0.125},
      // The TIN's tiles hold the whole mesh's triangles: the same image up to rounding.
      {" --set tin.tolerance_m=0.0005", 0.5, 0.005, "tin"},
  };
  for (const Case& c : cases) {
    Image images[2];
    for (int mesh = 0; mesh < 2; ++mesh) {
      const fs::path shot = dir_ / ("shot" + std::to_string(mesh) + ".png");
      const test::CliResult r = test::run_shell(
          "{ " + test::xvfb() + SB_CLI_PATH + " interactive " + test::shipped_scene("flat_stroke.toml") +
          " --backend " + c.backend + " --set terrain.kind=dunes --set terrain.wavelength_m=0.1" + c.sets +
          " --device replay:" + hover.string() + " --frames 20 --size 640 400 --no-panel --screenshot " +
          shot.string() + (mesh ? " --mesh-display" : "") + "; } 2>&1");
      ASSERT_EQ(r.code, 0) << r.out;
      images[mesh] = read_rgb(shot);
      ASSERT_EQ(images[mesh].width, 640u) << c.sets;
      ASSERT_EQ(images[mesh].height, 400u) << c.sets;
    }
    EXPECT_GT(brightness_spread(images[0]), 10.0) << c.sets;
    const auto [mean, far_fraction] = image_difference(images[0], images[1], 24);
    std::cout << "[" << c.backend << " tiles against mesh" << c.sets << "] mean difference " << mean
              << ", fraction of pixels off by more than 24: " << far_fraction << "\n";
    EXPECT_LE(mean, c.mean) << c.sets;
    EXPECT_LE(far_fraction, c.far_fraction) << c.sets;
  }
}

}  // namespace
}  // namespace sb
