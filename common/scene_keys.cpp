#include "common/scene_keys.hpp"

#include <map>

namespace sb {

std::string scene_key_meaning(const std::string& key) {
  static const std::map<std::string, std::string> meanings = {
      {"domain.origin_m", "lower-left corner, m"},
      {"domain.size_m", "extent, m (the paper: diagonal 1 m, [0.7071, 0.7071])"},
      {"domain.crs", "coordinate reference system written into GIS exports (e.g. \"EPSG:32633\")"},
      {"terrain.kind", "initial surface"},
      {"terrain.height_m", "flat height; base height of dunes and heightmaps"},
      {"terrain.amplitude_m", "dunes: ridge amplitude"},
      {"terrain.wavelength_m", "dunes: ridge wavelength"},
      {"terrain.components", "dunes: number of ridges"},
      {"terrain.seed", "dunes: random seed"},
      {"terrain.path", "heightmap: 16-bit grey PNG stretched over the domain (relative to the scene file)"},
      {"terrain.vertical_scale_m", "heightmap: z = height_m + v/65535 * scale"},
      {"terrain.slope_deg", "plane: slope; height_m at the domain's centre; cone: flank slope"},
      {"terrain.volume_m3", "cone: its volume above height_m (apex at the domain's centre)"},
      {"terrain.azimuth_deg", "plane: downhill direction, counter-clockwise from +x"},
      {"material.critical_angle_deg", "angle of repose"},
      {"material.transfer_fraction", "fraction of a pair's excess moved per visit"},
      {"material.stiffness_n_per_m", "haptic force model: stiffness"},
      {"material.drag_n_s_per_m", "haptic force model: drag"},
      {"material.friction", "haptic force model: friction"},
      {"erosion.max_passes_per_step", "erosion passes over the active set after each stamp"},
      {"erosion.idle_passes", "an element leaves the active set after this many visits without transfer"},
      {"erosion.settle_tolerance_deg", "slopes up to critical + this count as stable"},
      {"erosion.relax_at_end", "settle after the stroke (recorded as steps with stamp -1)"},
      {"erosion.relax_max_passes", "at most this many settling passes"},
      {"erosion.cascade",
       "settling starts with a coarse-to-fine cascade (much faster on large disturbances, but a spreading pile "
       "ends flatter); false: the fine rule alone"},
      {"erosion.rule",
       "\"gradient\" (default): also along the downhill gradient, so a surface rests at the critical angle in "
       "every azimuth; \"edge\": slopes along neighbour directions only (the paper's)"},
      {"tool.shape", "footprint"},
      {"tool.radius_m", "disk radius; pour radius"},
      {"tool.size_m", "box: full sizes; ellipse: axes (along and across the motion)"},
      {"tool.polygon_m", "polygon footprint in tool coordinates (x along the motion)"},
      {"tool.sides", "disk and ellipse as n-gons"},
      {"tool.depth_m", "tool bottom below the initial surface (when stroke.z_m is absent)"},
      {"tool.profile", "bottom profile"},
      {"tool.sphere_radius_m", "sphere-cap profile: sphere radius"},
      {"tool.rim_width_m", "rim band outside the footprint where displaced sand goes (default: half the radius)"},
      {"tool.rim_forward_bias", "rim weighting towards the motion"},
      {"tool.displacement",
       "where a moving tool puts the cut sand: carried with it as a pile ahead of and beside it, bulldozed ahead of it "
       "at the angle of repose, or on a rim band around it"},
      {"tool.carry_shed_fraction",
       "carry: the fraction of its pile the tool leaves behind per its own length travelled, besides what its front "
       "deflects"},
      {"tool.face_friction",
       "carry: friction coefficient between the tool's faces and the sand; a front face turned more than its "
       "arctangent from the motion sends sand round the tool (inf: nothing slides)"},
      {"tool.volume_m3", "pour: volume poured per stamp"},
      {"stroke.path_m", "polyline, m"},
      {"stroke.z_m", "tool bottom z at each waypoint (default: surface - depth)"},
      {"stroke.spacing_m", "stamps at this arc-length spacing, first and last included"},
      {"stroke.repeat", "trace the stroke this many times"},
      {"tin.alpha_flat_deg", "simplification threshold"},
      {"tin.tolerance_m", "max height error of the initial TIN (greedy insertion, then the terrain's L2 projection)"},
      {"tin.conserve_volume", "give back the volume change of every retriangulation; false: the paper's model"},
      {"tin.contour_subdivision_m", "subdivide the tool's outer contour; 0: polygon only"},
      {"tin.snap_m", "points closer than this to a vertex reuse it"},
      {"tin.initial_points", "start from about this many vertices; 0: as few as the terrain needs"},
      {"tin.initial_jitter", "lattice jitter as a fraction of a cell"},
      {"tin.contour_gap_m", "outer-to-inner contour distance; 0: 5% of the tool size"},
      {"tin.refine_m",
       "erosion splits edges longer than this that sand flows across; 0: 4 tin.tolerance_m / tan(critical), "
       "at least half the tool radius, at most 5% of the domain"},
      {"tin.curvature_tolerance_m",
       "erosion also splits edges sand flows across where length x facet-gradient jump / 4 exceeds this; 0: off"},
      {"tin.curvature_when",
       "when curvature refinement runs: always, or only while the sand settles (no tool that step)"},
      {"tin.refine_min_m",
       "the shortest edge that split may make (at least a quarter of tin.refine_m); 0: half of tin.refine_m"},
      {"tin.planar_tolerance_m", "height tolerance of the coarsening; 0: tin.tolerance_m / 4"},
      {"tin.coarsen", "at rest, simplification also removes vertices near the plane of their neighbours"},
      {"grid.cell_m", "node spacing"},
      {"grid.storage", "height storage type"},
      {"grid.neighbours", "erosion stencil (4 or 8)"},
      {"grid.threads", "threads a large dense erosion pass may use (1 or 2); the heights do not depend on it"},
      {"output.raster_m", "spacing of the comparison raster (default: min(0.0025, extent/100))"},
      {"output.energy", "record the potential energy after each step"},
      {"reference.kind", "analytic reference for the accuracy metrics"},
      {"haptics.blend_ms", "interactive servo: a new height patch's force jump fades out over this time"},
      {"haptics.max_force_rate_n_per_s",
       "interactive servo: force change limit per second, a fault guard; 0: unlimited"},
      {"haptics.passivity_control", "passivity controller: damping whenever the observer would go positive"},
      {"haptics.passivity_max_force_n", "passivity controller: at most this damping force"},
      {"haptics.coupling", "virtual coupling: the sand pushes a simulated tool tied to the device"},
      {"haptics.coupling_stiffness_n_per_m", "virtual coupling: spring stiffness"},
      {"haptics.coupling_damping_n_s_per_m", "virtual coupling: damping"},
      {"haptics.tool_mass_kg", "virtual coupling: mass of the simulated tool"},
  };
  const auto it = meanings.find(key);
  return it == meanings.end() ? std::string() : it->second;
}

}  // namespace sb
