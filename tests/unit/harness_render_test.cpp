// The offscreen renderer, its frames and labels, the comparison pictures, and
// `sandbench render` as a process: pictures are not blank, shading agrees with the
// heights, output is deterministic, bad input exits 2 and leaves nothing behind.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>

#include "harness/figures/canvas.hpp"
#include "harness/figures/compare_pictures.hpp"
#include "harness/render/colour.hpp"
#include "harness/render/frame.hpp"
#include "harness/render/mesh.hpp"
#include "harness/render/renderer.hpp"
#include "harness_test_support.hpp"

namespace sb {
namespace {

namespace fs = std::filesystem;

// A known scene: level sand at 0.1 m with a round hill and a trench, 0.2 m square.
double known_height(const Vec2& p) {
  const double hill = 0.02 * std::exp(-(p - Vec2(0.07, 0.13)).squaredNorm() / (2 * 0.03 * 0.03));
  const double along = std::clamp((p.x() - 0.06) / 0.09, 0.0, 1.0);
  const Vec2 on_line = Vec2(0.06, 0.05) + along * Vec2(0.09, 0.03);
  const double trench = 0.012 * std::exp(-(p - on_line).squaredNorm() / (2 * 0.008 * 0.008));
  return 0.1 + hill - trench;
}

Raster raster_of(const std::function<double(const Vec2&)>& f, double size = 0.2, double spacing = 0.002) {
  Raster r = Raster::covering({Vec2(0, 0), Vec2(size, size)}, spacing);
  for (std::size_t iy = 0; iy < r.ny; ++iy)
    for (std::size_t ix = 0; ix < r.nx; ++ix) r.at(ix, iy) = f(r.point(ix, iy));
  return r;
}

double stddev_luminance(const Image& im) {
  double s = 0, s2 = 0;
  const double n = static_cast<double>(im.width()) * im.height();
  for (int y = 0; y < im.height(); ++y)
    for (int x = 0; x < im.width(); ++x) {
      const double l = im.luminance(x, y);
      s += l;
      s2 += l * l;
    }
  return std::sqrt(std::max(0.0, s2 / n - (s / n) * (s / n)));
}

double correlation(const std::vector<double>& a, const std::vector<double>& b) {
  double ma = 0, mb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) ma += a[i], mb += b[i];
  ma /= a.size(), mb /= b.size();
  double sab = 0, saa = 0, sbb = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  return sab / std::sqrt(saa * sbb);
}

// SB_TEST_PICTURES=DIR keeps the pictures the tests look at, for a person to look at too.
void keep(const Image& im, const std::string& name) {
  if (const char* dir = std::getenv("SB_TEST_PICTURES")) write_png(fs::path(dir) / ("render_" + name + ".png"), im);
}

class Render : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { renderer_ = new Renderer(); }
  static void TearDownTestSuite() {
    delete renderer_;
    renderer_ = nullptr;
  }
  static Renderer* renderer_;
  Raster raster_ = raster_of(known_height);
  SurfaceMesh mesh_ = mesh_from_raster(raster_);
  RenderFrame domain_frame_ = make_frame({{nullptr, &raster_}}, FrameRegion::Domain);
};
Renderer* Render::renderer_ = nullptr;

TEST_F(Render, TopViewIsNotBlankAndItsShadingFollowsTheSlopesOfTheRaster) {
  RenderOptions o;
  o.view = View::Top;
  o.width = o.height = 200;
  const Image im = renderer_->render(mesh_, domain_frame_, o);
  keep(im, "top");
  ASSERT_EQ(im.width(), 200);
  ASSERT_EQ(im.height(), 200);
  EXPECT_GT(stddev_luminance(im), 0.02);

  // Lambert shading computed from the heights, at every pixel centre (the top view maps the
  // square domain onto the square image, +y up).
  const Vec3 light = light_direction();
  std::vector<double> rendered, expected;
  const double h = 1e-4;
  for (int py = 0; py < im.height(); ++py)
    for (int px = 0; px < im.width(); ++px) {
      const Vec2 p((px + 0.5) / im.width() * 0.2, 0.2 - (py + 0.5) / im.height() * 0.2);
      const double dx = (raster_.interpolate(p + Vec2(h, 0)) - raster_.interpolate(p - Vec2(h, 0))) / (2 * h);
      const double dy = (raster_.interpolate(p + Vec2(0, h)) - raster_.interpolate(p - Vec2(0, h))) / (2 * h);
      const Vec3 n = Vec3(-dx, -dy, 1).normalized();
      expected.push_back(kAmbient + kDiffuse * std::max(0.0, n.dot(light)));
      rendered.push_back(im.luminance(px, py));
    }
  EXPECT_GT(correlation(rendered, expected), 0.95);
  // The hill's north-west flank faces the light, its south-east flank faces away.
  const auto lum_at = [&](double x, double y) {
    return im.luminance(static_cast<int>(x / 0.2 * 200), static_cast<int>((0.2 - y) / 0.2 * 200));
  };
  EXPECT_GT(lum_at(0.05, 0.15), lum_at(0.09, 0.11) + 0.1);
}

