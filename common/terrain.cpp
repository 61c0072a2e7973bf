#include "common/terrain.hpp"

namespace sb {

void Terrain::surface_faces(const Aabb2& box, std::vector<Vec3>& out) const {
  const SurfaceMesh m = mesh();
  for (const auto& t : m.triangles) {
    const Vec3 &a = m.vertices[t[0]], &b = m.vertices[t[1]], &c = m.vertices[t[2]];
    if (centroid_in(box, a, b, c)) out.insert(out.end(), {a, b, c});
  }
}

}  // namespace sb
