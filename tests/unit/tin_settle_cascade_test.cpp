// The TIN's settling cascade (tin/settle_cascade.hpp): exact volume and falling energy on
// every level, levels on a hull that is not a rectangle, no cascade for small active sets or
// stroke budgets, and on the TIN a settled state at repose under the fine rule, reached with
// fewer updates than the fine passes alone.
#include <cmath>
#include <map>
#include <utility>

#include "tests/unit/tin_test_support.hpp"
#include "tin/settle_cascade.hpp"

namespace sb::tin::test {
namespace {

// A triangulated lattice (spacing h, each cell cut along its rising diagonal) of the points
// within `radius` of the centre (a disc: the hull is no rectangle), with a column of sand of
// height `column` within `column_radius`: barycentric areas from the triangles, the rings of
// the vertices with all 6 neighbours counter-clockwise.
CascadeRegion disc_lattice(int half, double h, double radius, double column, double column_radius) {
  CascadeRegion r;
  std::map<std::pair<int, int>, std::uint32_t> index;
  for (int j = -half; j <= half; ++j)
    for (int i = -half; i <= half; ++i) {
      const double x = i * h, y = j * h;
      if (std::hypot(x, y) > radius) continue;
      index[{i, j}] = static_cast<std::uint32_t>(r.x.size());
      r.x.push_back(x);
      r.y.push_back(y);
      r.z.push_back(std::hypot(x, y) < column_radius ? column : 0.0);
      r.active.push_back(std::hypot(x, y) < column_radius + 2 * h ? 1 : 0);
    }
  r.area.assign(r.x.size(), 0.0);
  const auto at = [&](int i, int j) {
    const auto it = index.find({i, j});
    return it == index.end() ? -1 : static_cast<long>(it->second);
  };
  for (const auto& [ij, a] : index) {
    const auto [i, j] = ij;
    const long b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
    const long tris[2][3] = {{a, b, c}, {a, c, d}};
    for (const auto& t : tris) {
      if (t[0] < 0 || t[1] < 0 || t[2] < 0) continue;
      for (int k = 0; k < 3; ++k) {
        r.area[static_cast<std::size_t>(t[k])] += h * h / 6.0;
        r.edges.push_back(static_cast<std::uint32_t>(t[k]));
        r.edges.push_back(static_cast<std::uint32_t>(t[(k + 1) % 3]));
      }
    }
  }
  const int ring[6][2] = {{1, 0}, {1, 1}, {0, 1}, {-1, 0}, {-1, -1}, {0, -1}};  // counter-clockwise
  std::vector<std::pair<int, int>> lattice(r.x.size());                         // index -> (i, j)
  for (const auto& [ij, a] : index) lattice[a] = ij;
  r.ring_begin.assign(r.x.size() + 1, 0);
  for (std::size_t a = 0; a < lattice.size(); ++a) {
    std::vector<std::uint32_t> members;
    for (const auto& o : ring) {
      const long m = at(lattice[a].first + o[0], lattice[a].second + o[1]);
      if (m >= 0) members.push_back(static_cast<std::uint32_t>(m));
    }
    if (members.size() == 6) r.ring.insert(r.ring.end(), members.begin(), members.end());
    r.ring_begin[a + 1] = static_cast<std::uint32_t>(r.ring.size());
  }
  return r;
}

double volume(const CascadeRegion& r) {
  double v = 0.0;
  for (std::size_t i = 0; i < r.size(); ++i) v += r.area[i] * r.z[i];
  return v;
}
double energy(const CascadeRegion& r) {
  double e = 0.0;
  for (std::size_t i = 0; i < r.size(); ++i) e += 0.5 * r.area[i] * r.z[i] * r.z[i];
  return e;
}

ErosionRule rule30() {
  Material m;
  m.critical_angle_deg = 30.0;
  m.transfer_fraction = 0.5;
  return ErosionRule::from(m, 0.1);
}

TEST(TinSettleCascade, VolumeExactAndEnergyFallingOnEveryLevelOfADisc) {
  CascadeRegion r = disc_lattice(16, 0.005, 0.08, 0.02, 0.02);
  const double v0 = volume(r), e0 = energy(r);
  CascadeOptions o;
  o.cell_m = 0.005;
  o.measure_energy = true;
  o.fine_level = true;
  const CascadeReport report = settle_cascade(r, rule30(), o);
  ASSERT_GE(report.levels.size(), 2u);  // cells of 2x2, 4x4 lattice spacings (1x1 merges nothing)
  EXPECT_GT(report.moved_m3, 0.1 * v0);
  EXPECT_NEAR(volume(r), v0, 1e-12 * v0);
  EXPECT_LT(energy(r), e0);
  for (std::size_t k = 0; k < report.levels.size(); ++k) {
    const CascadeLevelReport& l = report.levels[k];
    EXPECT_LE(l.energy_after, l.energy_before * (1.0 + 1e-14)) << "level " << k + 1;
    if (k + 1 < report.levels.size()) {
      EXPECT_GT(l.clusters, report.levels[k + 1].clusters);
    }
  }
  EXPECT_LE(report.fine.energy_after, report.fine.energy_before * (1.0 + 1e-14));
  // The fine level ran to repose: the fine rule moves nothing at any vertex it visits.
  ASSERT_LT(report.fine.passes, o.max_fine_passes);
  const ErosionRule rule = rule30();
  for (std::size_t i = 0; i < r.size(); ++i) {
    const std::uint32_t b = r.ring_begin[i], e = r.ring_begin[i + 1];
    if (b == e) continue;
    std::vector<ErosionNeighbour> nbrs;
    for (std::uint32_t k = b; k < e; ++k) {
      const std::uint32_t j = r.ring[k];
      const double dx = r.x[j] - r.x[i], dy = r.y[j] - r.y[i];
      nbrs.push_back({r.z[j], std::hypot(dx, dy), r.area[j], dx, dy});
    }
    std::vector<double> out(nbrs.size());
    EXPECT_EQ(erosion_transfers(r.z[i], r.area[i], {}, nbrs, rule, out, NeighbourLayout::Fan), 0.0) << "vertex " << i;
  }
}

TEST(TinSettleCascade, ClustersAloneKeepVolumeAndLowerEnergy) {
  CascadeRegion r = disc_lattice(30, 0.004, 0.12, 0.04, 0.02);
  const double v0 = volume(r), e0 = energy(r);
  CascadeOptions o;
  o.cell_m = 0.004;
  const CascadeReport report = settle_cascade(r, rule30(), o);
  ASSERT_GE(report.levels.size(), 2u);
  EXPECT_EQ(report.fine.updates, 0u);
  EXPECT_GT(report.moved_m3, 0.0);
  EXPECT_NEAR(volume(r), v0, 1e-12 * v0);
  EXPECT_LT(energy(r), e0);
}

TEST(TinSettleCascade, SmallRegionsAndStrokeBudgetsUseNoCascade) {
  EXPECT_FALSE(cascade_pays(100, ErosionBudget{64}));                      // few active vertices
  EXPECT_FALSE(cascade_pays(kCascadeMinActive, ErosionBudget{4}));         // a stroke's step
  EXPECT_FALSE(cascade_pays(kCascadeMinActive, ErosionBudget{64, 1000}));  // few updates allowed
  EXPECT_TRUE(cascade_pays(kCascadeMinActive, ErosionBudget{64}));
  // A region too small for kCascadeMinClusters clusters: no level, nothing moved.
  CascadeRegion r = disc_lattice(2, 0.005, 0.01, 0.05, 0.006);
  const std::vector<double> z0 = r.z;
  CascadeOptions o;
  o.cell_m = 0.005;
  const CascadeReport report = settle_cascade(r, rule30(), o);
  EXPECT_TRUE(report.levels.empty());
  EXPECT_EQ(r.z, z0);
}

// flat_stroke.toml with a tool deeper than the bed: about 1000 vertices active when the
// stroke ends, so the runner's settling budgets run the cascade.
Scene deep_stroke(const std::string& rule) {
  return load_scene(SB_SOURCE_DIR "/experiments/scenes/flat_stroke.toml",
                    {"tool.depth_m=0.2", "erosion.rule=\"" + rule + "\"", "tool.displacement=\"rim\""});
}

struct Settled {
  std::unique_ptr<Terrain> terrain;
  std::size_t updates = 0;
  double volume_before = 0.0;
  bool settled = false;
};

// The stroke, then settling in budgets of `passes` (the runner's 64; 31 keeps the cascade off).
Settled stroke_and_settle(const Scene& s, int passes) {
  Settled out;
  out.terrain = make(s);
  for (const ToolStamp& st : schedule_of(s).stamps) step(*out.terrain, s, st);
  out.volume_before = out.terrain->volume();
  EXPECT_GE(out.terrain->stats().active, kCascadeMinActive);
  for (int done = 0; done < 100000 && !out.settled; done += passes) {
    out.updates += out.terrain->erode(rule_of(s), ErosionBudget{passes}).updates;
    out.terrain->simplify(SimplifyParams{s.tin.alpha_flat_deg});
    out.settled = out.terrain->stats().active == 0;
  }
  return out;
}

TEST(TinSettleCascade, TinSettlesToReposeWithFewerUpdates) {
  for (const char* rule : {"edge", "gradient"}) {
    SCOPED_TRACE(rule);
    const Scene s = deep_stroke(rule);
    const Settled cascade = stroke_and_settle(s, 64);
    const Settled fine = stroke_and_settle(s, kCascadeMinPasses - 1);
    for (const Settled* r : {&cascade, &fine}) {
      ASSERT_TRUE(r->settled);
      SB_EXPECT_TIN_OK(*r->terrain);
      EXPECT_NEAR(r->terrain->volume(), r->volume_before, 1e-12 * r->volume_before);
      EXPECT_LE(r->terrain->max_slope_deg(), 30.0 + s.erosion.settle_tolerance_deg + 1e-9);
      EXPECT_EQ(r->terrain->erode(rule_of(s), ErosionBudget{1}).transfers, 0u);  // at repose
    }
    EXPECT_LT(cascade.updates, 0.6 * static_cast<double>(fine.updates));  // measured: 0.39, 0.42
    // The same surface, up to the visiting order: heights along the stroke's cross-section.
    double worst = 0.0, sum2 = 0.0;
    for (int k = -40; k <= 40; ++k) {
      const Vec2 p = Vec2(0.35355, 0.35355) + 0.002 * k * Vec2(std::sqrt(0.5), -std::sqrt(0.5));
      const double d = cascade.terrain->height(p) - fine.terrain->height(p);
      worst = std::max(worst, std::abs(d));
      sum2 += d * d;
    }
    // Measured: worst 5.0 mm, RMS 2.8 mm (edge rule), 2.6 and 1.6 mm (gradient rule) in a
    // trench 10 cm deep whose walls rest at 30 degrees either way.
    EXPECT_LT(worst, 0.008);
    EXPECT_LT(std::sqrt(sum2 / 81.0), 0.004);
  }
}

}  // namespace
}  // namespace sb::tin::test
