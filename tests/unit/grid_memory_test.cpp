// stats().bytes against the allocator (counting_allocator.hpp): the grid's own account of
// its containers must match what it really holds.
#include "counting_allocator.hpp"
#include "grid_test_support.hpp"

namespace sb::grid::test {
namespace {

template <class Real>
class GridMemory : public ::testing::Test {};
TYPED_TEST_SUITE(GridMemory, StorageTypes, StorageName);

TYPED_TEST(GridMemory, StatsBytesMatchTheAllocator) {
  const Scene s = scene({"terrain.kind=\"dunes\""});
  const HeightField field = HeightField::from_scene(s);
  const StampSchedule schedule = schedule_of(s);
  // The schedule builds stamps on demand: hold them all before counting the grid's bytes.
  const std::vector<ToolStamp> stamps(schedule.stamps.begin(), schedule.stamps.end());
  const ErosionRule rule = rule_of(s);

  const long long before = ::sb::test::live_heap_bytes();
  auto t = make_grid_terrain(s, field);  // the scene's storage is double; build both below
  t.reset();
  ASSERT_EQ(::sb::test::live_heap_bytes(), before);

  const GridLayout layout = GridLayout::covering(s.domain.box(), s.grid.cell_m);
  const auto z0 = [&field](const Vec2& p) { return field(p); };
  auto grid = std::make_unique<GridTerrain<TypeParam>>(layout, z0, 8, 2);
  const auto held = [&] { return static_cast<std::size_t>(::sb::test::live_heap_bytes() - before); };
  EXPECT_EQ(held(), sizeof(GridTerrain<TypeParam>) + grid->stats().bytes);
  // Heights, 2 bytes of idle count per node, a membership bit per node (rows padded to
  // 64 bits) and a member count per row.
  const std::size_t fixed = layout.nodes() * (sizeof(TypeParam) + 2) + layout.ny * ((layout.nx + 63) / 64) * 8 +
                            layout.ny * sizeof(std::uint32_t);
  EXPECT_EQ(grid->stats().bytes, fixed);

  std::size_t peak_active = 0;
  for (const ToolStamp& st : stamps) {
    grid->stamp(st);
    EXPECT_EQ(held(), sizeof(GridTerrain<TypeParam>) + grid->stats().bytes);
    grid->erode(rule, {.max_passes = 4});
    EXPECT_EQ(held(), sizeof(GridTerrain<TypeParam>) + grid->stats().bytes);
    peak_active = std::max(peak_active, grid->stats().active);
  }
  ASSERT_GT(peak_active, 0u);
  // The active set does not grow with its size; erosion adds its node-class tables (at
  // most 5 x 5 classes of a few hundred bytes).
  EXPECT_GT(grid->stats().bytes, fixed);
  EXPECT_LE(grid->stats().bytes, fixed + 25 * 1024);
  grid.reset();
  EXPECT_EQ(::sb::test::live_heap_bytes(), before);
}

}  // namespace
}  // namespace sb::grid::test
