#include "common/schedule.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

namespace sb {

double polyline_length(const std::vector<Vec2>& path) {
  double len = 0.0;
  for (std::size_t i = 1; i < path.size(); ++i) len += (path[i] - path[i - 1]).norm();
  return len;
}

std::size_t stamp_arc_count(double length_m, double spacing_m) {
  if (length_m <= 0.0) return 1;
  // Whole spacings strictly inside, then the end unless it coincides with the last one.
  const auto whole = static_cast<std::size_t>(std::floor(length_m / spacing_m));
  const double tolerance = 1e-9 * spacing_m;
  return length_m - static_cast<double>(whole) * spacing_m > tolerance ? whole + 2 : whole + 1;
}

double stamp_arc_position(double length_m, double spacing_m, std::size_t count, std::size_t k) {
  if (length_m <= 0.0) return 0.0;
  return k + 1 == count ? length_m : static_cast<double>(k) * spacing_m;
}

std::vector<double> stamp_arc_positions(double length_m, double spacing_m) {
  const std::size_t n = stamp_arc_count(length_m, spacing_m);
  std::vector<double> s(n);
  for (std::size_t k = 0; k < n; ++k) s[k] = stamp_arc_position(length_m, spacing_m, n, k);
  return s;
}

namespace {

// What generating one stamp of a stroke needs; shared by every copy of the schedule.
struct StrokeStamps {
  ToolSpec tool;
  Stroke stroke;
  std::function<double(const Vec2&)> initial_height;
  std::vector<double> segment_end;  // arc length at the end of segment i (summed in path order)
  double length_m = 0.0;
  std::size_t per_trace = 1;

  ToolStamp operator()(std::size_t index) const {
    const auto& path = stroke.path_m;
    const double s = stamp_arc_position(length_m, stroke.spacing_m, per_trace, index % per_trace);
    // The segment holding arc position s: the first whose end reaches s (zero-length
    // segments are skipped), the last one at most.
    std::size_t seg = 0;
    if (path.size() > 2)
      seg = static_cast<std::size_t>(std::lower_bound(segment_end.begin(), segment_end.end() - 1, s) -
                                     segment_end.begin());
    Vec2 p = path[0];
    Vec2 dir = Vec2::Zero();
    double z_way = 0.0;
    if (path.size() >= 2) {
      const double seg_start = seg == 0 ? 0.0 : segment_end[seg - 1];
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
    return make_stamp(tool, pose, dir, static_cast<std::uint32_t>(index));
  }
};

}  // namespace

StampSchedule make_schedule(const ToolSpec& tool, const Stroke& stroke,
                            const std::function<double(const Vec2&)>& initial_height) {
  auto gen = std::make_shared<StrokeStamps>();
  gen->tool = tool;
  gen->stroke = stroke;
  gen->initial_height = initial_height;
  const auto& path = stroke.path_m;
  double end = 0.0;
  for (std::size_t i = 1; i < path.size(); ++i) gen->segment_end.push_back(end += (path[i] - path[i - 1]).norm());
  gen->length_m = polyline_length(path);
  gen->per_trace = stamp_arc_count(gen->length_m, stroke.spacing_m);
  StampSchedule schedule;
  schedule.length_m = gen->length_m;
  const std::size_t total = gen->per_trace * static_cast<std::size_t>(std::max(stroke.repeat, 0));
  schedule.stamps = StampSequence(total, [gen](std::size_t i) { return (*gen)(i); });
  return schedule;
}

}  // namespace sb
