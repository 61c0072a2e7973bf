// The lock-free hand-overs between the servo and the simulation (TripleBuffer, SpscRing),
// the tick histogram, and height patches filled from a real terrain.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "common/haptics/height_patch.hpp"
#include "common/haptics/spsc_ring.hpp"
#include "common/haptics/tick_histogram.hpp"
#include "common/haptics/triple_buffer.hpp"
#include "common/height_field.hpp"
#include "common/scene.hpp"
#include "common_haptics_test_support.hpp"
#include "grid/grid_terrain.hpp"

namespace sb::haptics {
namespace {

TEST(HapticsTripleBuffer, ReaderSeesTheNewestPublishedValueOnce) {
  TripleBuffer<int> b(0);
  EXPECT_FALSE(b.update());
  EXPECT_EQ(b.front(), 0);
  b.back() = 1;
  b.publish();
  b.back() = 2;
  b.publish();  // replaces 1, which the reader never took
  EXPECT_TRUE(b.update());
  EXPECT_EQ(b.front(), 2);
  EXPECT_FALSE(b.update());
  EXPECT_EQ(b.front(), 2);
  b.back() = 3;
  b.publish();
  EXPECT_TRUE(b.update());
  EXPECT_EQ(b.front(), 3);
}

// A writer fills whole patches with their version number while a reader checks that every
// patch it sees is whole (never torn) and that versions never go back. Run under TSan too.
TEST(HapticsTripleBuffer, ConcurrentPatchesAreNeverTorn) {
  PatchBuffer buffer;
  reserve_patches(buffer, 33);
  std::atomic<bool> done{false};
  const std::uint64_t publications = 20000;
  std::thread writer([&] {
    for (std::uint64_t v = 1; v <= publications; ++v) {
      HeightPatch& p = buffer.back();
      p.heights.nx = p.heights.ny = 33;
      p.heights.values.assign(33 * 33, static_cast<double>(v));
      p.version = v;
      p.valid = true;
      buffer.publish();
    }
    done.store(true);
  });
  std::uint64_t last = 0, seen = 0;
  bool torn = false, backwards = false;
  while (!done.load() || buffer.update()) {
    buffer.update();
    const HeightPatch& p = buffer.front();
    if (!p.valid) continue;
    for (double h : p.heights.values) torn |= h != static_cast<double>(p.version);
    backwards |= p.version < last;
    seen += p.version != last;
    last = p.version;
  }
  writer.join();
  buffer.update();
  EXPECT_FALSE(torn);
  EXPECT_FALSE(backwards);
  EXPECT_EQ(buffer.front().version, publications);  // the last one always arrives
  EXPECT_GT(seen, 0u);
}

TEST(HapticsSpscRing, KeepsOrderAcrossThreadsAndRefusesWhenFull) {
  SpscRing<int> small(3);
  EXPECT_EQ(small.capacity(), 4u);
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(small.push(i));
  EXPECT_FALSE(small.push(99));
  int v = -1;
  EXPECT_TRUE(small.pop(v));
  EXPECT_EQ(v, 0);

  SpscRing<int> ring(256);
  const int n = 200000;
  std::thread producer([&] {
    for (int i = 0; i < n;)
      if (ring.push(i)) ++i;
  });
  int expected = 0;
  bool in_order = true;
  while (expected < n) {
    int x;
    if (ring.pop(x)) in_order &= x == expected++;
  }
  producer.join();
  EXPECT_TRUE(in_order);
  int x;
  EXPECT_FALSE(ring.pop(x));
}

TEST(HapticsTickHistogram, PercentilesAreUpperBinEdgesAndMaxIsExact) {
  TickHistogram h;
  EXPECT_EQ(h.percentile(0.5), 0.0);
  for (int i = 1; i <= 100; ++i) h.add(i);  // 1 .. 100 us
  EXPECT_EQ(h.count(), 100u);
  EXPECT_DOUBLE_EQ(h.max(), 100.0);
  EXPECT_NEAR(h.percentile(0.5), 50.0, TickHistogram::kBinUs + 1e-9);
  EXPECT_NEAR(h.percentile(0.99), 99.0, TickHistogram::kBinUs + 1e-9);
  EXPECT_DOUBLE_EQ(h.percentile(1.0), 100.0);
  h.add(1e6);  // beyond the range: kept as the maximum
  EXPECT_DOUBLE_EQ(h.max(), 1e6);
  EXPECT_DOUBLE_EQ(h.percentile(1.0), 1e6);
  EXPECT_NEAR(h.percentile(0.5), 51.0, TickHistogram::kBinUs + 1e-9);  // rank 51 of 101
  h.add(-3.0);                                                         // a clock going backwards counts as zero
  EXPECT_EQ(h.count(), 102u);
}

TEST(HapticsPatch, LayoutCoversTheToolAndItsMargin) {
  const PatchLayout l = PatchLayout::for_tool(0.02, 0.015, 48);
  EXPECT_EQ(l.cells % 2, 1u);
  EXPECT_DOUBLE_EQ(l.half_m, 0.035);
  EXPECT_NEAR(l.spacing_m * static_cast<double>(l.cells - 1), 2.0 * l.half_m, 1e-15);
}

TEST(HapticsPatch, FilledFromAGridTerrainItHoldsTheTerrainHeights) {
  const Scene scene = parse_scene(R"(
[domain]
size_m = [0.5, 0.5]
[terrain]
kind = "dunes"
height_m = 0.1
amplitude_m = 0.03
wavelength_m = 0.15
[stroke]
path_m = [[0.25, 0.25]]
[grid]
cell_m = 0.005
)",
                                  "patch.toml");
  const HeightField initial = HeightField::from_scene(scene);
  const auto terrain = grid::make_grid_terrain(scene, initial);
  const ForceParams params = ForceParams::from(test::sand(), test::disk(0.02));
  const PatchLayout layout = PatchLayout::for_tool(params.reach_m, 0.02);
  PatchBuffer buffer;
  reserve_patches(buffer, layout.cells);
  const Vec2 centre(0.2, 0.31);
  fill_patch(*terrain, centre, layout, params, 7, buffer.back());
  const double* storage = buffer.back().heights.values.data();
  buffer.publish();
  ASSERT_TRUE(buffer.update());
  const HeightPatch& p = buffer.front();
  EXPECT_TRUE(p.valid);
  EXPECT_EQ(p.version, 7u);
  EXPECT_EQ(p.heights.values.data(), storage);  // filled in place: reserve made room
  EXPECT_EQ(p.heights.nx, layout.cells);
  EXPECT_NEAR((p.heights.point(layout.cells / 2, layout.cells / 2) - centre).norm(), 0.0, 1e-15);
  for (std::size_t iy = 0; iy < p.heights.ny; iy += 7)
    for (std::size_t ix = 0; ix < p.heights.nx; ix += 5)
      EXPECT_DOUBLE_EQ(p.heights.at(ix, iy), terrain->height(p.heights.point(ix, iy)));
  EXPECT_EQ(p.params.footprint_size, 32);
  EXPECT_NEAR(p.params.reach_m, 0.02, 1e-12);
}

TEST(HapticsPatch, ForceParamsDecimateHugeFootprintsAndGivePoursADisk) {
  ToolSpec fine = test::disk(0.02);
  fine.sides = 4096;
  const ForceParams p = ForceParams::from(test::sand(), fine);
  EXPECT_LE(p.footprint_size, ForceParams::kMaxFootprint);
  EXPECT_GE(p.footprint_size, ForceParams::kMaxFootprint / 2);
  ToolSpec pour;
  pour.shape = ToolShape::Pour;
  pour.radius_m = 0.03;
  const ForceParams q = ForceParams::from(test::sand(), pour);
  EXPECT_EQ(q.footprint_size, 16);
  EXPECT_NEAR(q.reach_m, 0.03, 1e-12);
}

}  // namespace
}  // namespace sb::haptics