TEST_F(Render, SameInputGivesTheSameBytes) {
  RenderOptions o;
  o.width = 320;
  o.height = 240;
  o.wireframe = true;
  o.contours = true;
  const Image a = renderer_->render(mesh_, domain_frame_, o);
  const Image b = renderer_->render(mesh_, domain_frame_, o);
  EXPECT_EQ(a.bytes(), b.bytes());
  Renderer other;
  EXPECT_EQ(other.render(mesh_, domain_frame_, o).bytes(), a.bytes());

  const fs::path dir = fs::temp_directory_path() / ("sb_render_det_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  write_png(dir / "a.png", a);
  write_png(dir / "b.png", b);
  EXPECT_EQ(test::slurp(dir / "a.png"), test::slurp(dir / "b.png"));
  EXPECT_GT(test::slurp(dir / "a.png").size(), 1000u);
  fs::remove_all(dir);
}

TEST_F(Render, ObliqueViewShowsTheSandInTheMiddleAndBackgroundAtTheTop) {
  RenderOptions o;
  o.width = 400;
  o.height = 300;
  const Image im = renderer_->render(mesh_, domain_frame_, o);
  EXPECT_GT(stddev_luminance(im), 0.02);
  const Rgb background = im.at(2, 2);
  const Rgb middle = im.at(200, 150);
  EXPECT_NE(middle, background);
  EXPECT_GT(middle.r, middle.b);  // sand is warm
}

TEST_F(Render, WireframeDrawsConstrainedEdgesInRed) {
  // Constrain the raster's edges along its middle row: a red line across the top view.
  SurfaceMesh mesh = mesh_;
  const std::size_t row = raster_.ny / 2;
  for (std::size_t ix = 0; ix + 1 < raster_.nx; ++ix)
    mesh.constrained_edges.push_back(
        {static_cast<std::uint32_t>(row * raster_.nx + ix), static_cast<std::uint32_t>(row * raster_.nx + ix + 1)});
  RenderOptions o;
  o.view = View::Top;
  o.width = o.height = 200;
  o.wireframe = true;
  const Image im = renderer_->render(mesh, domain_frame_, o);
  keep(im, "wireframe");
  auto red = [](const Rgb& c) { return c.r > 150 && c.g < 90 && c.b < 90; };
  int on_line = 0, elsewhere = 0;
  for (int x = 0; x < im.width(); ++x) {
    bool hit = false;
    for (int y = 97; y <= 102; ++y) hit = hit || red(im.at(x, y));
    on_line += hit;
    for (int y = 0; y < 80; ++y) elsewhere += red(im.at(x, y));
  }
  EXPECT_GT(on_line, 180);
  EXPECT_EQ(elsewhere, 0);
  // Ordinary edges darken the sand compared with the plain rendering.
  o.wireframe = false;
  const Image plain = renderer_->render(mesh, domain_frame_, o);
  double with = 0, without = 0;
  for (int y = 0; y < 80; ++y)
    for (int x = 0; x < 200; ++x) with += im.luminance(x, y), without += plain.luminance(x, y);
  EXPECT_LT(with, 0.97 * without);
}

TEST_F(Render, ContoursColourByHeightAndDrawLines) {
  RenderOptions o;
  o.view = View::Top;
  o.width = o.height = 200;
  o.contours = true;
  const Image im = renderer_->render(mesh_, domain_frame_, o);
  keep(im, "contours");
  // Level sand far from the features and the hilltop get different colours from the map.
  const Rgb level = im.at(190, 190), top = im.at(70, 70), trench = im.at(105, 135);
  EXPECT_NE(level, top);
  EXPECT_NE(level, trench);
  int dark = 0;
  for (int y = 0; y < 200; ++y)
    for (int x = 0; x < 200; ++x) dark += im.luminance(x, y) < 0.2;
  EXPECT_GT(dark, 200);   // contour lines around the hill and the trench
  EXPECT_LT(dark, 8000);  // but not a dark picture
}

TEST_F(Render, BadSizesAreRefused) {
  RenderOptions o;
  o.width = 0;
  EXPECT_THROW(renderer_->render(mesh_, domain_frame_, o), std::invalid_argument);
  o.width = renderer_->max_size() + 1;
  EXPECT_THROW(renderer_->render(mesh_, domain_frame_, o), std::invalid_argument);
}

TEST(RenderFrame, ChangedRegionBoxesTheChangeAndSharesHeights) {
  const Raster initial = raster_of([](const Vec2&) { return 0.1; });
  const Raster a = raster_of([](const Vec2& p) { return (p - Vec2(0.15, 0.05)).norm() < 0.01 ? 0.09 : 0.1; });
  const Raster b = raster_of([](const Vec2& p) { return (p - Vec2(0.15, 0.05)).norm() < 0.012 ? 0.092 : 0.1; });
  const RenderFrame f = make_frame({{&initial, &a}, {&initial, &b}}, FrameRegion::Changed);
  EXPECT_TRUE(f.region.contains(Vec2(0.15, 0.05)));
  EXPECT_FALSE(f.region.contains(Vec2(0.05, 0.15)));
  EXPECT_LT((f.region.hi - f.region.lo).maxCoeff(), 0.1);
  EXPECT_NEAR(f.z_min_m, 0.09, 1e-12);
  EXPECT_NEAR(f.z_max_m, 0.1, 1e-12);
  EXPECT_GT(f.contour_step_m, 0.0);
  EXPECT_LE((f.z_max_m - f.z_min_m) / f.contour_step_m, 15.0 + 1e-9);

  const RenderFrame unchanged = make_frame({{&initial, &initial}}, FrameRegion::Changed);
  EXPECT_EQ(unchanged.region.lo, Vec2(0, 0));
  EXPECT_NEAR(unchanged.region.hi.x(), 0.2, 1e-12);
  EXPECT_GT(unchanged.z_max_m, unchanged.z_min_m);  // a level surface still gets a range
}

TEST(RenderLabels, TextAndNumbersAreDrawnAndFormatted) {
  Canvas canvas(200, 40, {255, 255, 255});
  canvas.draw_text(2, 2, "grid 20 164 cells", {0, 0, 0}, 2);
  const Image im = canvas.image();
  int ink = 0;
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 200; ++x) ink += im.luminance(x, y) < 0.5;
  EXPECT_GT(ink, 100);
  EXPECT_GT(text_width("abc", 2), text_width("ab", 2));
  EXPECT_LE(text_width("grid 20 164 cells", 2), 200);
  EXPECT_GT(text_height(2), text_height(1));
  EXPECT_EQ(format_tick(0.105, 0.005), "0.105");
  EXPECT_EQ(format_tick(-0.002, 0.001, true), "-0.002");
  EXPECT_EQ(format_tick(0.0025, 0.0025, true), "+0.0025");
  EXPECT_EQ(format_tick(0.0, 0.001), "0");
  EXPECT_DOUBLE_EQ(nice_step(0.013, 15), 0.001);
  EXPECT_DOUBLE_EQ(nice_ceil(0.0037), 0.005);
  EXPECT_DOUBLE_EQ(fine_ceil(0.00326), 0.004);
  EXPECT_EQ(format_tick(0.0015, 0.0015), "0.0015");
  EXPECT_EQ(format_count(1234567), "1 234 567");
  EXPECT_EQ(format_bytes(203688), "198.9 KiB");
}

