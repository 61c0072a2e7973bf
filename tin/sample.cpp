// Raster sampling (Terrain::sample): the TIN's piecewise-linear surface at every point of a
// raster, by the cheaper of two routes that give the same heights.
//   - Rasterising the faces, when the raster has at least one point per kFacesPerPoint faces
//     (a whole-terrain raster): every finite face takes the raster points inside it (the
//     points of its bounding box, tested against its edges) and interpolates them with the
//     same expression as height(). O(faces + points).
//   - A walk per point (height()), row by row in boustrophedon order so that each walk is one
//     or two faces long: O(points). Used for sparse rasters on large TINs (a haptic patch on 10^5
//     vertices), and for the points no face took: outside the domain (height() clamps them),
//     and points on an edge whose rounded edge tests both faces declined.
// Same heights: a point strictly inside a face gets interpolate(face, point), as height()
// gives it; a point on a vertex gets the vertex's height, as height() does; a point on an
// edge gets the interpolation of either face, as height()'s walk may end in either (they
// agree to rounding, a few units in the last place).
// Rasterising face by face costs a few times fewer instructions a point than walking to each
// point, until the faces outnumber the points (then the faces' loop waits on memory), so very
// large TINs walk. tests/bench/tin_query_bench.cpp measures both on 10^4 to 10^6 vertices.
#include <algorithm>
#include <cmath>
#include <limits>

#include "tin/detail/tin_impl.hpp"

namespace sb::tin::detail {

namespace {

// Rasterise when faces <= kFacesPerPoint x raster points (measured above: 2.5 faces a point
// still halves the time).
constexpr double kFacesPerPoint = 4.0;

// The raster indices i with lo <= origin + i * spacing <= hi (as the division rounds: a point
// it leaves out is walked to), clipped to [0, n - 1]; false when none.
bool index_range(double lo, double hi, double origin, double spacing, std::size_t n, std::size_t& i0, std::size_t& i1) {
  const double a = std::ceil((lo - origin) / spacing), b = std::floor((hi - origin) / spacing);
  if (!(a <= b) || b < 0.0 || a > static_cast<double>(n - 1)) return false;
  i0 = a < 0.0 ? 0 : static_cast<std::size_t>(a);
  i1 = std::min(static_cast<std::size_t>(b), n - 1);
  return i0 <= i1;
}

}  // namespace

void TinTerrain::sample(Raster& out) const {
  const std::size_t points = out.nx * out.ny;
  constexpr double kUnset = std::numeric_limits<double>::quiet_NaN();
  out.values.assign(points, kUnset);
  if (points == 0) return;
  if (static_cast<double>(cdt_.tds().number_of_faces()) <= kFacesPerPoint * static_cast<double>(points)) {
    for (auto f = cdt_.finite_faces_begin(); f != cdt_.finite_faces_end(); ++f) {
      const Point &a = f->vertex(0)->point(), &b = f->vertex(1)->point(), &c = f->vertex(2)->point();
      const double lo_x = std::min({a.x(), b.x(), c.x()}), hi_x = std::max({a.x(), b.x(), c.x()});
      const double lo_y = std::min({a.y(), b.y(), c.y()}), hi_y = std::max({a.y(), b.y(), c.y()});
      // (No zero-area faces in a CGAL triangulation; a guard, as interpolate() has one.)
      if (!((b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x()) > 0.0)) continue;
      std::size_t x0 = 0, x1 = 0, y0 = 0, y1 = 0;
      if (!index_range(lo_x, hi_x, out.origin_m.x(), out.spacing_m, out.nx, x0, x1) ||
          !index_range(lo_y, hi_y, out.origin_m.y(), out.spacing_m, out.ny, y0, y1))
        continue;
      for (std::size_t iy = y0; iy <= y1; ++iy)
        for (std::size_t ix = x0; ix <= x1; ++ix) {
          double& value = out.at(ix, iy);
          if (!std::isnan(value)) continue;
          const Vec2 p = out.point(ix, iy);
          // Counter-clockwise face: p is inside (or on its boundary) when it lies left of, or
          // on, each edge. Outside the domain, height() clamps the point first: left to it.
          const auto left_of = [&p](const Point& u, const Point& v) {
            return (v.x() - u.x()) * (p.y() - u.y()) - (v.y() - u.y()) * (p.x() - u.x()) >= 0.0;
          };
          if (!left_of(a, b) || !left_of(b, c) || !left_of(c, a) || !box_.contains(p)) continue;
          const Point* const corners[3] = {&a, &b, &c};
          value = interpolate(f, p);
          for (const Point* v : corners)
            if (v->x() == p.x() && v->y() == p.y()) value = v->z();
        }
    }
  }
  for (std::size_t iy = 0; iy < out.ny; ++iy)
    for (std::size_t k = 0; k < out.nx; ++k) {
      const std::size_t ix = iy % 2 == 0 ? k : out.nx - 1 - k;
      double& value = out.at(ix, iy);
      if (std::isnan(value)) value = height(out.point(ix, iy));
    }
}

}  // namespace sb::tin::detail
