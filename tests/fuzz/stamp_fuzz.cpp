// libFuzzer target: random stamp sequences on both back-ends. The input bytes are read as
// stamps (x, y, depth, radius, spacing to the next); after each stamp, erosion and
// simplification, check() must hold and the volume must stay finite.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "harness/run/backends.hpp"
#include "harness/run/runner.hpp"

namespace {

const char* kScene = R"(
[domain]
size_m = [0.2, 0.2]
[terrain]
kind = "flat"
height_m = 0.05
[stroke]
path_m = [[0.1, 0.1]]
[grid]
cell_m = 0.005
)";

double unit(const std::uint8_t* p) {  // two bytes -> [0, 1]
  return static_cast<double>(p[0] | (p[1] << 8)) / 65535.0;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const sb::PreparedScene prepared = sb::prepare_scene(sb::parse_scene(kScene, "fuzz"));
  constexpr std::size_t kStampBytes = 8;
  for (const char* backend : {"tin", "grid", "sparse"}) {
    auto terrain = sb::make_terrain(backend, prepared.scene, prepared.initial);
    sb::Vec2 previous(0.1, 0.1);
    for (std::size_t i = 0; i + kStampBytes <= size && i < 64 * kStampBytes; i += kStampBytes) {
      const std::uint8_t* p = data + i;
      const sb::Vec2 xy(-0.05 + 0.3 * unit(p), -0.05 + 0.3 * unit(p + 2));  // may leave the domain
      sb::ToolSpec tool = prepared.scene.tool;
      tool.radius_m = 0.001 + 0.05 * unit(p + 4);
      tool.rim.width_m = tool.radius_m / 2;
      sb::ToolPose pose{xy, 0.05 - 0.03 * (p[6] / 255.0), 0.0};
      const sb::Vec2 d = xy - previous;
      const sb::Vec2 dir = d.norm() > 0 ? sb::Vec2(d / d.norm()) : sb::Vec2::Zero();
      terrain->stamp(sb::make_stamp(tool, pose, dir, static_cast<std::uint32_t>(i / kStampBytes)));
      terrain->erode(prepared.rule, sb::ErosionBudget{p[7] % 4});
      terrain->simplify(sb::SimplifyParams{0.4});
      if (!terrain->check().ok() || !std::isfinite(terrain->volume())) __builtin_trap();
      previous = xy;
    }
  }
  return 0;
}