TEST(ComparePictures, DifferenceMapIsRedWhereTheSecondIsHigher) {
  const Raster initial = raster_of([](const Vec2&) { return 0.1; });
  const Raster base =
      raster_of([](const Vec2& p) { return 0.1 - 0.01 * std::exp(-(p - Vec2(0.1, 0.1)).squaredNorm() / 2e-4); });
  const Raster higher = raster_of([&](const Vec2& p) {
    return base.interpolate(p) + 0.002 * std::exp(-(p - Vec2(0.1, 0.1)).squaredNorm() / 1e-4);
  });
  SurfaceMesh m0 = mesh_from_raster(base), m1 = mesh_from_raster(higher);
  const Json s0 = {{"vertices", 0}, {"cells", 10000}, {"memory_bytes", 80000}};
  const Json s1 = {{"vertices", 321}, {"triangles", 600}, {"constrained_edges", 40}, {"memory_bytes", 20000}};
  const std::vector<PictureRun> runs = {{"grid", &m0, &initial, &base, &s0}, {"tin", &m1, &initial, &higher, &s1}};
  const RenderFrame frame = comparison_frame(runs);
  const Image diff = difference_map(runs, frame);
  keep(diff, "difference");
  int red = 0, blue = 0;
  for (int y = 0; y < diff.height(); ++y)
    for (int x = 0; x < diff.width(); ++x) {
      const Rgb c = diff.at(x, y);
      red += c.r > 150 && c.g < 110 && c.b < 110;
      blue += c.b > 150 && c.r < 110;
    }
  EXPECT_GT(red, blue + 1000);  // the colour bar is as red as it is blue; the map is red only
  EXPECT_EQ(run_caption_lines(s0), (std::vector<std::string>{"10 000 cells", "memory 78.1 KiB"}));
  EXPECT_EQ(run_caption_lines(s1),
            (std::vector<std::string>{"321 vertices, 600 triangles, 40 constrained edges", "memory 19.5 KiB"}));

  Renderer renderer;
  const Image sides = side_by_side(renderer, runs, frame);
  EXPECT_GT(sides.width(), 2 * 640);
  EXPECT_GT(stddev_luminance(sides), 0.02);
  EXPECT_THROW(difference_map({runs.front()}, frame), std::invalid_argument);
}

