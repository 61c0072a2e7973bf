// `sandbench render RUN.h5 -o IMAGE.png [--view oblique|top] [--wireframe] [--contours]
//  [--size WxH] [--region changed|domain]`: an offscreen picture of a run's final surface.
#include <charconv>
#include <iostream>
#include <memory>

#include "common/input_error.hpp"
#include "harness/cli/commands.hpp"
#include "harness/cli/validators.hpp"
#include "harness/figures/picture.hpp"
#include "harness/io/run_file.hpp"

namespace sb::cli {

namespace {
struct RenderCliOptions {
  std::string run;
  std::string out;
  View view = View::Oblique;
  std::string size = "1024x768";
  FrameRegion region = FrameRegion::Changed;
  bool wireframe = false;
  bool contours = false;
};

constexpr int kMinSize = 16, kMaxSize = 8192;

void render_command(const RenderCliOptions& o) {
  RenderOptions options;
  std::tie(options.width, options.height) = parse_image_size(o.size);
  options.view = o.view;
  options.wireframe = o.wireframe;
  options.contours = o.contours;
  const std::filesystem::path out = o.out;
  const RunFile run = read_run_file(o.run);
  const RenderFrame frame = make_frame({{&run.initial_raster, &run.final_raster}}, o.region);
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
  cmd->add_option("-o,--out", opts->out, "PNG image to write")->required()->check(output_file());
  cmd->add_option("--view", opts->view, "oblique (default) | top")
      ->transform(names<View>({{"oblique", View::Oblique}, {"top", View::Top}}));
  cmd->add_flag("--wireframe", opts->wireframe, "Overlay the mesh edges; constrained edges in red");
  cmd->add_flag("--contours", opts->contours, "Height colour map with contour lines and a legend");
  cmd->add_option("--size", opts->size, "Image size WxH in pixels (default 1024x768)")
      ->check(image_size(kMinSize, kMaxSize));
  cmd->add_option("--region", opts->region,
                  "changed (default: where the surface changed, with a margin) | domain (everything)")
      ->transform(names<FrameRegion>({{"changed", FrameRegion::Changed}, {"domain", FrameRegion::Domain}}));
  cmd->callback([opts] { render_command(*opts); });
}

}  // namespace sb::cli
