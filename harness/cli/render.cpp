// `sandbench render RUN.h5 -o IMAGE.png [--view oblique|top] [--wireframe] [--contours]
//  [--size WxH] [--region changed|domain]`: an offscreen picture of a run's final surface.
#include <charconv>
#include <iostream>
#include <memory>

#include "common/input_error.hpp"
#include "harness/cli/commands.hpp"
#include "harness/figures/picture.hpp"
#include "harness/io/run_file.hpp"

namespace sb::cli {

namespace {
struct RenderCliOptions {
  std::string run;
  std::string out;
  std::string view = "oblique";
  std::string size = "1024x768";
  std::string region = "changed";
  bool wireframe = false;
  bool contours = false;
};

constexpr int kMinSize = 16, kMaxSize = 8192;

int parse_dimension(const std::string& text, const std::string& whole) {
  int v = 0;
  const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || r.ec != std::errc() || r.ptr != text.data() + text.size() || v < kMinSize || v > kMaxSize)
    throw InputError("--size \"" + whole + "\": must be WxH with W and H whole numbers in " + std::to_string(kMinSize) +
                     ".." + std::to_string(kMaxSize) + ", e.g. 1024x768");
  return v;
}

void render_command(const RenderCliOptions& o) {
  RenderOptions options;
  const auto x = o.size.find('x');
  if (x == std::string::npos) throw InputError("--size \"" + o.size + "\": must be WxH, e.g. 1024x768");
  options.width = parse_dimension(o.size.substr(0, x), o.size);
  options.height = parse_dimension(o.size.substr(x + 1), o.size);
  if (o.view == "oblique")
    options.view = View::Oblique;
  else if (o.view == "top")
    options.view = View::Top;
  else
    throw InputError("--view \"" + o.view + "\": must be oblique or top");
  FrameRegion region = FrameRegion::Changed;
  if (o.region == "domain")
    region = FrameRegion::Domain;
  else if (o.region != "changed")
    throw InputError("--region \"" + o.region + "\": must be changed or domain");
  options.wireframe = o.wireframe;
  options.contours = o.contours;
  const std::filesystem::path out = o.out;
  if (out.has_parent_path() && !std::filesystem::is_directory(out.parent_path()))
    throw InputError("-o " + out.string() + ": directory " + out.parent_path().string() + " does not exist");
  if (std::filesystem::is_directory(out)) throw InputError("-o " + out.string() + " is a directory; give a file name");

  const RunFile run = read_run_file(o.run);
  const RenderFrame frame = make_frame({{&run.initial_raster, &run.final_raster}}, region);
  if (run.mesh.triangles.empty()) std::cerr << "sandbench: " << o.run << " has no mesh; drawing its final raster\n";
  Renderer renderer;
  write_png(out, render_picture(renderer, run.mesh, run.final_raster, frame, options));
  std::cerr << "wrote " << out.string() << "\n";
}
}  // namespace

void add_render_command(CLI::App& app) {
  auto opts = std::make_shared<RenderCliOptions>();
  CLI::App* cmd = app.add_subcommand("render", "Render a run file's final surface offscreen (OSMesa) to a PNG");
  cmd->add_option("run", opts->run, "Run file (HDF5) written by sandbench run or compare")->required();
  cmd->add_option("-o,--out", opts->out, "PNG image to write")->required();
  cmd->add_option("--view", opts->view, "oblique (default) | top");
  cmd->add_flag("--wireframe", opts->wireframe, "Overlay the mesh edges; constrained edges in red");
  cmd->add_flag("--contours", opts->contours, "Height colour map with contour lines and a legend");
  cmd->add_option("--size", opts->size, "Image size WxH in pixels (default 1024x768)");
  cmd->add_option("--region", opts->region,
                  "changed (default: where the surface changed, with a margin) | domain (everything)");
  cmd->callback([opts] { render_command(*opts); });
}

}  // namespace sb::cli
