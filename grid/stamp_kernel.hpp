#pragma once
// The grid stamp (grid_stamp.hpp) as a template over the height storage, so that the dense
// and the sparse grid share one implementation. Include only where it is instantiated.
//
// Store concept (HeightGrid<Real> is one):
//   const GridLayout& layout() const;
//   double z(std::uint32_t k) const;        // height of node k = iy * nx + ix
//   void set(std::uint32_t k, double z);    // stores z, carrying the rounding error on
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "common/bilinear.hpp"
#include "common/front_pile.hpp"
#include "common/terrain.hpp"
#include "grid/compensated_sum.hpp"
#include "grid/grid_layout.hpp"
#include "grid/grid_stamp.hpp"

namespace sb::grid {

namespace stamp_detail {

struct Cut {
  std::uint32_t node;
  double bottom_z;
};
struct Deposit {
  std::uint32_t node;
  double weight;
};

// Rim nodes for a stamp whose own rim band holds none: the band is widened by a growing
// multiple of the cell diagonal and weighted by taper only (the directional factor may be
// zero on the only side the domain leaves). Empty only when no node lies outside the
// footprint at all.
inline std::vector<Deposit> widened_rim(const GridLayout& layout, const ToolStamp& s) {
  const Aabb2 footprint_box = bounds(s.footprint);
  const Aabb2 grid_box = layout.box();
  std::vector<Deposit> rim;
  // 64 doublings outgrow any domain; the bound only guards against non-finite input.
  double extra = layout.diagonal();
  for (int round = 0; round < 64; ++round, extra *= 2.0) {
    const double width = std::max(0.0, s.rim.width_m) + extra;
    const Aabb2 window = footprint_box.expanded(width);
    const NodeRange r = layout.nodes_in(window);
    bool any_outside = false;
    for (std::size_t iy = r.y0; !r.empty && iy <= r.y1; ++iy) {
      for (std::size_t ix = r.x0; ix <= r.x1; ++ix) {
        const Vec2 p = layout.position(ix, iy);
        if (s.contains(p)) continue;
        any_outside = true;
        const double d = distance_to_boundary(s.footprint, p);
        if (d < width) rim.push_back({layout.index(ix, iy), 1.0 - d / width});
      }
    }
    if (!rim.empty()) return rim;
    const bool covers_grid = window.contains(grid_box.lo) && window.contains(grid_box.hi);
    if (covers_grid && !any_outside) return rim;
  }
  return rim;
}

// Two circles about the footprint's vertex centroid that classify most nodes of the window
// without a polygon test: a node inside the inner circle is in the footprint; a node
// beyond the outer one is outside it, and beyond the outer one plus the rim width it is
// also past the rim band (its distance to the boundary is at least |p - c| - R). Margins of
// a billionth keep nodes whose classification rounding could flip on the polygon tests.
struct FootprintCircles {
  Vec2 centre{0.0, 0.0};
  double inner2 = -1.0;  // squared radii
  double outer2 = 0.0;
  double band2 = 0.0;

  explicit FootprintCircles(const ToolStamp& s) {
    for (const Vec2& v : s.footprint) centre += v;
    centre /= static_cast<double>(s.footprint.size());
    double outer = 0.0;
    for (const Vec2& v : s.footprint) outer = std::max(outer, (v - centre).norm());
    const double margin = 1e-9 * outer;
    if (s.contains(centre)) {
      const double inner = distance_to_boundary(s.footprint, centre) - margin;
      if (inner > 0.0) inner2 = inner * inner;
    }
    outer += margin;
    outer2 = outer * outer;
    const double band = outer + std::max(0.0, s.rim.width_m) + margin;
    band2 = band * band;
  }

