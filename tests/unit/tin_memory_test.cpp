// stats().bytes against allocator accounting (the allocator counting_allocator.cpp installs
// for sb_tin_tests), and check() after every operation.
#include "counting_allocator.hpp"
#include "tin_test_support.hpp"

namespace sb::tin::test {
namespace {

// Live bytes allocated by `make` (and whatever it runs) that are still held at the end.
struct Counted {
  std::unique_ptr<Terrain> terrain;
  long long bytes = 0;
};
template <class Make>
Counted counted(Make&& make) {
  const long long before = ::sb::test::live_heap_bytes();
  Counted c;
  c.terrain = make();
  c.bytes = ::sb::test::live_heap_bytes() - before;
  return c;
}

void expect_bytes_match(const Counted& c, double tolerance, const char* what) {
  const double reported = static_cast<double>(c.terrain->stats().bytes);
  const double actual = static_cast<double>(c.bytes);
  EXPECT_NEAR(reported, actual, tolerance * actual)
      << what << ": stats().bytes " << reported << ", allocator " << actual;
}

// stats().bytes counts the containers' capacities; the allocator sees the same blocks. The
// small difference is the estimate of CGAL's block table and of the hash table's nodes.
TEST(TinMemory, BytesMatchAllocatorAccounting) {
  {
    const Scene s = scene();
    const Counted c = counted([&] { return make(s); });
    expect_bytes_match(c, 0.02, "flat, built");
  }
  {
    const Scene s = scene(kDunesScene);
    const Counted c = counted([&] { return make(s); });
    expect_bytes_match(c, 0.02, "dunes, built");
    const ModelStats st = c.terrain->stats();
    const double per_vertex = static_cast<double>(st.bytes) / static_cast<double>(st.vertices);
    EXPECT_GT(per_vertex, 48.0 + 2.0 * 56.0);  // a vertex and its two triangles
    EXPECT_LT(per_vertex, 220.0);              // plus container slack, as documented
  }
  {
    // After a stroke: constraints (hash nodes), lists and scratch buffers too.
    const Scene s = scene();
    const Counted c = counted([&] {
      auto t = make(s);
      for (const ToolStamp& st : schedule_of(s).stamps) step(*t, s, st);
      return t;
    });
    ASSERT_GT(c.terrain->stats().constrained_edges, 30u);  // the last stamp's
    ASSERT_GT(c.terrain->stats().active, 0u);
    expect_bytes_match(c, 0.02, "flat, after a stroke");
  }
}

TEST(TinCheck, HoldsAfterEveryOperation) {
  const Scene s = scene(kDunesScene, {"tin.conserve_volume=true"});
  auto t = make(s);
  SB_ASSERT_TIN_OK(*t);
  const ErosionRule rule = rule_of(s);
  int k = 0;
  for (const ToolStamp& st : schedule_of(s).stamps) {
    t->stamp(st);
    SB_ASSERT_TIN_OK(*t);
    t->erode(rule, ErosionBudget{4});
    SB_ASSERT_TIN_OK(*t);
    t->simplify(SimplifyParams{0.4});
    SB_ASSERT_TIN_OK(*t);
    if (k++ % 5 == 0) {
      ToolStamp pour;
      pour.pose.xy = st.pose.xy + Vec2(0.03, 0.0);
      pour.pour_volume_m3 = 2e-7;
      pour.pour_radius_m = 0.004;
      t->stamp(pour);
      SB_ASSERT_TIN_OK(*t);
    }
  }
  Raster raster = Raster::covering(s.domain.box(), 0.01);
  t->sample(raster);
  t->mesh();
  SB_ASSERT_TIN_OK(*t);
}

}  // namespace
}  // namespace sb::tin::test
