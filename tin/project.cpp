// The initial TIN's heights: the L2 projection of the terrain onto the mesh.
//
// Greedy insertion (build.cpp) adds vertices until the interpolating TIN is within
// tin.tolerance_m of every sample, but interpolation errs to one side wherever the terrain
// bends: the chords of a cone's circular level lines lie below it, so cone.toml's TIN (35
// degrees, 1 mm tolerance) held 2.7 % less sand than the terrain, and every metric measured
// against the terrain's sand started short. The projection keeps the mesh and takes the heights
// z that minimise the integral of (TIN - terrain)^2 over the domain: M z = b, with M the mass
// matrix of the piecewise-linear hat functions and b_i the integral of the terrain times vertex
// i's hat function (a three-point rule on pieces of the triangle no wider than the terrain's
// detail). Because the hat functions sum to one, the TIN's volume is then the terrain's (to the
// rule's accuracy: cone.toml's sand to 6e-7) and a plane is reproduced exactly; the
// mean-square error is no larger than the interpolant's (measured: cone.toml 65 -> 43 um, dunes
// on 3000 initial points 124 -> 63 um), while the largest error, at a kink (a cone's apex and
// toe), may exceed tin.tolerance_m a little.
//
// Cost: O(faces + domain area / detail^2) to assemble (the pieces are bounded like greedy
// insertion's samples); conjugate gradients with a diagonal preconditioner converge in a
// number of iterations independent of the mesh (the diagonally scaled mass matrix of linear
// triangles has its eigenvalues in [1/2, 2]: Wathen 1987), each O(faces); the mass matrix is
// applied face by face, never stored. 10^6 initial points of dunes: 0.9 s more to build (3.4 ->
// 4.3 s for the whole run), peak memory 374 -> 406 MB.
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "common/height_field.hpp"
#include "tin/detail/tin_impl.hpp"

