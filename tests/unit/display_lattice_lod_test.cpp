// The levels of detail of the lattice display (harness/window/lattice_lod.hpp): for lattices
// of many shapes and foci, every lattice cell is drawn by exactly one patch cell (no gap, no
// overlap), the finest patch is at full resolution around the focus, a patch's border lies on
// the next coarser patch's vertex lines (what keeps the surface free of cracks), and a small
// lattice is one patch of its own cells.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "harness/window/lattice_lod.hpp"

namespace sb {
namespace {

// Node of vertex k of a patch along an axis of n nodes.
std::size_t vertex_node(std::size_t x0, std::size_t stride, std::size_t k, std::size_t n) {
  return std::min(x0 + k * stride, n - 1);
}

void check(std::size_t nx, std::size_t ny, std::size_t fx, std::size_t fy) {
  const std::string what =
      std::to_string(nx) + " x " + std::to_string(ny) + " at " + std::to_string(fx) + ", " + std::to_string(fy);
  const auto [cx, cy] = lattice_patch_cells(nx, ny);
  const std::vector<LatticePatch> patches = lattice_patches(nx, ny, fx, fy);
  ASSERT_FALSE(patches.empty()) << what;
  EXPECT_EQ(patches.front().stride, 1u) << what;
  EXPECT_LE(patches.size(), 16u) << what;
  std::vector<int> drawn((nx - 1) * (ny - 1), 0);
  for (std::size_t p = 0; p < patches.size(); ++p) {
    const LatticePatch& q = patches[p];
    if (p + 1 < patches.size()) {
      const std::size_t coarse = patches[p + 1].stride;
      EXPECT_EQ(q.coarse, coarse) << what;
      EXPECT_EQ(q.x0 % coarse, 0u) << what;
      EXPECT_EQ(q.y0 % coarse, 0u) << what;
      const std::size_t ex = vertex_node(q.x0, q.stride, cx, nx), ey = vertex_node(q.y0, q.stride, cy, ny);
      EXPECT_TRUE(ex % coarse == 0 || ex == nx - 1) << what;
      EXPECT_TRUE(ey % coarse == 0 || ey == ny - 1) << what;
    } else {
      EXPECT_EQ(q.coarse, 0u) << what;
    }
    for (std::size_t j = 0; j < cy; ++j)
      for (std::size_t i = 0; i < cx; ++i) {
        if (i >= q.hx0 && i < q.hx1 && j >= q.hy0 && j < q.hy1) continue;
        const std::size_t xa = vertex_node(q.x0, q.stride, i, nx), xb = vertex_node(q.x0, q.stride, i + 1, nx);
        const std::size_t ya = vertex_node(q.y0, q.stride, j, ny), yb = vertex_node(q.y0, q.stride, j + 1, ny);
        for (std::size_t y = ya; y < yb; ++y)
          for (std::size_t x = xa; x < xb; ++x) ++drawn[y * (nx - 1) + x];
      }
  }
  std::size_t gaps = 0, overlaps = 0;
  for (const int d : drawn) gaps += d == 0, overlaps += d > 1;
  EXPECT_EQ(gaps, 0u) << what;
  EXPECT_EQ(overlaps, 0u) << what;
  // The focus is inside the finest patch, away from its border unless the domain's is near.
  const LatticePatch& fine = patches.front();
  EXPECT_LE(fine.x0, fx) << what;
  EXPECT_LE(fine.y0, fy) << what;
  EXPECT_GE(vertex_node(fine.x0, 1, cx, nx), std::min(fx, nx - 1)) << what;
  EXPECT_GE(vertex_node(fine.y0, 1, cy, ny), std::min(fy, ny - 1)) << what;
}

TEST(LatticeLod, EveryCellIsDrawnOnceAroundAnyFocus) {
  for (const auto& [nx, ny] : std::vector<std::pair<std::size_t, std::size_t>>{{2, 2},
                                                                               {142, 142},
                                                                               {257, 100},
                                                                               {161, 161},
                                                                               {162, 161},
                                                                               {201, 201},
                                                                               {251, 251},
                                                                               {258, 258},
                                                                               {5001, 3},
                                                                               {401, 401},
                                                                               {1001, 1001},
                                                                               {1001, 300},
                                                                               {4097, 4097},
                                                                               {3000, 129}})
    for (const double u : {0.0, 0.13, 0.5, 0.77, 1.0}) {
      check(nx, ny, static_cast<std::size_t>(u * (nx - 1)), static_cast<std::size_t>((1.0 - u) * (ny - 1)));
    }
}

TEST(LatticeLod, SmallLatticesAreOnePatchOfTheirOwnCells) {
  const std::vector<LatticePatch> p = lattice_patches(142, 100, 70, 50);
  ASSERT_EQ(p.size(), 1u);
  EXPECT_EQ(p[0].x0, 0u);
  EXPECT_EQ(p[0].stride, 1u);
  EXPECT_EQ(lattice_patch_cells(142, 100), (std::pair<std::size_t, std::size_t>{141, 99}));
  // Levelled: the triangles drawn do not grow with the lattice.
  EXPECT_LE(lattice_patches(4097, 4097, 2000, 2000).size(), lattice_patches(1001, 1001, 500, 500).size() + 2);
}

// The patch cells a lattice is drawn with (each patch's cells less its hole).
std::size_t drawn_cells(std::size_t nx, std::size_t ny) {
  const auto [cx, cy] = lattice_patch_cells(nx, ny);
  std::size_t cells = 0;
  for (const LatticePatch& p : lattice_patches(nx, ny, nx / 2, ny / 2))
    cells += cx * cy - (p.hx1 - p.hx0) * (p.hy1 - p.hy0);
  return cells;
}

TEST(LatticeLod, WholeOrLevelledByTheCellsNotBySide) {
  // Drawn whole up to kFullCells cells, whatever the shape: the shipped scenes' lattices
  // (141 x 141 cells the largest) and a long thin strip.
  EXPECT_EQ(lattice_patches(142, 142, 70, 70).size(), 1u);
  EXPECT_EQ(lattice_patches(161, 81, 80, 40).size(), 1u);
  EXPECT_EQ(lattice_patches(161, 161, 80, 80).size(), 1u);
  EXPECT_EQ(lattice_patches(5001, 3, 2500, 1).size(), 1u);
  EXPECT_GT(lattice_patches(162, 161, 80, 80).size(), 1u);
  // A small domain at a fine cell (0.25 m at 1 mm: 250 x 250 cells) costs no more to draw than a
  // large one (1 m at 1 mm), and far fewer than its whole mesh.
  EXPECT_LE(drawn_cells(251, 251), drawn_cells(1001, 1001));
  EXPECT_LT(drawn_cells(251, 251), 250u * 250u / 2);
  // No lattice is drawn with more cells than kFullCells until the levels of a very large domain
  // add up to it (each level adds 3/4 of a patch).
  for (const std::size_t n : {2u, 100u, 161u, 162u, 201u, 251u, 400u, 1001u, 2049u})
    EXPECT_LE(drawn_cells(n, n), kFullCells) << n;
}

}  // namespace
}  // namespace sb
