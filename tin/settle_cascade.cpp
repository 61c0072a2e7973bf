// The TIN's settling cascade on plain arrays (settle_cascade.hpp has the method, its
// conservation and energy arguments, and when it runs).
#include "tin/settle_cascade.hpp"

#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <utility>

namespace sb::tin {

namespace {

// One level: per node (a vertex on level 0, a cluster above) its area, position, height,
// restricted height and neighbours (CSR), and per node of the finer level its parent here.
struct Level {
  std::vector<double> area, x, y, z, z0;
  std::vector<std::uint32_t> adj_begin, adj;
  std::vector<std::int64_t> cell_x, cell_y;  // the node's cell on this level (clusters only)
  std::vector<std::uint32_t> parent_of_finer;
  std::vector<std::uint8_t> active;
  std::size_t size() const { return z.size(); }
};

// Neighbour lists, both directions, from undirected pairs (duplicates and self-pairs dropped).
void build_adjacency(Level& level, std::vector<std::pair<std::uint32_t, std::uint32_t>>& pairs) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> both;
  both.reserve(2 * pairs.size());
  for (const auto& [a, b] : pairs) {
    if (a == b) continue;
    both.emplace_back(a, b);
    both.emplace_back(b, a);
  }
  std::sort(both.begin(), both.end());
  both.erase(std::unique(both.begin(), both.end()), both.end());
  level.adj_begin.assign(level.size() + 1, 0);
  level.adj.resize(both.size());
  for (std::size_t k = 0; k < both.size(); ++k) {
    ++level.adj_begin[both[k].first + 1];
    level.adj[k] = both[k].second;
  }
  for (std::size_t i = 0; i < level.size(); ++i) level.adj_begin[i + 1] += level.adj_begin[i];
}

// The clusters of `finer` by cells of side `cell` (vertices), or by finer's cells merged 2^shift
// x 2^shift (a cluster level); restricted areas, positions, heights, activity; adjacency from
// finer's.
Level coarsen(const Level& finer, bool finer_is_vertices, double x0, double y0, double cell, int shift) {
  Level c;
  const std::size_t n = finer.size();
  std::unordered_map<std::uint64_t, std::uint32_t> index;
  index.reserve(n);
  std::vector<std::uint32_t> parent(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::int64_t cx = 0, cy = 0;
    if (finer_is_vertices) {
      cx = static_cast<std::int64_t>(std::floor((finer.x[i] - x0) / cell));
      cy = static_cast<std::int64_t>(std::floor((finer.y[i] - y0) / cell));
    } else {
      cx = finer.cell_x[i] >> shift;
      cy = finer.cell_y[i] >> shift;
    }
    const std::uint64_t key = (static_cast<std::uint64_t>(cx) << 32) ^ static_cast<std::uint64_t>(cy & 0xffffffff);
    const auto [it, fresh] = index.emplace(key, static_cast<std::uint32_t>(c.cell_x.size()));
    if (fresh) {
      c.cell_x.push_back(cx);
      c.cell_y.push_back(cy);
    }
    parent[i] = it->second;
  }
  const std::size_t m = c.cell_x.size();
  c.area.assign(m, 0.0);
  c.x.assign(m, 0.0);
  c.y.assign(m, 0.0);
  c.z.assign(m, 0.0);
  c.active.assign(m, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t p = parent[i];
    const double a = finer.area[i];
    c.area[p] += a;
    c.x[p] += a * finer.x[i];
    c.y[p] += a * finer.y[i];
    c.z[p] += a * finer.z[i];
    c.active[p] |= finer.active[i];
  }
  for (std::size_t p = 0; p < m; ++p) {
    if (!(c.area[p] > 0.0)) continue;  // (zero-area members only: the cluster never moves sand)
    c.x[p] /= c.area[p];
    c.y[p] /= c.area[p];
    c.z[p] /= c.area[p];
  }
  c.z0 = c.z;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  for (std::size_t i = 0; i < n; ++i)
    for (std::uint32_t k = finer.adj_begin[i]; k < finer.adj_begin[i + 1]; ++k)
      if (finer.adj[k] > i && parent[i] != parent[finer.adj[k]]) pairs.emplace_back(parent[i], parent[finer.adj[k]]);
  build_adjacency(c, pairs);
  c.parent_of_finer = std::move(parent);
  return c;
}

double energy(const Level& l) {
  double e = 0.0;
  for (std::size_t i = 0; i < l.size(); ++i) e += 0.5 * l.area[i] * l.z[i] * l.z[i];
  return e;
}

// A level's active set, visited in passes as TinTerrain::erode visits L_e: a member that gives
// re-activates what its change may unsettle (touch), one that does not leaves after
// idle_passes idle visits; only eligible nodes ever join.
class Worklist {
 public:
  explicit Worklist(std::vector<std::uint8_t> eligible)
      : eligible_(std::move(eligible)), in_(eligible_.size(), 0), idle_(eligible_.size(), 0) {}
  void touch(std::uint32_t i) {
    idle_[i] = 0;
    if (in_[i] || !eligible_[i]) return;
    in_[i] = 1;
    list_.push_back(i);
  }
  bool empty() const { return list_.empty(); }
  // One pass over the members as they were at its start; visit(i) returns whether i gave.
  template <class Visit>
  void pass(int idle_passes, CascadeLevelReport& lr, Visit&& visit) {
    ++lr.passes;
    work_ = list_;
    for (const std::uint32_t i : work_) {
      if (!in_[i]) continue;
      ++lr.updates;
      if (!visit(i) && ++idle_[i] >= idle_passes) in_[i] = 0;
    }
    std::erase_if(list_, [&](std::uint32_t i) { return !in_[i]; });
  }

