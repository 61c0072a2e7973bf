#include "common/front_pile.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/tool.hpp"

namespace sb {

bool in_front_pile(const ToolStamp& s, const Vec2& p) {
  const Vec2 offset = p - s.pose.xy;
  const double across = std::abs(offset.x() * s.motion_dir.y() - offset.y() * s.motion_dir.x());
  return offset.dot(s.motion_dir) > 0.0 && across <= s.half_width_m;
}

double front_pile_flat_reach(double volume_m3, double width_m, double tan_repose) {
  if (!(volume_m3 > 0.0) || !(tan_repose > 0.0) || !(width_m > 0.0)) return 0.0;
  return std::sqrt(2.0 * volume_m3 / (tan_repose * width_m));
}

double front_pile_level(const std::vector<PileSample>& samples, double volume_m3, double tan_repose) {
  // f(H) = sum A_i max(0, H - a_i), a_i = tan d_i + z_i, is piecewise linear and increasing:
  // between consecutive thresholds it is A H - (sum A a) over the samples below.
  std::vector<std::pair<double, double>> threshold;  // (a_i, A_i)
  threshold.reserve(samples.size());
  for (const PileSample& s : samples)
    if (s.area_m2 > 0.0) threshold.emplace_back(tan_repose * s.distance_m + s.z_m, s.area_m2);
  if (threshold.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(threshold.begin(), threshold.end());
  const double volume = std::max(volume_m3, 0.0);
  double area = 0.0, moment = 0.0;
  for (std::size_t k = 0; k < threshold.size(); ++k) {
    area += threshold[k].second;
    moment += threshold[k].second * threshold[k].first;
    const bool last = k + 1 == threshold.size();
    // The level lies below the next threshold when the samples so far hold V there.
    if (last || area * threshold[k + 1].first - moment >= volume) return (volume + moment) / area;
  }
  return std::numeric_limits<double>::quiet_NaN();  // not reached
}

double front_pile_depth(const PileSample& s, double level_m, double tan_repose) {
  return std::max(0.0, level_m - tan_repose * s.distance_m - s.z_m);
}

}  // namespace sb