  // Whether p, at squared distance d2 from the centre, is in the stamp's footprint: the circles
  // decide, the polygon only between them.
  bool inside(const ToolStamp& s, const Vec2& p, double d2) const {
    return d2 < inner2 || (d2 <= outer2 && s.contains(p));
  }
};

// The nodes of a bulldozing stamp's front pile (common/front_pile.hpp), each weighted by its
// depth under the pile. The region sampled starts at the pile's reach on flat ground and widens
// until it holds every node the pile covers (the pile carried from earlier stamps raises the
// level: a round or two more) or the corridor runs off the grid. Empty when no node lies ahead
// of the tool. Only the corridor's bounding box is scanned, and the circles classify most of its
// nodes, so the polygon's distance is taken only for nodes that may lie within the reach.
template <class Store>
std::vector<Deposit> front_pile_nodes(const Store& grid, const ToolStamp& s, const FootprintCircles& circles,
                                      double volume, double slump_band_m) {
  const GridLayout& layout = grid.layout();
  const double tan = s.rim.tan_repose;
  const double margin = 0.5 * std::min(layout.dx, layout.dy);  // rounding at the corridor's edges
  const double outer = std::sqrt(circles.outer2);
  const PileDistance distance(s);
  double reach = std::max({front_pile_flat_reach(volume, 2.0 * s.half_width_m, tan), s.rim.width_m, layout.diagonal()});
  std::vector<std::uint32_t> nodes;
  std::vector<PileSample> samples;
  std::size_t sampled_before = 0;
  // Each round at least 1.5 times wider: 64 outgrow any domain; the bound guards non-finite input.
  for (int round = 0; round < 64; ++round) {
    nodes.clear();
    samples.clear();
    const NodeRange r = layout.nodes_in(front_pile_box(s, reach, margin));
    double lowest = HUGE_VAL;
    for (std::size_t iy = r.y0; !r.empty && iy <= r.y1; ++iy) {
      for (std::size_t ix = r.x0; ix <= r.x1; ++ix) {
        const Vec2 p = layout.position(ix, iy);
        if (!in_front_pile(s, p, slump_band_m)) continue;
        const double d2 = (p - circles.centre).squaredNorm();
        if (circles.inside(s, p, d2)) continue;
        if (std::sqrt(d2) - outer > reach) continue;  // a lower bound of its distance to the footprint
        const double d = distance(p);
        if (d > reach) continue;
        const std::uint32_t k = layout.index(ix, iy);
        nodes.push_back(k);
        samples.push_back({d, grid.z(k), layout.area(k)});
        lowest = std::min(lowest, samples.back().z_m);
      }
    }
    if (samples.empty()) return {};
    const double level = front_pile_level(samples, volume, tan);
    const double needed = front_pile_reach_needed(level, lowest, tan);
    // No node gained since the last round: the corridor runs off the grid, and a wider window
    // would only rescan it (up to the whole grid, every stamp, with a pile against the border).
    const bool off_grid = nodes.size() == sampled_before;
    sampled_before = nodes.size();
    if (needed <= reach || off_grid || !std::isfinite(needed)) {
      std::vector<Deposit> pile;
      for (std::size_t i = 0; i < nodes.size(); ++i)
        if (const double depth = front_pile_depth(samples[i], level, tan); depth > 0.0)
          pile.push_back({nodes[i], depth});
      return pile;
    }
    reach = std::max(1.1 * needed, 1.5 * reach);
  }
  return {};
}

// A carrying stamp picks up what it keeps of the pile the stamp before it heaped (front_pile.hpp),
// at the nodes outside its footprint (the footprint's it cuts whole). The volume it took.
template <class Store>
double pick_up_carried(Store& grid, const ToolStamp& s, const FootprintCircles& circles, const CarriedNodes& carried,
                       std::vector<std::uint32_t>& changed) {
  const double keep = carried_fraction(s, carried.origin);
  if (!(keep > 0.0)) return 0.0;
  const GridLayout& layout = grid.layout();
  CompensatedSum taken;
  for (const auto& [k, base] : carried.base) {
    const auto [ix, iy] = layout.split(k);
    const Vec2 p = layout.position(ix, iy);
    const double d2 = (p - circles.centre).squaredNorm();
    if (circles.inside(s, p, d2)) continue;
    const double z = grid.z(k), dz = keep * (z - base);
    if (!(dz > 0.0)) continue;
    grid.set(k, z - dz);
    taken.add(layout.area(k) * dz);
    changed.push_back(k);
  }
  return taken.value();
}

template <class Store>
StampReport cut_and_push(Store& grid, const ToolStamp& s, std::vector<std::uint32_t>& changed, CarriedNodes* carried) {
  const GridLayout& layout = grid.layout();
  StampReport report;
  // Whatever this stamp does, the pile it may leave for the next one is set below or none.
  const CarriedNodes previous = carried ? std::exchange(*carried, CarriedNodes{}) : CarriedNodes{};
  if (s.footprint.size() < 3) return report;
  const NodeRange r = layout.nodes_in(s.influence_bounds());
  if (r.empty) return report;

  const FootprintCircles circles(s);
  std::vector<Cut> cuts;
  std::vector<Deposit> rim;
  // The footprint's nodes into `cuts` (cut_pass) or the rim band's into `rim`, in storage order.
  const auto scan = [&](bool cut_pass) {
    for (std::size_t iy = r.y0; iy <= r.y1; ++iy) {
      for (std::size_t ix = r.x0; ix <= r.x1; ++ix) {
        const Vec2 p = layout.position(ix, iy);
        const double d2 = (p - circles.centre).squaredNorm();
        if (d2 >= circles.band2) continue;
        const std::uint32_t k = layout.index(ix, iy);
        if (circles.inside(s, p, d2)) {
          const double bottom = s.bottom_z(p);
          if (cut_pass && grid.z(k) > bottom) cuts.push_back({k, bottom});
        } else if (!cut_pass) {
          if (const double w = s.rim_weight_outside(p, distance_to_boundary(s.footprint, p)); w > 0.0)
            rim.push_back({k, w});
        }
      }
    }
  };
  scan(true);
  // What a carrying stamp picks up lies outside the footprint, so the cuts are the same before and after.
  const double picked = pick_up_carried(grid, s, circles, previous, changed);
  if (cuts.empty() && !(picked > 0.0)) return report;
  CompensatedSum removed;
  removed.add(picked);
  for (const Cut& c : cuts) removed.add(layout.area(c.node) * (grid.z(c.node) - c.bottom_z));
  const double volume = removed.value();
  // A bulldozing stamp's sand goes ahead of the tool; the rim takes it when nothing lies ahead
  // (the tool at the domain's far side) and for every other stamp.
  if (s.bulldozes()) {
    const double band = slump_band(s, grid.height(bed_probe(s, std::max(layout.dx, layout.dy))));
    rim = front_pile_nodes(grid, s, circles, volume, band);
  }
  if (carried && s.carries() && !rim.empty()) {
    carried->origin = carried_origin(s);
    carried->base.reserve(rim.size());
    for (const Deposit& d : rim) carried->base.emplace_back(d.node, grid.z(d.node));
  }
  if (rim.empty()) scan(false);
  if (rim.empty()) rim = widened_rim(layout, s);
  // No node outside the footprint (a tool larger than the domain): cutting would lose
  // the volume, so the stamp does nothing.
  if (rim.empty()) return report;

  CompensatedSum rim_weight;
  for (const Deposit& d : rim) rim_weight.add(layout.area(d.node) * d.weight);
  const double per_weight = volume / rim_weight.value();

  for (const Cut& c : cuts) {
    grid.set(c.node, c.bottom_z);
    changed.push_back(c.node);
  }
  CompensatedSum deposited;
  for (const Deposit& d : rim) {
    const double dz = per_weight * d.weight;
    grid.set(d.node, grid.z(d.node) + dz);
    deposited.add(layout.area(d.node) * dz);
    changed.push_back(d.node);
  }
  report.volume_removed_m3 = volume;
  report.volume_deposited_m3 = deposited.value();
  report.elements_touched = cuts.size() + rim.size();
  return report;
}

// Where a pour's sand lands: a cone of the pour radius (as on the TIN, tin/stamp.cpp), handed
// to the nodes by their bilinear weights. A lattice of samples centred on the pour point gives
// each sample's share of the cone to the four nodes around it; bilinear weights reproduce linear
// functions, so the sand's centroid lands on the pour point wherever that lies between nodes.
// (Spread evenly over the nodes within the radius, it landed up to 0.6 mm off on 2.5 mm cells, and
// pile.toml's error at pour points between nodes came mostly from that: 29-55 um, 29 re-centred.)
// Samples outside the grid are clamped onto its border (bilinear_cell, common/bilinear.hpp). O((radius / spacing)^2)
// samples, spacing a quarter of the smaller of cell and radius, at most 256 x 256.
inline std::vector<Deposit> pour_weights(const GridLayout& layout, const Vec2& centre, double radius) {
  const double cell = std::min(layout.dx, layout.dy);
  const double r = radius > 0.0 && std::isfinite(radius) ? radius : 0.0;
  const int half = r > 0.0 ? std::clamp(static_cast<int>(std::ceil(4.0 * r / std::min(cell, r))), 1, 128) : 0;
  const double spacing = half > 0 ? r / half : 0.0;
  std::vector<Deposit> out;
  const auto splat = [&](const Vec2& p, double w) {
    const Vec2 g = (p - layout.origin).cwiseQuotient(Vec2(layout.dx, layout.dy));
    const BilinearCell c = bilinear_cell(g.x(), g.y(), layout.nx, layout.ny);
    out.push_back({layout.index(c.ix, c.iy), w * (1.0 - c.tx) * (1.0 - c.ty)});
    out.push_back({layout.index(c.ix1, c.iy), w * c.tx * (1.0 - c.ty)});
    out.push_back({layout.index(c.ix, c.iy1), w * (1.0 - c.tx) * c.ty});
    out.push_back({layout.index(c.ix1, c.iy1), w * c.tx * c.ty});
  };
  for (int i = -half; i < half; ++i)
    for (int j = -half; j < half; ++j) {
      const Vec2 offset((i + 0.5) * spacing, (j + 0.5) * spacing);
      const double w = 1.0 - offset.norm() / r;
      if (w > 0.0) splat(centre + offset, w);
    }
  if (out.empty()) splat(centre, 1.0);  // a point pour, or one narrower than the samples
  // One entry per node, in node order.
  std::sort(out.begin(), out.end(), [](const Deposit& a, const Deposit& b) { return a.node < b.node; });
  std::size_t kept = 0;
  for (const Deposit& d : out) {
    if (kept > 0 && out[kept - 1].node == d.node)
      out[kept - 1].weight += d.weight;
    else
      out[kept++] = d;
  }
  out.resize(kept);
  return out;
}

template <class Store>
StampReport pour(Store& grid, const ToolStamp& s, std::vector<std::uint32_t>& changed) {
  const GridLayout& layout = grid.layout();
  if (!s.pose.xy.allFinite() || !std::isfinite(s.pour_volume_m3)) return {};
  const std::vector<Deposit> nodes = pour_weights(layout, s.pose.xy, s.pour_radius_m);
  CompensatedSum total;
  for (const Deposit& d : nodes) total.add(d.weight);
  CompensatedSum deposited;
  std::size_t touched = 0;
  for (const Deposit& d : nodes) {
    if (!(d.weight > 0.0)) continue;
    ++touched;
    const double area = layout.area(d.node);
    const double dz = s.pour_volume_m3 * (d.weight / total.value()) / area;
    grid.set(d.node, grid.z(d.node) + dz);
    deposited.add(area * dz);
    changed.push_back(d.node);
  }
  StampReport report;
  report.volume_deposited_m3 = deposited.value();
  report.elements_touched = touched;
  return report;
}

}  // namespace stamp_detail

template <class Store>
StampReport stamp_grid(Store& grid, const ToolStamp& s, std::vector<std::uint32_t>& changed, CarriedNodes* carried) {
  if (s.is_pour()) {
    if (carried) *carried = CarriedNodes{};
    return stamp_detail::pour(grid, s, changed);
  }
  return stamp_detail::cut_and_push(grid, s, changed, carried);
}

}  // namespace sb::grid