 private:
  std::vector<std::uint8_t> eligible_, in_;
  std::vector<std::uint16_t> idle_;
  std::vector<std::uint32_t> list_, work_;
};

// Gauss-Seidel passes of the rule over the level's active nodes (as TinTerrain::erode visits
// L_e: a node that gives re-activates itself and its neighbours; one idle too long leaves).
void relax(Level& l, const ErosionRule& rule, const CascadeOptions& o, CascadeLevelReport& lr, CascadeReport& r) {
  const std::size_t n = l.size();
  std::vector<std::uint8_t> eligible(n);
  for (std::size_t i = 0; i < n; ++i) eligible[i] = l.area[i] > 0.0;
  Worklist list(std::move(eligible));
  for (std::uint32_t i = 0; i < n; ++i)
    if (l.active[i]) list.touch(i);
  std::vector<ErosionNeighbour> nbrs;
  std::vector<double> out;
  const auto visit = [&](std::uint32_t i) {
    const std::uint32_t b = l.adj_begin[i], e = l.adj_begin[i + 1];
    nbrs.clear();
    for (std::uint32_t k = b; k < e; ++k) {
      const std::uint32_t j = l.adj[k];
      const double dx = l.x[j] - l.x[i], dy = l.y[j] - l.y[i];
      nbrs.push_back({l.z[j], std::sqrt(dx * dx + dy * dy), l.area[j], dx, dy});
    }
    out.resize(nbrs.size());
    const double total = erosion_transfers(l.z[i], l.area[i], {}, nbrs, rule, out, NeighbourLayout::Stencil);
    if (!(total > 0.0)) return false;
    l.z[i] -= total / l.area[i];
    list.touch(i);
    for (std::uint32_t k = b; k < e; ++k) {
      const std::uint32_t j = l.adj[k];
      list.touch(j);
      if (out[k - b] <= 0.0) continue;
      l.z[j] += out[k - b] / l.area[j];
      ++r.transfers;
    }
    r.moved_m3 += total;
    return true;
  };
  for (int pass = 0; pass < o.max_passes_per_level && !list.empty(); ++pass) list.pass(o.idle_passes, lr, visit);
  r.updates += lr.updates;
}

// The fine level: the rule as the TIN's passes apply it (Fan layout, the fan gradient under the
// gradient rule), on the vertices whose whole ring is in the region.
void relax_fine(std::span<double> z, std::span<const double> area, std::span<const double> x, std::span<const double> y,
                std::span<const std::uint32_t> ring_begin, std::span<const std::uint32_t> ring,
                std::span<const std::uint8_t> active, const ErosionRule& rule, const CascadeOptions& o,
                CascadeLevelReport& lr, CascadeReport& r) {
  const std::size_t n = z.size();
  const auto visited = [&](std::uint32_t i) { return ring_begin[i + 1] > ring_begin[i]; };
  std::vector<std::uint8_t> eligible(n);
  for (std::uint32_t i = 0; i < n; ++i) eligible[i] = visited(i);
  Worklist list(std::move(eligible));
  for (std::uint32_t i = 0; i < n; ++i)
    if (active[i]) list.touch(i);
  // The rings' offsets, distances, areas and conductances do not change (the mesh does not):
  // laid out once, a visit only reads the heights in. So are the fan gradient's coefficients
  // (fan_gradient_coefficients: it is linear in the height differences), where the rule does
  // not cap drops; capped drops need the steepest facet, so the facets are computed one by one
  // (fan_gradient), as TinTerrain::erode does; laid out once per star, the fine level's visits
  // do not recompute the ring's geometry (callgrind on flat_stroke.toml with tool.depth_m = 0.2
  // counts the difference).
  const bool gradient = rule.needs_gradient();
  const bool linear_gradient = gradient && !rule.cap_drop;
  std::vector<ErosionNeighbour> nbrs(ring.size());
  std::vector<double> conductance(ring.size());
  std::vector<double> gcx(linear_gradient ? ring.size() : 0), gcy(linear_gradient ? ring.size() : 0);
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t b = ring_begin[i], e = ring_begin[i + 1];
    for (std::uint32_t k = b; k < e; ++k) {
      const std::uint32_t j = ring[k];
      const double dx = x[j] - x[i], dy = y[j] - y[i];
      nbrs[k] = {0.0, std::sqrt(dx * dx + dy * dy), area[j], dx, dy};
    }
    const std::span<const ErosionNeighbour> fan(nbrs.data() + b, e - b);
    if (linear_gradient)
      fan_gradient_coefficients(fan, std::span(gcx).subspan(b, e - b), std::span(gcy).subspan(b, e - b));
    for (std::size_t a = 0; a < fan.size(); ++a) conductance[b + a] = fan_conductance(fan, a);
  }
  std::vector<double> out;
  const auto visit = [&](std::uint32_t i) {
    const std::uint32_t b = ring_begin[i], e = ring_begin[i + 1];
    SurfaceGradient g;
    for (std::uint32_t k = b; k < e; ++k) {
      const double zk = z[ring[k]];
      nbrs[k].z = zk;
      if (!linear_gradient) continue;
      g.x += gcx[k] * (zk - z[i]);
      g.y += gcy[k] * (zk - z[i]);
    }
    const std::span<const ErosionNeighbour> fan(nbrs.data() + b, e - b);
    if (gradient && rule.cap_drop) g = fan_gradient(z[i], fan, true);
    out.resize(fan.size());
    const double total =
        erosion_transfers(z[i], area[i], g, fan, rule, out, NeighbourLayout::Fan, conductance.data() + b);
    if (!(total > 0.0 && area[i] > 0.0)) return false;
    z[i] -= total / area[i];
    list.touch(i);
    for (std::uint32_t k = b; k < e; ++k) list.touch(ring[k]);
    for (std::uint32_t k = b; k < e; ++k) {
      const std::uint32_t j = ring[k];
      if (out[k - b] <= 0.0 || area[j] <= 0.0) continue;
      z[j] += out[k - b] / area[j];
      if (gradient)  // its neighbours' fan gradients read it
        for (std::uint32_t m = ring_begin[j]; m < ring_begin[j + 1]; ++m) list.touch(ring[m]);
      ++r.transfers;
    }
    r.moved_m3 += total;
    return true;
  };
  for (int pass = 0; pass < o.max_fine_passes && !list.empty(); ++pass) list.pass(o.idle_passes, lr, visit);
  r.updates += lr.updates;
}

}  // namespace

