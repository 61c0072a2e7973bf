// The display feed the window reads (harness/interactive/display_feed.hpp): fed incrementally,
// with the window taking the changes now and then, its copy ends equal to a full read of the
// terrain on every back-end (the grids' lattice bit for bit, the TIN's mesh vertex for vertex),
// and every stamp time reaches the window once. Then the simulation thread driven by a replay
// device: the volume it tracks from the phases' reports equals volume() at the end, and a
// window's copy taken while it ran equals the terrain once it stopped.
#include "harness/interactive/display_feed.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <random>
#include <thread>

#include "common/haptics/replay_device.hpp"
#include "common/height_field.hpp"
#include "common/scene.hpp"
#include "harness/interactive/device.hpp"
#include "harness/interactive/sim.hpp"
#include "harness/run/backends.hpp"
#include "harness_test_support.hpp"
#include "terrain_test_support.hpp"

namespace sb {
namespace {

// A window's copy, brought up to date by what it takes: a lattice's heights, or a mesh's faces
// by tile.
struct WindowCopy {
  std::vector<float> z;
  std::vector<std::vector<float>> tiles;
  std::vector<double> stamp_times_s;
  void take(DisplayFeed& feed) {
    if (feed.mesh_tiles() > 0) {
      MeshTileUpdate u;
      feed.take(u);
      stamp_times_s.insert(stamp_times_s.end(), u.stamp_times_s.begin(), u.stamp_times_s.end());
      tiles.resize(feed.mesh_tiles());
      ASSERT_EQ(u.offsets.size(), u.tiles.size() + 1);
      for (std::size_t k = 0; k < u.tiles.size(); ++k)
        tiles[u.tiles[k]].assign(u.xyz.begin() + static_cast<std::ptrdiff_t>(u.offsets[k]),
                                 u.xyz.begin() + static_cast<std::ptrdiff_t>(u.offsets[k + 1]));
      return;
    }
    LatticeUpdate u;
    feed.take(u);
    stamp_times_s.insert(stamp_times_s.end(), u.stamp_times_s.begin(), u.stamp_times_s.end());
    if (!feed.lattice()) return;
    const std::size_t nx = feed.lattice()->nx;
    std::size_t offset = 0;
    for (const NodeRect& r : u.rects)
      for (std::size_t y = r.y0; y < r.y1; ++y)
        for (std::size_t x = r.x0; x < r.x1; ++x) z[y * nx + x] = u.heights[offset++];
    EXPECT_EQ(offset, u.heights.size());
  }
};

std::vector<float> read_all(const Terrain& t, const HeightLattice& l, double z_ref) {
  std::vector<float> z(l.nx * l.ny);
  t.lattice_heights({0, 0, l.nx, l.ny}, z_ref, z.data(), l.nx);
  return z;
}

void expect_same_mesh(const SurfaceMesh& a, const SurfaceMesh& b, const std::string& who) {
  ASSERT_EQ(a.vertices.size(), b.vertices.size()) << who;
  ASSERT_EQ(a.triangles.size(), b.triangles.size()) << who;
  for (std::size_t i = 0; i < a.vertices.size(); ++i) ASSERT_EQ(a.vertices[i], b.vertices[i]) << who << " vertex " << i;
  EXPECT_EQ(a.triangles, b.triangles) << who;
}

using Face = std::array<float, 9>;

// The faces of the window's tiles, sorted.
std::vector<Face> tile_faces(const WindowCopy& w) {
  std::vector<Face> faces;
  for (const std::vector<float>& t : w.tiles) {
    EXPECT_EQ(t.size() % 9, 0u);
    for (std::size_t i = 0; i + 9 <= t.size(); i += 9) {
      Face f;
      std::copy_n(t.begin() + static_cast<std::ptrdiff_t>(i), 9, f.begin());
      faces.push_back(f);
    }
  }
  std::sort(faces.begin(), faces.end());
  return faces;
}

// The faces of a whole mesh as the feed sends them (float corners relative to `origin`), sorted.
std::vector<Face> mesh_faces(const SurfaceMesh& m, const Vec3& origin) {
  std::vector<Face> faces;
  for (const auto& t : m.triangles) {
    Face f;
    for (int c = 0; c < 3; ++c) {
      const Vec3 q = m.vertices[t[static_cast<std::size_t>(c)]] - origin;
      for (int a = 0; a < 3; ++a) f[static_cast<std::size_t>(3 * c + a)] = static_cast<float>(q[a]);
    }
    faces.push_back(f);
  }
  std::sort(faces.begin(), faces.end());
  return faces;
}

// The window's copy equals a full read of the terrain.
void expect_copy_of(const WindowCopy& w, DisplayFeed& feed, const Terrain& t, const std::string& who) {
  if (feed.lattice()) {
    EXPECT_EQ(w.z, read_all(t, *feed.lattice(), feed.z_ref())) << who;
  } else if (feed.mesh_tiles() > 0) {
    const std::vector<Face> tiled = tile_faces(w), whole = mesh_faces(t.mesh(), feed.origin());
    EXPECT_EQ(tiled.size(), whole.size()) << who;
    EXPECT_TRUE(tiled == whole) << who << ": the tiles' faces differ from the whole mesh's";
  } else {
    ASSERT_TRUE(feed.mesh()) << who;
    expect_same_mesh(feed.mesh()->mesh, t.mesh(), who);
  }
}

TEST(DisplayFeed, IncrementalCopyEqualsAFullReadOnEveryBackEnd) {
  const Scene s = parse_scene(test::flat_sand_scene("0.4", "0.1", test::kDisk2cm, R"(
[stroke]
path_m = [[0.1, 0.2], [0.2, 0.2]]
spacing_m = 0.005
[grid]
cell_m = 0.002
)"),
                              "test", {});
  const HeightField field = HeightField::from_scene(s);
  const ErosionRule rule = test::rule_of(s);
  struct Case {
    std::string backend;
    bool tiles;
  };
  for (const Case& c : {Case{"grid", true}, Case{"sparse", true}, Case{"tin", true}, Case{"tin", false}}) {
    const std::string who = c.backend + (c.tiles ? "" : " whole");
    auto t = make_terrain(c.backend, s, field);
    DisplayFeed feed(*t, 0.1, s.domain.box(), c.tiles);
    EXPECT_EQ(feed.mesh_tiles() > 0, c.backend == "tin" && c.tiles) << who;
    std::vector<double> times;
    ASSERT_TRUE(feed.publish(*t, true, times));
    WindowCopy window;
    if (feed.lattice()) window.z.assign(feed.lattice()->nx * feed.lattice()->ny, -1.0f);
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> pos(0.05, 0.35), depth(0.004, 0.012);
    std::vector<double> sent;
    for (int i = 0; i < 16; ++i) {
      t->stamp(test::stamp_at(s, {pos(rng), pos(rng)}, 0.1 - depth(rng), {0.3, 1.0}, static_cast<std::uint32_t>(i)));
      times.push_back(i);
      sent.push_back(i);
      t->erode(rule, {.max_passes = 4});
      if (i % 5 == 4) t->simplify({});
      if (i % 2 == 0) feed.publish(*t, true, times);  // some changes published in the next one
      if (i % 3 == 0) window.take(feed);              // some publications taken together
    }
    t->erode(rule, {.max_passes = 64, .settling = true});
    feed.publish(*t, true, times);
    window.take(feed);
    expect_copy_of(window, feed, *t, who);
    EXPECT_EQ(window.stamp_times_s, sent) << who;
    if (feed.lattice()) {
      LatticeUpdate none;
      EXPECT_FALSE(feed.take(none)) << who << ": nothing left pending";
    } else if (feed.mesh_tiles() > 0) {
      MeshTileUpdate none;
      EXPECT_FALSE(feed.take(none)) << who << ": nothing left pending";
    }
  }
}

// A replay presses a disk 1 cm into flat_stroke.toml and drags it 6 cm, with erosion on.
TEST(DisplayFeed, SimulationTracksTheVolumeAndFeedsTheWholeSurface) {
  const PreparedScene prepared = prepare_scene(load_scene(test::shipped_scene("flat_stroke.toml"), {}));
  haptics::Trajectory traj;
  const Vec2 a(0.30, 0.33), b(0.36, 0.36);
  for (int i = 0; i <= 120; ++i) {
    const double u = i / 120.0;
    const Vec2 xy = a + std::max(0.0, (u - 0.2) / 0.8) * (b - a);
    traj.samples.push_back({0.9 * u, Vec3(xy.x(), xy.y(), 0.105 - 0.015 * std::min(1.0, u / 0.2)), 0});
  }
  for (const std::string backend : {"grid", "sparse", "tin"}) {
    const haptics::DeviceLimits limits = scene_device_limits(prepared.initial, 8.0, 2000.0);
    haptics::ReplayDevice device(traj, limits);
    haptics::PatchBuffer patches;
    haptics::ServoOptions options;
    options.realtime = false;
    haptics::ServoLoop servo(device, patches, options);
    Simulation sim(prepared, make_terrain(backend, prepared.scene, prepared.initial), patches, servo, backend);
    DisplayFeed& feed = sim.display();
    WindowCopy window;
    if (feed.lattice()) window.z.assign(feed.lattice()->nx * feed.lattice()->ny, -1.0f);
    servo.start();
    sim.start();
    for (int i = 0; i < 400 && !device.finished(); ++i) {
      window.take(feed);
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    servo.stop();
    sim.stop();  // publishes the final surface
    ASSERT_TRUE(device.finished()) << backend;
    const SimTotals totals = sim.totals();
    EXPECT_GE(totals.stamps, 5u) << backend;
    EXPECT_GT(totals.display_ms.size(), 1u) << backend;
    EXPECT_NEAR(totals.volume_tracked_m3, totals.volume_final_m3, 1e-12 * totals.volume_initial_m3) << backend;
    window.take(feed);
    expect_copy_of(window, feed, sim.terrain(), backend);
    EXPECT_EQ(window.stamp_times_s.size(), totals.stamps) << backend;
  }
}

}  // namespace
}  // namespace sb
