#pragma once
// The front pile of a bulldozing tool (tool.displacement = "bulldoze"): the sand a moving tool
// cuts is heaped ahead of it, in the corridor the footprint sweeps (ahead of the pose, within
// the footprint's half width across the motion), up to a surface at the angle of repose that
// falls away from the footprint,
//
//   z_pile(p) = H - tan(repose) * d(p),   d = distance from p to the footprint.
//
// The level H is the one at which the pile, filled onto the terrain as it is, holds exactly the
// cut volume:
//
//   sum over samples of area * max(0, H - tan(repose) * d - z) = V.
//
// The sand already ahead (the pile of the earlier stamps, carried with the tool because each
// stamp cuts its back part again) counts as terrain, so the pile grows with the cut and runs out
// ahead at the angle of repose within the stamp, where a band of fixed width ahead made it a
// column that erosion had to take down over many steps. Erosion spills
// the corridor's sides, which the moving tool leaves behind as side berms. Each back-end collects
// its nodes or vertices as samples, asks for the level and deposits in proportion to the depths;
// the stamp normalises the deposit, so the volume stays exact.
//
// Carrying (tool.displacement = "carry", the default): the particles carry the pile's flanks
// beside the blade with them, and a pile filled beside the tool, left where it lies, leaves those
// flanks behind as berms several times the particles'. So a carrying stamp first picks up the
// pile the stamp before it heaped: at every element of that pile outside its footprint, the sand
// standing above the height the element had before the deposit, all but what the tool sheds,
//
//   kept = ((1 - carry_shed_fraction) (1 - deflection))^(moved / length),
//
// length: the footprint's along the motion (what is left stays: in the corridor the footprint
// cuts it again, beside it it is berm). The default sheds nothing; the deflection is what the
// front's shape sends round the tool. Against a face whose outward normal is turned theta from
// the motion, pushed sand slides along the face when the push's tangential part beats friction,
// tan theta > mu (the tool's face_friction); the net sliding force per unit push is
// sin theta - mu cos theta. Averaged over the front, weighted by the width each face pushes,
//
//   deflection = sum over front edges of w_e max(0, sin theta_e - mu cos theta_e) / sum of w_e,
//
// w_e the edge's width across the motion. A blade square to the motion deflects nothing (its
// pile is carried whole, and the berms are what erosion spills off the flanks between stamps);
// a disk deflects 1 / (2 (1 + mu^2)) - mu (pi/2 - theta_0 - sin(2 theta_0) / 2) / 2, theta_0 = atan mu:
// 0.22 for the particles' mu = 0.5, its sand flowing round its curved front into its berms. The
// default mu is infinite (nothing deflects): see RimRule::face_friction.
// Then it heaps its cut and what it picked up as one pile, ahead of the pose and beside the tool
// back to its rear (not in the trench the tool's rear half sweeps), at the angle of repose
// falling away from the tool's front face (d: the distance to the footprint's edges that face
// the motion), so the flanks slope down backwards along the tool instead of standing as a wall
// that erosion pours into the trench. Beside the tool the pile starts beyond the band the
// trench's walls take as they slump (slump_band): put on it, the flanks went into the trench
// with the walls, and the trench filled into a V where the grains' stays open. The state
// between stamps is that pile's elements and their heights before the deposit, which each
// back-end keeps; picking up measures what it takes, so the volume stays exact.
#include <cstdint>
#include <utility>
#include <vector>

#include "common/geometry.hpp"

namespace sb {

struct ToolStamp;

struct PileSample {
  double distance_m;  // to the footprint
  double z_m;         // terrain height before the deposit
  double area_m2;     // the sample's share of the surface
};

// Whether p takes part in a bulldozing stamp's front pile: outside the footprint (the caller
// knows), ahead of the pose along the motion and within the footprint's half width across it;
// for a carrying stamp, anywhere ahead of the pose and, beside the footprint's width, back to its
// rear, but not within `slump_band_m` of its sides until past its front (slump_band). O(1).
bool in_front_pile(const ToolStamp& s, const Vec2& p, double slump_band_m = 0.0);

// Where a carrying stamp reads the bed: a step ahead of its front, where the pile it carries was
// just picked up, so the height there is the bed's. O(1).
Vec2 bed_probe(const ToolStamp& s, double step_m);

// The band beside a carrying tool that its trench's walls take: a wall cut `depth` deep slumps
// to the angle of repose about its mid-height (the sand above that line falls below it), so the
// bed within depth / (2 tan(repose)) of the cut's edge goes into the trench, and any pile put on
// it too. The pile beside the tool starts beyond it, where the grains put their berms. depth:
// the bed's height at bed_probe above the tool's bottom; 0 for a stamp that does not carry. O(1).
double slump_band(const ToolStamp& s, double bed_z_m);

// The distance d of the pile's surface from the tool: to the footprint (bulldozing), or to its
// edges that face the motion (carrying). The edges are chosen once, when it is made: O(footprint);
// then O(those edges) a point.
class PileDistance {
 public:
  explicit PileDistance(const ToolStamp& s);
  double operator()(const Vec2& p) const;

 private:
  std::vector<std::pair<Vec2, Vec2>> edges_;
};

// PileDistance for one point. O(footprint).
double pile_distance(const ToolStamp& s, const Vec2& p);

// The box holding every point of the pile region (in_front_pile) within `reach` of the
// footprint, grown by `margin`. O(footprint).
Aabb2 front_pile_box(const ToolStamp& s, double reach, double margin);

// Which stamp heaped a carried pile, for the next stamp to decide whether it carries it on.
struct CarriedPileOrigin {
  bool valid = false;
  std::uint32_t generation = 0;
  Vec2 xy{0.0, 0.0};
};

// The share of the carried sand the stamp's front sends round the tool per its length travelled
// (above): 0 for a stamp that does not carry. O(footprint).
double front_deflection(const ToolStamp& s);

// What a carrying stamp keeps of the pile `previous` heaped: ((1 - shed) (1 - deflection))^(moved /
// length) when it follows that stamp (the next generation) and moved at most its own length since, else 0 (a new
// stroke, or a tool that jumped, starts a new pile). O(1).
double carried_fraction(const ToolStamp& s, const CarriedPileOrigin& previous);

// The origin a carrying stamp leaves for the next one. O(1).
CarriedPileOrigin carried_origin(const ToolStamp& s);

// The distance from the footprint within which the pile holding `volume_m3` on flat ground
// ends, ahead of a blade `width_m` wide: the ramp's R with tan * width * R^2 / 2 = V; 0 when
// the width or the volume is not positive. The first region a back-end samples; it widens the
// region while the level asks for more (front_pile_reach_needed). O(1).
double front_pile_flat_reach(double volume_m3, double width_m, double tan_repose);

// The level H above. Exact for the samples given (sorted thresholds, no iteration):
// O(n log n). Samples with zero area are ignored; NaN when no sample has area.
double front_pile_level(const std::vector<PileSample>& samples, double volume_m3, double tan_repose);

// How far from the footprint a pile of level H can reach over terrain no lower than
// `lowest_z_m`: a region sampled to at least this distance holds every point the pile
// covers. O(1).
inline double front_pile_reach_needed(double level_m, double lowest_z_m, double tan_repose) {
  return (level_m - lowest_z_m) / tan_repose;
}

// The deposit's depth at a sample for level H (the weight the stamp normalises). O(1).
double front_pile_depth(const PileSample& s, double level_m, double tan_repose);

}  // namespace sb