CascadeReport settle_cascade(CascadeRegion& region, const ErosionRule& given, const CascadeOptions& options) {
  CascadeReport report;
  const std::size_t n = region.size();
  if (n == 0 || !(options.cell_m > 0.0)) return report;
  ErosionRule rule = given;
  rule.kind = ErosionRuleKind::Edge;  // clusters have no facet gradient

  // Level 0: the vertices.
  std::vector<Level> levels(1);
  Level& fine = levels[0];  // (only until levels grows)
  fine.area = region.area;
  fine.x = region.x;
  fine.y = region.y;
  fine.z = region.z;
  fine.active = region.active;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> pairs;
  pairs.reserve(region.edges.size() / 2);
  for (std::size_t k = 0; k + 1 < region.edges.size(); k += 2) pairs.emplace_back(region.edges[k], region.edges[k + 1]);
  build_adjacency(fine, pairs);
  const double x0 = *std::min_element(region.x.begin(), region.x.end());
  const double y0 = *std::min_element(region.y.begin(), region.y.end());

  // Restriction, every level from the same fine state (the energy argument needs it).
  // A cell size that merges too little (vertices as far apart as the cells) is skipped: the
  // next level tries cells twice as large.
  double cell = options.cell_m;
  int shift = 1;  // from the last level kept
  for (int k = 1; k <= options.max_levels; ++k, cell *= 2.0) {
    const bool from_vertices = levels.size() == 1;
    Level c = coarsen(levels.back(), from_vertices, x0, y0, cell, shift);
    if (c.size() < kCascadeMinClusters) break;
    if (5 * c.size() > 4 * levels.back().size()) {
      ++shift;
      continue;
    }
    levels.push_back(std::move(c));
    shift = 1;
  }
  if (levels.size() < 2 && !options.fine_level) return report;

  // Coarsest to level 1: relax, then add the level's change to its children.
  for (std::size_t k = levels.size() - 1; k >= 1; --k) {
    Level& l = levels[k];
    Level& finer = levels[k - 1];
    CascadeLevelReport lr;
    lr.clusters = l.size();
    if (options.measure_energy) lr.energy_before = energy(l);
    relax(l, rule, options, lr, report);
    if (options.measure_energy) lr.energy_after = energy(l);
    for (std::size_t i = 0; i < l.size(); ++i) lr.changed += l.z[i] != l.z0[i];
    for (std::size_t c = 0; c < finer.size(); ++c) {
      const std::uint32_t p = l.parent_of_finer[c];
      const double dz = l.z[p] - l.z0[p];
      if (dz == 0.0) continue;
      finer.z[c] += dz;
      finer.active[c] = 1;
    }
    report.levels.push_back(lr);
  }
  std::reverse(report.levels.begin(), report.levels.end());
  Level& vertices = levels[0];
  if (options.fine_level && region.ring_begin.size() == n + 1) {
    if (options.measure_energy) report.fine.energy_before = energy(vertices);
    relax_fine(vertices.z, vertices.area, vertices.x, vertices.y, region.ring_begin, region.ring, vertices.active,
               given, options, report.fine, report);
    if (options.measure_energy) report.fine.energy_after = energy(vertices);
  }
  region.z = vertices.z;
  return report;
}

}  // namespace sb::tin
