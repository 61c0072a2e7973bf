#pragma once
// StampSchedule: a stroke (polyline, optional bottom z per waypoint, spacing) turned once
// into the list of ToolStamps every back-end receives. O(stamps).
#include <functional>
#include <vector>

#include "common/tool.hpp"

namespace sb {

struct Stroke {
  std::vector<Vec2> path_m;  // waypoints, at least one
  std::vector<double> z_m;   // tool bottom z per waypoint; empty: surface - depth
  double spacing_m = 0.005;  // arc length between stamps
  int repeat = 1;            // trace the whole stroke this many times
};

struct StampSchedule {
  std::vector<ToolStamp> stamps;
  double length_m = 0.0;  // arc length of one trace
};

// Arc-length positions 0, s, 2s, ... along the polyline, plus its end when the last gap is
// not a whole spacing (so first and last waypoints are always stamped). A one-point path
// gives one position.
std::vector<double> stamp_arc_positions(double length_m, double spacing_m);
double polyline_length(const std::vector<Vec2>& path);

// `initial_height` gives the surface before the stroke; used for the bottom z when the
// stroke has no z per waypoint (bottom = surface - tool depth).
StampSchedule make_schedule(const ToolSpec& tool, const Stroke& stroke,
                            const std::function<double(const Vec2&)>& initial_height);

}  // namespace sb
