// A TIN run must not depend on where the heap puts its vertices and faces: the same scene run
// twice in one process (so at different addresses, with the heap laid out differently) gives
// the same mesh, bit for bit. Orders that follow addresses (hash maps, pointer sorts, a walk
// started from "the lowest address") once made two reproductions of the paper disagree.
// Nor on whether it is observed: queries between the steps (height(), sample(): the runner's
// energy rasters, renders, haptic patches) once moved the walk the next stamp started from.
#include <gtest/gtest.h>

#include <functional>
#include <memory>
#include <random>
#include <vector>

#include "common/raster.hpp"
#include "tin_test_support.hpp"

namespace sb::tin::test {
namespace {

// A stroke that digs, leaves the domain and comes back along the border: stamps clipped by the
// border, constraints dropped behind the tool, erosion into the border.
// `observe` is called after every step.
SurfaceMesh run_leaving_stroke(const std::function<void(const Terrain&, const Scene&)>& observe = {}) {
  const Scene s = scene(kFlatScene, {"stroke.path_m=[[0.25, 0.25], [0.55, 0.25], [0.55, -0.05], [0.25, 0.02]]"});
  auto t = make(s);
  for (const ToolStamp& st : schedule_of(s).stamps) {
    step(*t, s, st);
    if (observe) observe(*t, s);
  }
  relax(*t, s, 20000);
  SB_EXPECT_TIN_OK(*t);
  return t->mesh();
}

// Blocks of many sizes, every other one freed: the next allocations land in holes whose
// order differs from a fresh heap's.
std::vector<std::unique_ptr<char[]>> fragment_heap() {
  std::mt19937 rng(12345);
  std::vector<std::unique_ptr<char[]>> kept;
  for (int i = 0; i < 4000; ++i) {
    const std::size_t n = 16 + rng() % 5000;
    auto block = std::make_unique<char[]>(n);
    if (i % 2 == 0) kept.push_back(std::move(block));  // the odd ones are freed at once
  }
  return kept;
}

void expect_same_mesh(const SurfaceMesh& first, const SurfaceMesh& second) {
  ASSERT_EQ(first.vertices.size(), second.vertices.size());
  ASSERT_EQ(first.triangles.size(), second.triangles.size());
  // Sets of points compared in position order: the output order may follow the container's.
  auto sorted = [](std::vector<Vec3> v) {
    std::sort(v.begin(), v.end(), [](const Vec3& a, const Vec3& b) {
      return std::tie(a.x(), a.y(), a.z()) < std::tie(b.x(), b.y(), b.z());
    });
    return v;
  };
  const std::vector<Vec3> a = sorted(first.vertices), b = sorted(second.vertices);
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a[i], b[i]) << "vertex " << i;
}

TEST(TinReproducible, SameMeshWhateverTheHeapLayout) {
  const SurfaceMesh first = run_leaving_stroke();
  const auto holes = fragment_heap();
  expect_same_mesh(first, run_leaving_stroke());
}

TEST(TinReproducible, SameMeshWhetherObservedOrNot) {
  const SurfaceMesh unobserved = run_leaving_stroke();
  const SurfaceMesh observed = run_leaving_stroke([](const Terrain& t, const Scene& s) {
    // Walks to scattered points, a raster too coarse to rasterise (walks), a fine one.
    for (int i = 0; i < 50; ++i) t.height({0.01 * i, 0.5 - 0.0097 * i});
    Raster coarse = Raster::covering(s.domain.box(), 0.1), fine = Raster::covering(s.domain.box(), 0.004);
    t.sample(coarse);
    t.sample(fine);
  });
  expect_same_mesh(unobserved, observed);
}

}  // namespace
}  // namespace sb::tin::test
