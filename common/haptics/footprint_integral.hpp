#pragma once
// The exact overlap of a polygon with the cells of a lattice: for every unit cell
// [i, i+1] x [j, j+1] (lattice coordinates) that the polygon overlaps, the piece of the polygon
// inside it, handed to a callback. Rows of cells are cut by Sutherland-Hodgman clipping
// against the row's two lines; within a row, a cell that no side of that strip reaches lies
// wholly inside or wholly outside the polygon (decided at its centre) and is handed over as
// its square, and only the cells the polygon's boundary crosses are clipped again. So the
// pieces tile the polygon exactly (the polygon may be non-convex; a piece is then a
// possibly self-touching polygon whose signed area is still that of the overlap), and each
// piece moves continuously with the polygon: a vertex crossing a cell line only adds a
// degenerate edge. Cost: O(rows * edges + cells overlapped + boundary cells * edges in the
// strip). No allocation: fixed buffers sized for kMaxVertices input vertices.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

#include "common/geometry.hpp"

namespace sb::haptics {

template <int kMaxVertices>
class FootprintCells {
 public:
  // Each half-plane clip at most doubles the vertex count; a piece takes four clips.
  static constexpr int kCapacity = 16 * kMaxVertices + 16;

  // Calls f(piece, count, i, j, whole) for every cell (i, j) with 0 <= i < cells_x,
  // 0 <= j < cells_y that `poly` (n vertices, counter-clockwise, lattice coordinates) overlaps;
  // whole: the piece is the entire cell (its square, counter-clockwise). Returns the number of
  // cells visited.
  template <class F>
  int for_each_piece(const Vec2* poly, int n, int cells_x, int cells_y, F&& f) {
    if (n < 3 || n > kMaxVertices) return 0;
    double vmin = poly[0].y(), vmax = poly[0].y();
    for (int i = 1; i < n; ++i) {
      vmin = std::min(vmin, poly[i].y());
      vmax = std::max(vmax, poly[i].y());
    }
    if (!(vmin < cells_y && vmax > 0.0)) return 0;  // also catches NaN
    const int j_lo = std::max(0, static_cast<int>(std::floor(vmin)));
    const int j_hi = std::min(cells_y - 1, static_cast<int>(std::floor(vmax)));
    int visited = 0;
    for (int j = j_lo; j <= j_hi; ++j) {
      const double lo = j, hi = j + 1.0;
      int m = clip(poly, n, a_.data(), 1, lo, false);      // v >= lo
      m = clip(a_.data(), m, strip_.data(), 1, hi, true);  // v <= hi
      if (m < 3) continue;
      visited += row(m, j, cells_x, f);
    }
    return visited;
  }

 private:
  // Sutherland-Hodgman against one axis-aligned half-plane: coordinate `axis` >= line
  // (upper = false) or <= line (upper = true). Intersection points lie exactly on the line.
  static int clip(const Vec2* in, int n, Vec2* out, int axis, double line, bool upper) {
    int m = 0;
    auto inside = [&](const Vec2& p) { return upper ? p[axis] <= line : p[axis] >= line; };
    for (int i = 0, k = n - 1; i < n; k = i++) {
      const Vec2& a = in[k];
      const Vec2& b = in[i];
      const bool ia = inside(a), ib = inside(b);
      if (ia != ib) {
        const double t = (line - a[axis]) / (b[axis] - a[axis]);
        Vec2 x = a + t * (b - a);
        x[axis] = line;
        out[m++] = x;
      }
      if (ib) out[m++] = b;
    }
    return m;
  }

  // The cells of row j overlapped by the strip polygon strip_[0, m).
  template <class F>
  int row(int m, int j, int cells_x, F& f) {
    const double lo = j, hi = j + 1.0, mid = j + 0.5;
    // Sides: the strip's edges not lying on its two lines; they decide which cells need
    // clipping. Their crossings of the middle line decide inside / outside for the rest.
    int sides = 0, crossings = 0;
    double umin = strip_[0].x(), umax = strip_[0].x();
    for (int i = 0, k = m - 1; i < m; k = i++) {
      const Vec2& a = strip_[k];
      const Vec2& b = strip_[i];
      umin = std::min(umin, b.x());
      umax = std::max(umax, b.x());
      if ((a.y() == lo && b.y() == lo) || (a.y() == hi && b.y() == hi)) continue;
      side_lo_[sides] = std::min(a.x(), b.x());
      side_hi_[sides++] = std::max(a.x(), b.x());
      if ((a.y() <= mid) != (b.y() <= mid))
        xs_[crossings++] = a.x() + (mid - a.y()) * (b.x() - a.x()) / (b.y() - a.y());
    }
    std::sort(xs_.begin(), xs_.begin() + crossings);
    const int i_lo = std::max(0, static_cast<int>(std::floor(umin)));
    const int i_hi = std::min(cells_x - 1, static_cast<int>(std::floor(umax)));
    int visited = 0, left_of_centre = 0;
    for (int i = i_lo; i <= i_hi; ++i) {
      const double c0 = i, c1 = i + 1.0;
      bool crossed = false;
      for (int s = 0; s < sides && !crossed; ++s) crossed = side_lo_[s] <= c1 && side_hi_[s] >= c0;
      if (crossed) {
        int k = clip(strip_.data(), m, a_.data(), 0, c0, false);
        k = clip(a_.data(), k, piece_.data(), 0, c1, true);
        if (k >= 3) {
          f(static_cast<const Vec2*>(piece_.data()), k, i, j, false);
          ++visited;
        }
        continue;
      }
      const double centre = i + 0.5;
      while (left_of_centre < crossings && xs_[left_of_centre] < centre) ++left_of_centre;
      if (left_of_centre % 2 == 1) {
        square_[0] = Vec2(c0, lo);
        square_[1] = Vec2(c1, lo);
        square_[2] = Vec2(c1, hi);
        square_[3] = Vec2(c0, hi);
        f(static_cast<const Vec2*>(square_.data()), 4, i, j, true);
        ++visited;
      }
    }
    return visited;
  }

  std::array<Vec2, kCapacity> a_, strip_, piece_;
  std::array<Vec2, 4> square_;
  std::array<double, kCapacity> side_lo_, side_hi_, xs_;
};

}  // namespace sb::haptics
