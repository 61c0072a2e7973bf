#include "harness/window/lattice_lod.hpp"

#include <algorithm>

namespace sb {

namespace {

// The first node of a patch of `extent` lattice cells along an axis of n nodes around node f,
// a multiple of `unit`: centred on f, but never past the far border by a whole unit (the patch
// then reaches it, its last vertices clamped to the border).
std::size_t patch_start(std::size_t n, std::size_t extent, std::size_t f, std::size_t unit) {
  if (extent >= n - 1) return 0;
  const std::size_t centred = f > extent / 2 ? (f - extent / 2) / unit * unit : 0;
  const std::size_t last = (n - 1 - extent + unit - 1) / unit * unit;
  return std::min(centred, last);
}

// The cell of a patch from node x0 with stride s that holds node x (rounded up: the
// first cell past x), clamped to the patch's cells.
std::size_t cell_up(std::size_t x, std::size_t x0, std::size_t s, std::size_t cells) {
  return std::min(cells, (x - x0 + s - 1) / s);
}

}  // namespace

std::vector<LatticePatch> lattice_patches(std::size_t nx, std::size_t ny, std::size_t fx, std::size_t fy) {
  const auto [cx, cy] = lattice_patch_cells(nx, ny);
  fx = std::min(fx, nx - 1);
  fy = std::min(fy, ny - 1);
  std::vector<LatticePatch> patches;
  for (std::size_t s = 1;; s *= 2) {
    LatticePatch p;
    p.stride = s;
    const bool whole = cx * s >= nx - 1 && cy * s >= ny - 1;
    p.x0 = whole ? 0 : patch_start(nx, cx * s, fx, 2 * s);
    p.y0 = whole ? 0 : patch_start(ny, cy * s, fy, 2 * s);
    if (!patches.empty()) {
      LatticePatch& finer = patches.back();
      finer.coarse = s;
      const std::size_t fs = finer.stride;
      const std::size_t ex = std::min(finer.x0 + cx * fs, nx - 1), ey = std::min(finer.y0 + cy * fs, ny - 1);
      p.hx0 = (finer.x0 - p.x0) / s;
      p.hy0 = (finer.y0 - p.y0) / s;
      p.hx1 = cell_up(ex, p.x0, s, cx);
      p.hy1 = cell_up(ey, p.y0, s, cy);
    }
    patches.push_back(p);
    if (whole) return patches;
  }
}

}  // namespace sb