namespace sb::tin::detail {

namespace {

struct QuadraturePoint {
  double a, b, c;  // barycentric coordinates
  double weight;   // the weights sum to 1
};
// The three-point rule of degree 2 (Strang and Fix): exact where the terrain is linear over a
// triangle. Dunavant's seven-point rule of degree 5 took 0.8 s more on 10^6 initial points of
// dunes (the terrain's sines) for a cone.toml volume error of 1.9e-4 of its sand instead of 3.1e-4.
constexpr std::array<QuadraturePoint, 3> kRule{{{2.0 / 3.0, 1.0 / 6.0, 1.0 / 6.0, 1.0 / 3.0},
                                                {1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0, 1.0 / 3.0},
                                                {1.0 / 6.0, 1.0 / 6.0, 2.0 / 3.0, 1.0 / 3.0}}};
// At most this many pieces along a triangle's side for the quadrature (64^2 pieces).
constexpr int kMaxPieces = 64;
// The residual's norm relative to b's: the volume error is the residual's sum. Measured
// iterations from 36 vertices (cone.toml) to 10^6 (dunes on initial points): 16 to 23.
constexpr double kTolerance = 1e-14;
constexpr int kMaxIterations = 200;

}  // namespace

void TinTerrain::project_heights(const HeightField& field) {
  // Vertex indices in the vertices' marks (finish_build resets them); the faces as index
  // triples with their areas: the mass matrix is applied face by face, never stored (stored as
  // an Eigen sparse matrix for Eigen's conjugate gradients, with its assembly, it took 0.5 GB
  // for 10^6 vertices; the few lines of preconditioned CG below need none of it).
  std::vector<VertexHandle> vertices;
  vertices.reserve(cdt_.number_of_vertices());
  for (auto v = cdt_.finite_vertices_begin(); v != cdt_.finite_vertices_end(); ++v) {
    v->info().mark = static_cast<std::uint32_t>(vertices.size());
    vertices.push_back(v);
  }
  const std::size_t n = vertices.size();
  std::vector<std::array<std::uint32_t, 3>> faces;
  std::vector<double> areas;
  const double detail = field.feature_m();
  std::vector<double> b(n, 0.0), diagonal(n, 0.0);
  for (auto f = cdt_.finite_faces_begin(); f != cdt_.finite_faces_end(); ++f) {
    const double area = face_area(f);
    std::array<std::uint32_t, 3> at{};
    std::array<Vec2, 3> p;
    for (int k = 0; k < 3; ++k) {
      at[k] = f->vertex(k)->info().mark;
      p[k] = xy(f->vertex(k));
      diagonal[at[k]] += area / 6.0;
    }
    // A triangle wider than the terrain's detail is cut into k x k similar pieces first (the rule
    // on each): greedy insertion leaves large triangles wherever the tolerance allows, and a
    // small cone inside one was missed by its three points (1e-6 m^3 on a 2 mm tolerance: 5 %).
    double longest = 0.0;
    for (int k = 0; k < 3; ++k) longest = std::max(longest, (p[k] - p[(k + 1) % 3]).norm());
    const int pieces = std::clamp(static_cast<int>(std::ceil(longest / detail)), 1, kMaxPieces);
    const double piece_area = area / (pieces * pieces);
    const auto integrate = [&](double s0, double t0, double ds, double dt) {
      // The piece with barycentric corners (s0, t0), (s0 + ds, t0), (s0, t0 + dt) in units of
      // 1 / pieces along the triangle's second and third vertices.
      for (const QuadraturePoint& q : kRule) {
        const double l1 = (s0 + q.b * ds) / pieces, l2 = (t0 + q.c * dt) / pieces, l0 = 1.0 - l1 - l2;
        const double z = piece_area * q.weight * field(l0 * p[0] + l1 * p[1] + l2 * p[2]);
        b[at[0]] += z * l0;
        b[at[1]] += z * l1;
        b[at[2]] += z * l2;
      }
    };
    for (int s = 0; s < pieces; ++s)
      for (int t = 0; s + t < pieces; ++t) {
        integrate(s, t, 1.0, 1.0);                                    // pointing like the triangle
        if (s + t + 1 < pieces) integrate(s + 1, t + 1, -1.0, -1.0);  // and the piece between
      }
    faces.push_back(at);
    areas.push_back(area);
  }
  // y = M x: each face adds area / 12 (x_a + x_b + x_c + x_i) to each of its vertices i.
  const auto apply_mass = [&](const std::vector<double>& x, std::vector<double>& y) {
    std::fill(y.begin(), y.end(), 0.0);
    for (std::size_t f = 0; f < faces.size(); ++f) {
      const auto& [i, j, k] = faces[f];
      const double sum = x[i] + x[j] + x[k], w = areas[f] / 12.0;
      y[i] += w * (sum + x[i]);
      y[j] += w * (sum + x[j]);
      y[k] += w * (sum + x[k]);
    }
  };
  // Conjugate gradients preconditioned by the diagonal, from the interpolated heights.
  std::vector<double> z(n), r(n), s(n), d(n), md(n);
  for (std::size_t i = 0; i < n; ++i) z[i] = vertices[i]->point().z();
  apply_mass(z, md);
  double b_norm2 = 0.0, rs = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    r[i] = b[i] - md[i];
    d[i] = s[i] = r[i] / diagonal[i];
    rs += r[i] * s[i];
    b_norm2 += b[i] * b[i];
  }
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    double r_norm2 = 0.0;
    for (double x : r) r_norm2 += x * x;
    if (r_norm2 <= kTolerance * kTolerance * b_norm2) break;
    apply_mass(d, md);
    double dmd = 0.0;
    for (std::size_t i = 0; i < n; ++i) dmd += d[i] * md[i];
    if (!(dmd > 0.0)) break;
    const double alpha = rs / dmd;
    double rs_next = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      z[i] += alpha * d[i];
      r[i] -= alpha * md[i];
      s[i] = r[i] / diagonal[i];
      rs_next += r[i] * s[i];
    }
    const double beta = rs_next / rs;
    rs = rs_next;
    for (std::size_t i = 0; i < n; ++i) d[i] = s[i] + beta * d[i];
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(z[i])) return;  // (cannot happen for a valid mesh) the interpolation stays
  }
  for (std::size_t i = 0; i < n; ++i)
    vertices[i]->set_point(Point(vertices[i]->point().x(), vertices[i]->point().y(), z[i]));
  changes_.mark_all();
}

}  // namespace sb::tin::detail
