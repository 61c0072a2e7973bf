// The grid's front pile search (stamp_kernel.hpp front_pile_nodes) scans only the bounding box
// of a widening corridor ahead of the tool and skips the polygon distance where the footprint's
// circles decide. Its pile must equal the one the same widening finds by testing every node of
// the grid: disks, boxes and a concave polygon, on axis-aligned and oblique headings, tools
// smaller than a cell, rough sand, a pile that runs off the grid; bulldozing (the corridor) and
// carrying (beside the tool too, the distance from its front face).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <vector>

#include "grid/height_grid.hpp"
#include "grid/stamp_kernel.hpp"

namespace sb::grid {
namespace {

using stamp_detail::Deposit;
using stamp_detail::FootprintCircles;

// The search by brute force: each round samples every node of the grid ahead of the tool,
// outside its footprint and within the reach, and widens the reach as the kernel does.
std::map<std::uint32_t, double> pile_over_every_node(const HeightGrid<double>& g, const ToolStamp& s, double volume,
                                                     double band) {
  const GridLayout& layout = g.layout();
  const double tan = s.rim.tan_repose;
  double reach = std::max({front_pile_flat_reach(volume, 2.0 * s.half_width_m, tan), s.rim.width_m, layout.diagonal()});
  std::size_t sampled_before = 0;
  for (int round = 0; round < 64; ++round) {
    std::vector<std::uint32_t> nodes;
    std::vector<PileSample> samples;
    double lowest = HUGE_VAL;
    for (std::size_t iy = 0; iy < layout.ny; ++iy)
      for (std::size_t ix = 0; ix < layout.nx; ++ix) {
        const Vec2 p = layout.position(ix, iy);
        if (!in_front_pile(s, p, band) || s.contains(p)) continue;
        const double d = pile_distance(s, p);
        if (d > reach) continue;
        const std::uint32_t k = layout.index(ix, iy);
        nodes.push_back(k);
        samples.push_back({d, g.z(k), layout.area(k)});
        lowest = std::min(lowest, g.z(k));
      }
    std::map<std::uint32_t, double> pile;
    if (samples.empty()) return pile;
    const double level = front_pile_level(samples, volume, tan);
    const double needed = front_pile_reach_needed(level, lowest, tan);
    if (needed <= reach || nodes.size() == sampled_before) {
      for (std::size_t i = 0; i < nodes.size(); ++i)
        if (const double depth = front_pile_depth(samples[i], level, tan); depth > 0.0) pile[nodes[i]] = depth;
      return pile;
    }
    sampled_before = nodes.size();
    reach = std::max(1.1 * needed, 1.5 * reach);
  }
  return {};
}

ToolSpec tool(ToolShape shape, double size_m, Displacement model) {
  ToolSpec spec;
  spec.shape = shape;
  spec.radius_m = size_m;
  spec.half_size_m = {0.5 * size_m, size_m};
  spec.polygon_m = {{-size_m, -size_m}, {size_m, -size_m}, {size_m, size_m}, {0.0, 0.2 * size_m}, {-size_m, size_m}};
  spec.rim.model = model;
  spec.rim.width_m = 0.5 * size_m;
  return spec;
}

TEST(GridFrontPile, TheCorridorFindsThePileOfEveryNodeAhead) {
  const double cell = 0.002;
  const GridLayout layout = GridLayout::covering({{0.0, 0.0}, {0.2, 0.16}}, cell);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> rough(0.0, 0.003);
  const HeightGrid<double> grid(layout, [&](const Vec2&) { return 0.05 + rough(rng); });
  int compared = 0;
  for (const Displacement model : {Displacement::Bulldoze, Displacement::Carry})
    for (const ToolShape shape : {ToolShape::Disk, ToolShape::Box, ToolShape::Polygon}) {
      for (const double size : {0.0007, 0.004, 0.015}) {  // under a cell, a few cells, many
        for (const double heading_deg : {0.0, 90.0, 45.0, 200.0, 301.7}) {
          for (const Vec2& xy : {Vec2(0.1, 0.08), Vec2(0.185, 0.15)}) {  // mid-grid; the pile off the grid
            for (const double volume : {1e-9, 2e-6, 4e-5})
              for (const double band : {0.0, 0.006}) {  // the slump band beside a carrying tool
                const double a = heading_deg * std::numbers::pi / 180.0;
                const Vec2 dir(std::cos(a), std::sin(a));
                ToolPose pose;
                pose.xy = xy;
                pose.bottom_z = 0.04;
                pose.heading_rad = a;
                const ToolStamp s = make_stamp(tool(shape, size, model), pose, dir, 0);
                const std::vector<Deposit> found = front_pile_nodes(grid, s, FootprintCircles(s), volume, band);
                const std::map<std::uint32_t, double> expected = pile_over_every_node(grid, s, volume, band);
                ASSERT_EQ(found.size(), expected.size())
                    << static_cast<int>(shape) << " " << size << " " << heading_deg;
                for (const Deposit& d : found) {
                  const auto e = expected.find(d.node);
                  ASSERT_NE(e, expected.end()) << "node " << d.node << " is not under the pile";
                  EXPECT_NEAR(d.weight, e->second, 1e-12) << "node " << d.node;
                }
                ++compared;
              }
          }
        }
      }
    }
  EXPECT_EQ(compared, 2 * 3 * 3 * 5 * 2 * 3 * 2);
}

}  // namespace
}  // namespace sb::grid
