// The TIN for a display that keeps its faces by tile: what changed (ChangeCells, marked by every
// edit), and the faces whose centroid lies in a box.
#include "tin/detail/tin_impl.hpp"

namespace sb::tin::detail {

SurfaceChanges TinTerrain::changes_since(std::uint64_t version) {
  mark_pending_stars();
  SurfaceChanges c;
  c.tracked = true;
  c.version = changes_.since(version, c.regions);
  return c;
}

void TinTerrain::surface_faces(const Aabb2& box, std::vector<Vec3>& out) const {
  if (cdt_.dimension() < 2 || !(box.lo.x() < box.hi.x() && box.lo.y() < box.hi.y())) return;
  // From the middle of the box's part of the domain (the box may reach to infinity).
  const Aabb2 inside = intersection(box, box_);
  if (!(inside.lo.x() <= inside.hi.x() && inside.lo.y() <= inside.hi.y())) return;
  std::vector<FaceHandle> queue;
  visit_faces_overlapping(box, 0.5 * (inside.lo + inside.hi), query_walk_, queue, [&](FaceHandle f) {
    const auto corner = [&](int i) {
      const Point& p = f->vertex(i)->point();
      return Vec3(p.x(), p.y(), p.z());
    };
    const Vec3 a = corner(0), b = corner(1), c = corner(2);
    if (centroid_in(box, a, b, c)) out.insert(out.end(), {a, b, c});
  });
}

}  // namespace sb::tin::detail
