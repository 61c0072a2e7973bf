#include "harness/render/mesh.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <stdexcept>
#include <utility>

namespace sb {

namespace {
std::uint64_t edge_key(std::uint32_t a, std::uint32_t b) {
  return (static_cast<std::uint64_t>(std::min(a, b)) << 32) | std::max(a, b);
}

void push3(std::vector<float>& v, const Vec3& p) {
  v.push_back(static_cast<float>(p.x()));
  v.push_back(static_cast<float>(p.y()));
  v.push_back(static_cast<float>(p.z()));
}
}  // namespace

RenderMesh prepare_render_mesh(const SurfaceMesh& mesh, const Vec3& centre, bool with_edges) {
  RenderMesh out;
  out.centre = centre;
  const std::size_t nv = mesh.vertices.size();
  out.positions.reserve(3 * nv);
  for (const Vec3& p : mesh.vertices) push3(out.positions, p - centre);

  std::vector<Vec3> normal(nv, Vec3::Zero());
  out.triangles.reserve(3 * mesh.triangles.size());
  // Directed edges of the up-facing triangles; a boundary edge has no twin.
  std::vector<std::pair<std::uint64_t, std::uint64_t>> directed;  // (undirected key, a << 32 | b)
  directed.reserve(3 * mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    if (t[0] >= nv || t[1] >= nv || t[2] >= nv)
      throw std::invalid_argument("prepare_render_mesh: triangle index out of range");
    std::array<std::uint32_t, 3> v = t;
    Vec3 n = (mesh.vertices[v[1]] - mesh.vertices[v[0]]).cross(mesh.vertices[v[2]] - mesh.vertices[v[0]]);
    if (n.z() < 0.0) {
      std::swap(v[1], v[2]);
      n = -n;
    }
    for (int k = 0; k < 3; ++k) {
      normal[v[k]] += n;  // |n| is twice the area: area-weighted
      out.triangles.push_back(v[k]);
      const std::uint32_t a = v[k], b = v[(k + 1) % 3];
      directed.emplace_back(edge_key(a, b), (static_cast<std::uint64_t>(a) << 32) | b);
    }
  }
  out.normals.reserve(3 * nv);
  for (Vec3& n : normal) {
    const double len = n.norm();
    push3(out.normals, len > 0.0 ? Vec3(n / len) : Vec3(0.0, 0.0, 1.0));
  }

  std::sort(directed.begin(), directed.end());
  for (std::size_t i = 0; i < directed.size();) {
    std::size_t j = i + 1;
    while (j < directed.size() && directed[j].first == directed[i].first) ++j;
    const auto a = static_cast<std::uint32_t>(directed[i].second >> 32);
    const auto b = static_cast<std::uint32_t>(directed[i].second & 0xffffffffu);
    if (with_edges) {
      out.edges.push_back(a);
      out.edges.push_back(b);
    }
    if (j - i == 1) {
      // Skirt: a wall under the boundary edge a -> b (interior on its left), down to z = 0.
      const Vec3 pa = mesh.vertices[a] - centre, pb = mesh.vertices[b] - centre;
      const Vec3 qa(pa.x(), pa.y(), -centre.z()), qb(pb.x(), pb.y(), -centre.z());
      const Vec3 d = pb - pa;
      Vec3 outward(d.y(), -d.x(), 0.0);
      if (outward.norm() > 0.0) outward.normalize();
      for (const Vec3& p : {pa, qa, qb, pa, qb, pb}) {
        push3(out.skirt_positions, p);
        push3(out.skirt_normals, outward);
      }
    }
    i = j;
  }

  out.constrained.reserve(2 * mesh.constrained_edges.size());
  for (const auto& e : mesh.constrained_edges) {
    if (e[0] >= nv || e[1] >= nv) throw std::invalid_argument("prepare_render_mesh: edge index out of range");
    out.constrained.push_back(e[0]);
    out.constrained.push_back(e[1]);
  }
  return out;
}

SurfaceMesh mesh_from_raster(const Raster& r) {
  SurfaceMesh m;
  m.vertices.reserve(r.nx * r.ny);
  for (std::size_t iy = 0; iy < r.ny; ++iy)
    for (std::size_t ix = 0; ix < r.nx; ++ix) {
      const Vec2 p = r.point(ix, iy);
      m.vertices.emplace_back(p.x(), p.y(), r.at(ix, iy));
    }
  if (r.nx < 2 || r.ny < 2) return m;
  m.triangles.reserve(2 * (r.nx - 1) * (r.ny - 1));
  for (std::size_t iy = 0; iy + 1 < r.ny; ++iy)
    for (std::size_t ix = 0; ix + 1 < r.nx; ++ix) {
      const auto v = static_cast<std::uint32_t>(iy * r.nx + ix);
      const auto w = static_cast<std::uint32_t>(r.nx);
      m.triangles.push_back({v, v + 1, v + w + 1});
      m.triangles.push_back({v, v + w + 1, v + w});
    }
  return m;
}

}  // namespace sb