using test::sandbench;  // the binary as a process (harness_test_support.hpp)

// Width and height from a PNG's IHDR chunk; (0, 0) when the file is not a PNG.
std::pair<int, int> png_size(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  unsigned char h[24] = {};
  in.read(reinterpret_cast<char*>(h), 24);
  if (!in || h[1] != 'P' || h[2] != 'N' || h[3] != 'G') return {0, 0};
  auto be = [&](int i) { return (h[i] << 24) | (h[i + 1] << 16) | (h[i + 2] << 8) | h[i + 3]; };
  return {be(16), be(20)};
}

class RenderCli : public test::TempDirTest {
 protected:
  RenderCli() : TempDirTest("sb_render_cli_") {}
  void SetUp() override {
    TempDirTest::SetUp();
    run_ = dir_ / "grid.h5";
    const auto r =
        sandbench("run " + test::shipped_scene("flat_stroke.toml") + " --backend grid --out " + run_.string());
    ASSERT_EQ(r.code, 0) << r.out;
  }
  std::size_t files() const { return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir_), {})); }
  fs::path run_;
};

TEST_F(RenderCli, WritesPicturesOfTheRequestedSize) {
  auto r = sandbench("render " + run_.string() + " -o " + (dir_ / "a.png").string());
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(png_size(dir_ / "a.png"), std::make_pair(1024, 768));
  r = sandbench("render " + run_.string() + " -o " + (dir_ / "b.png").string() +
                " --view top --wireframe --contours --size 300x200 --region domain");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(png_size(dir_ / "b.png"), std::make_pair(300, 200));
}

TEST_F(RenderCli, BadInputExitsTwoNamesTheOptionAndWritesNothing) {
  const std::string out = (dir_ / "x.png").string();
  for (const char* size : {"100", "10x10", "100x", "axb", "100x100000", "-5x20"}) {
    const auto r = sandbench("render " + run_.string() + " -o " + out + " --size " + size);
    EXPECT_EQ(r.code, 2) << size << ": " << r.out;
    EXPECT_NE(r.out.find("--size"), std::string::npos) << r.out;
  }
  auto r = sandbench("render " + run_.string() + " -o " + out + " --view side");
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("--view"), std::string::npos) << r.out;
  r = sandbench("render " + (dir_ / "missing.h5").string() + " -o " + out);
  EXPECT_EQ(r.code, 2) << r.out;
  std::ofstream(dir_ / "not_a_run.h5") << "hello";
  r = sandbench("render " + (dir_ / "not_a_run.h5").string() + " -o " + out);
  EXPECT_EQ(r.code, 2) << r.out;
  r = sandbench("render " + run_.string() + " -o " + (dir_ / "no" / "such" / "dir.png").string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("-o"), std::string::npos) << r.out;
  r = sandbench("render " + run_.string() + " -o " + dir_.string());
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_EQ(sandbench("render " + run_.string()).code, 2);  // -o is required
  EXPECT_FALSE(fs::exists(out));
  EXPECT_EQ(files(), 2u);  // the run file and not_a_run.h5
}

}  // namespace
}  // namespace sb
