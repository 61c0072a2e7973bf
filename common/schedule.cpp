#include "common/schedule.hpp"

#include <algorithm>
#include <cmath>

namespace sb {

double polyline_length(const std::vector<Vec2>& path) {
  double len = 0.0;
  for (std::size_t i = 1; i < path.size(); ++i) len += (path[i] - path[i - 1]).norm();
  return len;
}

std::vector<double> stamp_arc_positions(double length_m, double spacing_m) {
  std::vector<double> s{0.0};
  if (length_m <= 0.0) return s;
  // Whole spacings strictly inside, then the end unless it coincides with the last one.
  const auto whole = static_cast<long>(std::floor(length_m / spacing_m));
  for (long k = 1; k <= whole; ++k) s.push_back(static_cast<double>(k) * spacing_m);
  const double tolerance = 1e-9 * spacing_m;
  if (length_m - s.back() > tolerance) {
    s.push_back(length_m);
  } else {
    s.back() = length_m;
  }
  return s;
}

StampSchedule make_schedule(const ToolSpec& tool, const Stroke& stroke,
                            const std::function<double(const Vec2&)>& initial_height) {
  StampSchedule schedule;
  const auto& path = stroke.path_m;
  schedule.length_m = polyline_length(path);
  const std::vector<double> arc = stamp_arc_positions(schedule.length_m, stroke.spacing_m);

  std::uint32_t generation = 0;
  for (int r = 0; r < stroke.repeat; ++r) {
    std::size_t seg = 0;
    double seg_start = 0.0;
    for (double s : arc) {
      // Advance to the segment holding arc position s (zero-length segments are skipped).
      while (seg + 2 < path.size() && seg_start + (path[seg + 1] - path[seg]).norm() < s) {
        seg_start += (path[seg + 1] - path[seg]).norm();
        ++seg;
      }
      Vec2 p = path[0];
      Vec2 dir = Vec2::Zero();
      double z_way = 0.0;
      if (path.size() >= 2) {
        const Vec2 a = path[seg], b = path[seg + 1];
        const double seg_len = (b - a).norm();
        const double t = seg_len > 0.0 ? std::clamp((s - seg_start) / seg_len, 0.0, 1.0) : 0.0;
        p = a + t * (b - a);
        if (seg_len > 0.0) dir = (b - a) / seg_len;
        if (!stroke.z_m.empty()) z_way = stroke.z_m[seg] + t * (stroke.z_m[seg + 1] - stroke.z_m[seg]);
      } else if (!stroke.z_m.empty()) {
        z_way = stroke.z_m[0];
      }
      ToolPose pose;
      pose.xy = p;
      pose.heading_rad = dir.squaredNorm() > 0.0 ? std::atan2(dir.y(), dir.x()) : 0.0;
      pose.bottom_z = stroke.z_m.empty() ? initial_height(p) - tool.depth_m : z_way;
      schedule.stamps.push_back(make_stamp(tool, pose, dir, generation++));
    }
  }
  return schedule;
}

}  // namespace sb
