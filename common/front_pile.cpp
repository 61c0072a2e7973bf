#include "common/front_pile.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/tool.hpp"

namespace sb {

namespace {

// The cosine of the angle between a footprint edge's outward normal and the motion (the footprint
// is counter-clockwise): positive for an edge that faces the motion; NaN for an edge of no length.
double facing(const Vec2& edge, const Vec2& dir) { return (edge.y() * dir.x() - edge.x() * dir.y()) / edge.norm(); }

}  // namespace

bool in_front_pile(const ToolStamp& s, const Vec2& p, double slump_band_m) {
  const Vec2 offset = p - s.pose.xy;
  const double along = offset.dot(s.motion_dir);
  const double across = std::abs(offset.x() * s.motion_dir.y() - offset.y() * s.motion_dir.x());
  // Carrying: beside the tool back to its rear, but not in the trench its rear half sweeps, nor
  // on the band its walls take beside it.
  if (s.carries()) {
    const bool beside_band = across > s.half_width_m && across <= s.half_width_m + slump_band_m;
    return (along > 0.0 || (along > s.rear_m && across > s.half_width_m)) && !(beside_band && along <= s.front_m);
  }
  return along > 0.0 && across <= s.half_width_m;
}

Vec2 bed_probe(const ToolStamp& s, double step_m) { return s.pose.xy + (s.front_m + step_m) * s.motion_dir; }

double slump_band(const ToolStamp& s, double bed_z_m) {
  const double depth = bed_z_m - s.pose.bottom_z, tan = s.rim.tan_repose;
  if (!s.carries() || !(depth > 0.0) || !(tan > 0.0)) return 0.0;
  return depth / (2.0 * tan);
}

PileDistance::PileDistance(const ToolStamp& s) {
  const std::size_t n = s.footprint.size();
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
    if (!s.carries() || facing(s.footprint[i] - s.footprint[j], s.motion_dir) > 1e-9)
      edges_.emplace_back(s.footprint[j], s.footprint[i]);
  }
}

double PileDistance::operator()(const Vec2& p) const {
  // One square root for the nearest edge, as distance_to_boundary: the same value bit for bit.
  double best = HUGE_VAL;
  for (const auto& [a, b] : edges_) best = std::min(best, squared_distance_to_segment(p, a, b));
  return std::sqrt(best);
}

double pile_distance(const ToolStamp& s, const Vec2& p) { return PileDistance(s)(p); }

Aabb2 front_pile_box(const ToolStamp& s, double reach, double margin) {
  // Bulldozing, the corridor: the footprint's width across the motion, from the pose to its
  // front plus the reach; carrying, the width plus the reach each side, from the tool's rear.
  const Vec2 dir = s.motion_dir, across(-dir.y(), dir.x());
  const bool carry = s.carries();
  const Vec2 side = (s.half_width_m + (carry ? reach : 0.0)) * across;
  const Vec2 back = (carry ? s.rear_m : 0.0) * dir, ahead = (std::max(0.0, s.front_m) + reach) * dir;
  const Vec2 a = s.pose.xy + back + side, b = s.pose.xy + back - side, c = s.pose.xy + ahead + side,
             d = s.pose.xy + ahead - side;
  return Aabb2{a.cwiseMin(b).cwiseMin(c).cwiseMin(d), a.cwiseMax(b).cwiseMax(c).cwiseMax(d)}.expanded(margin);
}

double carried_fraction(const ToolStamp& s, const CarriedPileOrigin& previous) {
  if (!s.carries() || !previous.valid || s.generation != previous.generation + 1) return 0.0;
  const double length = s.front_m - s.rear_m, moved = (s.pose.xy - previous.xy).norm();
  if (!(length > 0.0) || !(moved <= length)) return 0.0;
  return std::pow((1.0 - s.rim.carry_shed_fraction) * (1.0 - front_deflection(s)), moved / length);
}

double front_deflection(const ToolStamp& s) {
  if (!s.carries()) return 0.0;
  const double mu = s.rim.face_friction;
  double width = 0.0, sliding = 0.0;
  const std::size_t n = s.footprint.size();
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
    const Vec2 edge = s.footprint[i] - s.footprint[j];
    const double cos_theta = facing(edge, s.motion_dir);
    if (!(cos_theta > 0.0)) continue;  // not a front face (or no edge)
    const double length = edge.norm(), sin_theta = std::abs(edge.dot(s.motion_dir)) / length;
    const double w = length * cos_theta;  // the edge's width across the motion
    width += w;
    sliding += w * std::max(0.0, sin_theta - mu * cos_theta);
  }
  return width > 0.0 ? sliding / width : 0.0;
}

CarriedPileOrigin carried_origin(const ToolStamp& s) {
  return {.valid = s.carries(), .generation = s.generation, .xy = s.pose.xy};
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
