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
  // The faces overlapping the box are connected (the box is convex): walk them from the face at
  // its centre, taking those whose centroid lies in it. O(faces overlapping the box).
  const Aabb2 inside = intersection(box, box_);
  if (!(inside.lo.x() <= inside.hi.x() && inside.lo.y() <= inside.hi.y())) return;
  const std::uint32_t visited = next_face_epoch();
  const Location loc = locate(0.5 * (inside.lo + inside.hi), query_walk_);
  FaceHandle start = loc.face;  // (a point on the hull may locate in an infinite face)
  if (cdt_.is_infinite(start)) start = start->neighbor(start->index(cdt_.infinite_vertex()));
  std::vector<FaceHandle> queue{start};
  start->info() = visited;
  const auto corner = [](FaceHandle f, int i) {
    const Point& p = f->vertex(i)->point();
    return Vec3(p.x(), p.y(), p.z());
  };
  for (std::size_t k = 0; k < queue.size(); ++k) {
    const FaceHandle f = queue[k];
    const Vec3 a = corner(f, 0), b = corner(f, 1), c = corner(f, 2);
    if (centroid_in(box, a, b, c)) out.insert(out.end(), {a, b, c});
    for (int i = 0; i < 3; ++i) {
      const FaceHandle n = f->neighbor(i);
      if (cdt_.is_infinite(n) || n->info() == visited || !face_overlaps(n, box)) continue;
      n->info() = visited;
      queue.push_back(n);
    }
  }
}

}  // namespace sb::tin::detail
