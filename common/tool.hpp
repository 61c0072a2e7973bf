#pragma once
// Tools: a footprint polygon plus a bottom profile, posed in the world; and the pour tool.
// A ToolStamp is one application of a tool at one pose: the unit the back-ends consume.
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "common/geometry.hpp"

namespace sb {

enum class ToolShape { Disk, Box, Ellipse, Polygon, Pour };
enum class BottomProfile { Flat, SphereCap };
// Where a moving tool puts the sand it cuts: a rim band around the footprint (the paper's
// related work), the band ahead of it only, as a blade does (bulldozing), or a pile ahead of it
// and around its front that the tool carries from stamp to stamp, shedding part of it (carry).
enum class Displacement { Rim, Bulldoze, Carry };

// Names as in scene files and sessions ("disk", "sphere_cap"), one table each way.
std::string to_string(ToolShape s);
std::string to_string(BottomProfile p);
std::string to_string(Displacement d);
std::optional<ToolShape> tool_shape_from(std::string_view name);          // disk | box | ellipse | polygon | pour
std::optional<BottomProfile> bottom_profile_from(std::string_view name);  // flat | sphere_cap
std::optional<Displacement> displacement_from(std::string_view name);     // rim | bulldoze | carry

// Where the displaced volume goes. `Rim`: a band just outside the footprint, all around it,
// weighted towards the direction of motion (Sumner et al. 1999; Onoue & Nishita 2003).
// `Bulldoze`: a pile ahead of the moving tool at the angle of repose (common/front_pile.hpp),
// whose back part the next stamp cuts again, so the sand is carried with the tool as a growing
// front pile that spills forward and to the sides (the earthmoving models of Holz et al.
// 2009); a stamp that does not move, or whose pile would lie off the domain, uses the rim.
// `Carry`: the same pile, spread around the tool's front as well as ahead, and carried: each
// stamp picks up the pile the stamp before it left, less the part it sheds, and heaps it again
// with its own cut (common/front_pile.hpp).
struct RimRule {
  double width_m = 0.01;                   // band width outside the footprint boundary
  double forward_bias = 0.8;               // rim: 0 uniform; 1 nothing behind the tool
  Displacement model = Displacement::Rim;  // scenes default to Carry (tool.displacement)
  // Bulldoze: the slope the front pile stands at, the material's critical slope (scenes set it
  // from material.critical_angle_deg; this default is the material's default, 30 degrees).
  double tan_repose = 0.57735026918962573;
  // Carry: the fraction of its pile a tool leaves behind per its own length travelled, besides
  // what slides off its front (0: the berms are what erosion spills off the carried pile's
  // flanks and what the front deflects, as the particles show).
  double carry_shed_fraction = 0.0;
  // Carry: the Coulomb friction coefficient between the tool's faces and the sand. Sand against
  // a front face turned more than atan(face_friction) from the motion slides along it, round the
  // tool (front_deflection in common/front_pile.hpp). Infinite by default: the faces hold the
  // sand and nothing slides; the particles' own 0.5 meets no more of their bars
  // (results/particles_bars.md, model `deflect`).
  double face_friction = std::numeric_limits<double>::infinity();
};

struct ToolSpec {
  ToolShape shape = ToolShape::Disk;
  double radius_m = 0.02;        // disk radius; pour radius for the pour tool
  Vec2 half_size_m{0.02, 0.01};  // box half sizes; ellipse semi-axes
  std::vector<Vec2> polygon_m;   // polygon footprint, tool coordinates
  int sides = 32;                // n-gon sides for disk and ellipse
  BottomProfile profile = BottomProfile::Flat;
  double sphere_radius_m = 0.05;  // sphere-cap profile: sphere radius
  double depth_m = 0.01;          // bottom depth below the initial surface
  double pour_volume_m3 = 0.0;    // pour tool: volume added per stamp
  RimRule rim;

  // What is wrong with the fields the shape uses, named as scene keys ("tool.radius_m = 0
  // must be > 0"); nullopt when the tool is usable. Scenes check their keys with their own
  // ranges first; sessions, which carry whole tools, rely on this. O(polygon^2).
  std::optional<std::string> problem() const;

  // Corners of the footprint (1 for a pour): the least a stamp of this tool costs on every
  // back-end, which scenes and replayed sessions bound (kMaxStampCorners). O(1).
  std::size_t footprint_corners() const;

  // Footprint in tool coordinates (origin at the pose, x along the heading), CCW.
  // Empty for the pour tool, which has no footprint.
  std::vector<Vec2> footprint_local() const;
};

struct ToolPose {
  Vec2 xy{0.0, 0.0};
  double bottom_z = 0.0;     // lowest point of the tool bottom, m
  double heading_rad = 0.0;  // rotation of the footprint about z
};

struct ToolStamp {
  std::uint32_t generation = 0;  // stamp index in its schedule, from 0
  ToolPose pose;
  Vec2 motion_dir{0.0, 0.0};    // unit direction of motion; zero for a stationary stamp
  std::vector<Vec2> footprint;  // world coordinates, CCW; empty for a pour
  BottomProfile profile = BottomProfile::Flat;
  double sphere_radius_m = 0.0;
  RimRule rim;
  double half_width_m = 0.0;    // the footprint's half extent across the motion, from the pose
  double rear_m = 0.0;          // the footprint's extent along the motion from the pose: least
  double front_m = 0.0;         // and greatest (rear_m <= 0 <= front_m for a footprint about it)
  double pour_volume_m3 = 0.0;  // > 0 only for pours
  double pour_radius_m = 0.0;

  bool is_pour() const { return pour_volume_m3 > 0.0; }
  // Whether the cut sand goes to a front pile (common/front_pile.hpp) rather than the rim.
  bool bulldozes() const {
    return rim.model != Displacement::Rim && motion_dir.squaredNorm() > 0.0 && !footprint.empty();
  }
  // Whether the pile is carried from stamp to stamp (Displacement::Carry).
  bool carries() const { return bulldozes() && rim.model == Displacement::Carry; }
  // Height of the tool bottom at p (meaningful inside the footprint).
  double bottom_z(const Vec2& p) const;
  bool contains(const Vec2& p) const { return point_in_polygon(footprint, p); }
  // Weight of the rim's deposit at p: 0 inside the footprint and beyond the band, else the
  // taper falling linearly across the band times (1 + bias cos(phi)) / (1 + bias), phi the
  // angle between the motion and (p - pose). (A bulldozing stamp's pile: front_pile.hpp.)
  double rim_weight(const Vec2& p) const;
  // The same for a point outside the footprint whose distance to its boundary is known.
  double rim_weight_outside(const Vec2& p, double distance) const;
  // Footprint bounds grown by the rim band.
  Aabb2 influence_bounds() const;
};

// Places a tool at a pose: transforms the footprint into the world.
ToolStamp make_stamp(const ToolSpec& spec, const ToolPose& pose, const Vec2& motion_dir, std::uint32_t generation);

}  // namespace sb
