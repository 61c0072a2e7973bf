// Display change tracking (Terrain::changes_since, lattice_heights) on the lattice back-ends,
// each built through sb::make_terrain (grid in double and float, sparse): after random stamps,
// erosion steps and settling with the cascade, every node whose height changed lies in a
// rectangle the terrain reported; a stamp reports only tiles near its footprint; a terrain left
// alone reports nothing. The TIN has no lattice; every face it adds or removes has its centroid in a
// region it reports.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "common/height_field.hpp"
#include "common/scene.hpp"
#include "harness/run/backends.hpp"
#include "terrain_test_support.hpp"

namespace sb {
namespace {

// 0.6 m at 2 mm: 301 x 301 nodes, 5 x 5 tiles of 64.
Scene lattice_scene(const std::vector<std::string>& overrides) {
  return parse_scene(test::flat_sand_scene("0.6", "0.1", test::kDisk2cm, R"(
[stroke]
path_m = [[0.1, 0.3], [0.2, 0.3]]
spacing_m = 0.005
[grid]
cell_m = 0.002
)"),
                     "test", overrides);
}

struct Backend {
  const char* name;
  std::vector<std::string> overrides;
};

const Backend kLatticeBackends[] = {{"grid", {}}, {"grid", {"grid.storage=float"}}, {"sparse", {}}};

// Every node's height minus the sand's 0.1 m, as the display reads it.
std::vector<float> read_all(const Terrain& t, const HeightLattice& l) {
  std::vector<float> z(l.nx * l.ny);
  t.lattice_heights({0, 0, l.nx, l.ny}, 0.1, z.data(), l.nx);
  return z;
}

bool covered(const std::vector<NodeRect>& rects, std::size_t x, std::size_t y) {
  for (const NodeRect& r : rects)
    if (x >= r.x0 && x < r.x1 && y >= r.y0 && y < r.y1) return true;
  return false;
}

// Every changed node in a reported rectangle; returns how many nodes changed.
std::size_t expect_covered(const std::vector<float>& before, const std::vector<float>& after, const SurfaceChanges& c,
                           const HeightLattice& l, const std::string& what) {
  EXPECT_TRUE(c.tracked) << what;
  std::size_t changed = 0, missed = 0;
  for (std::size_t y = 0; y < l.ny; ++y)
    for (std::size_t x = 0; x < l.nx; ++x) {
      if (before[y * l.nx + x] == after[y * l.nx + x]) continue;
      ++changed;
      if (!covered(c.rects, x, y)) ++missed;
    }
  EXPECT_EQ(missed, 0u) << what << ": " << missed << " of " << changed << " changed nodes outside the reported tiles";
  return changed;
}

TEST(DisplayChanges, EveryChangedHeightIsInAReportedTileAfterRandomStrokes) {
  for (const Backend& b : kLatticeBackends) {
    const Scene s = lattice_scene(b.overrides);
    const HeightField field = HeightField::from_scene(s);
    auto t = make_terrain(b.name, s, field);
    const std::string who = std::string(b.name) + (b.overrides.empty() ? "" : " " + b.overrides[0]);
    const std::optional<HeightLattice> lattice = t->lattice();
    ASSERT_TRUE(lattice) << who;
    const HeightLattice& l = *lattice;
    EXPECT_EQ(l.nx, 301u);

    // The first call reports the whole lattice.
    SurfaceChanges first = t->changes_since(0);
    ASSERT_TRUE(first.tracked);
    std::size_t nodes = 0;
    for (const NodeRect& r : first.rects) nodes += (r.x1 - r.x0) * (r.y1 - r.y0);
    EXPECT_EQ(nodes, l.nx * l.ny) << who;
    std::uint64_t version = first.version;
    EXPECT_TRUE(t->changes_since(version).rects.empty()) << who << ": nothing happened";
    version = t->changes_since(version).version;

    const ErosionRule rule = test::rule_of(s);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> pos(0.05, 0.55), depth(0.004, 0.015);
    std::size_t changed_total = 0;
    std::vector<float> before = read_all(*t, l);
    for (int i = 0; i < 12; ++i) {
      // A stamp: its tiles lie within a tile of its footprint's box (the rim included).
      const Vec2 xy(pos(rng), pos(rng));
      const ToolStamp stamp = test::stamp_at(s, xy, 0.1 - depth(rng), {1.0, 0.5}, static_cast<std::uint32_t>(i));
      t->stamp(stamp);
      SurfaceChanges c = t->changes_since(version);
      version = c.version;
      std::vector<float> after = read_all(*t, l);
      changed_total += expect_covered(before, after, c, l, who + " stamp " + std::to_string(i));
      const double reach = 0.02 * 4 + 64 * 0.002;  // the disk, its rim band, and one tile
      for (const NodeRect& r : c.rects) {
        const double x0 = r.x0 * l.dx, x1 = (r.x1 - 1) * l.dx, y0 = r.y0 * l.dy, y1 = (r.y1 - 1) * l.dy;
        EXPECT_LT(x0, xy.x() + reach) << who;
        EXPECT_GT(x1, xy.x() - reach) << who;
        EXPECT_LT(y0, xy.y() + reach) << who;
        EXPECT_GT(y1, xy.y() - reach) << who;
      }
      before = std::move(after);
      // Erosion steps, and now and then a settling budget (the cascade's coarse levels too).
      for (int k = 0; k < 3; ++k) {
        const ErosionBudget budget =
            (i % 4 == 3 && k == 2) ? ErosionBudget{.max_passes = 64, .settling = true} : ErosionBudget{.max_passes = 4};
        t->erode(rule, budget);
        c = t->changes_since(version);
        version = c.version;
        after = read_all(*t, l);
        changed_total += expect_covered(before, after, c, l, who + " erosion after stamp " + std::to_string(i));
        before = std::move(after);
      }
    }
    EXPECT_GT(changed_total, 1000u) << who << ": the strokes changed the surface";
    // At rest (or merely left alone) nothing more is reported.
    EXPECT_TRUE(t->changes_since(version).rects.empty()) << who;
  }
}

// A face as its corners, starting from the least (the same face, however a mesh lists it).
using Face = std::array<double, 9>;
std::vector<Face> faces_of(const Terrain& t) {
  const SurfaceMesh m = t.mesh();
  std::vector<Face> faces;
  for (const auto& tri : m.triangles) {
    std::size_t first = 0;
    for (std::size_t c = 1; c < 3; ++c) {
      const Vec3 &a = m.vertices[tri[c]], &b = m.vertices[tri[first]];
      if (std::make_tuple(a.x(), a.y(), a.z()) < std::make_tuple(b.x(), b.y(), b.z())) first = c;
    }
    Face f;
    for (std::size_t c = 0; c < 3; ++c) {
      const Vec3& v = m.vertices[tri[(first + c) % 3]];
      for (std::size_t a = 0; a < 3; ++a) f[3 * c + a] = v[static_cast<Eigen::Index>(a)];
    }
    faces.push_back(f);
  }
  std::sort(faces.begin(), faces.end());
  return faces;
}

// Every face added or removed has its centroid in a reported region; returns how many changed.
std::size_t expect_faces_covered(const std::vector<Face>& before, const std::vector<Face>& after,
                                 const SurfaceChanges& c, const std::string& what) {
  EXPECT_TRUE(c.tracked) << what;
  std::vector<Face> changed;
  std::set_symmetric_difference(before.begin(), before.end(), after.begin(), after.end(), std::back_inserter(changed));
  std::size_t missed = 0;
  for (const Face& f : changed) {
    const Vec2 centroid((f[0] + f[3] + f[6]) / 3.0, (f[1] + f[4] + f[7]) / 3.0);
    bool in = false;
    for (const Aabb2& r : c.regions) in = in || r.contains(centroid);
    if (!in) ++missed;
  }
  EXPECT_EQ(missed, 0u) << what << ": " << missed << " of " << changed.size()
                        << " changed faces with their centroid outside the reported regions";
  return changed.size();
}

// The TIN's changes after every edit of random strokes: tools from a disk to one under its
// refinement length, each displacement model, headings all round, erosion, settling (the
// cascade), simplification, and a dunes TIN whose rest coarsens it.
TEST(DisplayChanges, EveryChangedTinFaceHasItsCentroidInAReportedRegion) {
  struct Case {
    std::string name;
    std::string tool;
    std::string terrain;  // extra scene text
  };
  const Case cases[] = {
      {"disk rim", std::string(test::kDisk2cm), ""},
      {"disk rim, no volume give-back", std::string(test::kDisk2cm), "[tin]\nconserve_volume = false\n"},
      {"disk carry", "shape = \"disk\"\nradius_m = 0.02\ndepth_m = 0.01\n", ""},
      {"box bulldoze", "shape = \"box\"\nsize_m = [0.02, 0.03]\ndepth_m = 0.012\ndisplacement = \"bulldoze\"\n", ""},
      {"disk under refine_m", "shape = \"disk\"\nradius_m = 0.0015\ndepth_m = 0.002\n", ""},
      {"dunes, coarsening", "shape = \"disk\"\nradius_m = 0.02\ndepth_m = 0.01\n", "[tin]\ncoarsen = true\n"},
  };
  for (const Case& k : cases) {
    std::vector<std::string> overrides;
    if (k.name.rfind("dunes", 0) == 0)
      overrides = {"terrain.kind=dunes", "terrain.wavelength_m=0.15", "terrain.amplitude_m=0.01"};
    const Scene s = parse_scene(
        test::flat_sand_scene("0.4", "0.1", k.tool, "[stroke]\npath_m = [[0.1, 0.2], [0.2, 0.2]]\n" + k.terrain),
        "test", overrides);
    const HeightField field = HeightField::from_scene(s);
    auto t = make_terrain("tin", s, field);
    EXPECT_FALSE(t->lattice());
    SurfaceChanges first = t->changes_since(0);
    ASSERT_TRUE(first.tracked) << k.name;
    ASSERT_FALSE(first.regions.empty()) << k.name << ": the first call reports everything";
    std::uint64_t version = t->changes_since(first.version).version;
    EXPECT_TRUE(t->changes_since(version).regions.empty()) << k.name << ": nothing happened";
    version = t->changes_since(version).version;

    const ErosionRule rule = test::rule_of(s);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> pos(0.04, 0.36), depth(0.003, 0.012), angle(0.0, 6.283185307179586);
    std::vector<Face> before = faces_of(*t);
    std::size_t changed_total = 0;
    const auto check = [&](const std::string& what) {
      const SurfaceChanges c = t->changes_since(version);
      version = c.version;
      std::vector<Face> after = faces_of(*t);
      changed_total += expect_faces_covered(before, after, c, k.name + " " + what);
      before = std::move(after);
    };
    Vec2 xy(pos(rng), pos(rng));
    for (int i = 0; i < 24; ++i) {
      // Strokes of 6 stamps 4 mm apart, each in a random direction from a random start.
      const double a = angle(rng);
      const Vec2 motion(std::cos(a), std::sin(a));
      if (i % 6 == 0) xy = Vec2(pos(rng), pos(rng));
      xy += 0.004 * motion;
      t->stamp(test::stamp_at(s, xy, 0.1 - depth(rng), motion, static_cast<std::uint32_t>(i / 6 + 1)));
      check("stamp " + std::to_string(i));
      t->erode(rule, {.max_passes = 4});
      check("erosion after stamp " + std::to_string(i));
      if (i % 3 == 2) {
        t->simplify(SimplifyParams{s.tin.alpha_flat_deg});
        check("simplification after stamp " + std::to_string(i));
      }
      if (i % 6 == 5) {
        t->erode(rule, {.max_passes = 64, .settling = true});
        check("settling after stamp " + std::to_string(i));
        t->simplify(SimplifyParams{s.tin.alpha_flat_deg});
        check("simplification at rest after stamp " + std::to_string(i));
      }
    }
    EXPECT_GT(changed_total, 500u) << k.name << ": the strokes changed the mesh";
    EXPECT_TRUE(t->changes_since(version).regions.empty()) << k.name << ": left alone, nothing changes";
  }
}

// On a TIN of 40 000 vertices (a 1 m square), what a stamp and its erosion report stays near
// them: the boxes cover about a hundredth of the domain, so a display reads that much again.
TEST(DisplayChanges, ATinStampReportsOnlyItsNeighbourhood) {
  const Scene s = parse_scene(test::flat_sand_scene("1.0", "0.1", "shape = \"disk\"\nradius_m = 0.02\ndepth_m = 0.01\n",
                                                    "[stroke]\npath_m = [[0.4, 0.5], [0.6, 0.5]]\n"),
                              "test", {"tin.initial_points=40000"});
  auto t = make_terrain("tin", s, HeightField::from_scene(s));
  std::uint64_t version = t->changes_since(0).version;
  const ErosionRule rule = test::rule_of(s);
  for (int i = 0; i < 10; ++i) {
    const Vec2 xy(0.4 + 0.004 * i, 0.5);
    t->stamp(test::stamp_at(s, xy, 0.09, {1.0, 0.0}, 1));
    t->erode(rule, {.max_passes = 4});
    t->simplify(SimplifyParams{s.tin.alpha_flat_deg});
    const SurfaceChanges c = t->changes_since(version);
    version = c.version;
    ASSERT_FALSE(c.regions.empty());
    double area = 0.0;
    for (const Aabb2& r : c.regions) {
      area += (r.hi - r.lo).prod();
      EXPECT_LT((0.5 * (r.lo + r.hi) - xy).norm(), 0.15) << "stamp " << i << ": a region far from the tool";
    }
    EXPECT_LT(area, 0.02) << "stamp " << i << ": m^2 reported, of a 1 m^2 domain";
  }
}

}  // namespace
}  // namespace sb
