#include "common/scene_sections.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>

#include "common/raster.hpp"

namespace sb::scene_detail {

namespace {

// The key that sets the tool's size.
std::string tool_size_key(const ToolSpec& t) {
  return t.shape == ToolShape::Polygon                              ? "tool.polygon_m"
         : t.shape == ToolShape::Disk || t.shape == ToolShape::Pour ? "tool.radius_m"
                                                                    : "tool.size_m";
}

// How far from its pose the tool's footprint reaches (a pour: its radius), plus its rim band
// when `rim`.
double tool_reach(const ToolSpec& t, bool rim) {
  if (t.shape == ToolShape::Pour) return t.radius_m;
  double r = 0.0;
  for (const Vec2& p : t.footprint_local()) r = std::max(r, p.norm());
  return rim ? r + t.rim.width_m : r;
}

// Refuses a tool that cannot fit in the domain at the points where the scene's reference
// measures its work: the pour point (pile), the stamp with its rim band (crater), the middle
// half of the stroke (trench, ridge).
void check_reference_fit(const Scene& s) {
  const auto& path = s.stroke.path_m;
  std::vector<Vec2> at;
  bool rim = false;
  if (s.reference == ReferenceKind::Pile) at = {path.front()};
  if (s.reference == ReferenceKind::Crater) {
    at = {path.front()};
    rim = true;
  }
  if (s.reference == ReferenceKind::Trench || s.reference == ReferenceKind::Ridge)
    at = {path.front() + 0.25 * (path.back() - path.front()), path.front() + 0.75 * (path.back() - path.front())};
  const double reach = tool_reach(s.tool, rim);
  const Aabb2 box = s.domain.box();
  for (const Vec2& c : at) {
    if (c.x() - reach >= box.lo.x() && c.x() + reach <= box.hi.x() && c.y() - reach >= box.lo.y() &&
        c.y() + reach <= box.hi.y())
      continue;
    std::ostringstream msg;
    msg << "gives a tool reaching " << reach << " m from its pose" << (rim ? " (with tool.rim_width_m)" : "")
        << ", which does not fit in the domain at (" << c.x() << ", " << c.y() << "), where reference.kind = \""
        << to_string(s.reference) << "\" measures it; use a smaller tool or move stroke.path_m";
    Fields::fail(tool_size_key(s.tool), msg.str());
  }
}

// The larger side of the domain: ranges of lengths scale with it.
double domain_extent(const Scene& s) { return std::max(s.domain.size_m.x(), s.domain.size_m.y()); }

// [domain]
void read_domain(Fields& f, Scene& s) {
  s.domain.origin_m = f.vec2("domain.origin_m", {0.0, 0.0}, open(-1e9, 1e9));
  s.domain.size_m = f.vec2("domain.size_m", Vec2(0.0, 0.0), positive(1e6), /*required=*/true);
  s.crs = f.string("domain.crs", /*required=*/false);
}

// [terrain]
void read_terrain(Fields& f, Scene& s, const std::filesystem::path& base_dir) {
  const std::string kind = f.choice("terrain.kind", "flat", {"flat", "dunes", "heightmap", "plane", "cone"});
  s.terrain.kind = kind == "flat"        ? TerrainKind::Flat
                   : kind == "dunes"     ? TerrainKind::Dunes
                   : kind == "heightmap" ? TerrainKind::Heightmap
                   : kind == "plane"     ? TerrainKind::Plane
                                         : TerrainKind::Cone;
  s.terrain.height_m = f.number("terrain.height_m", 0.1, open(-1e6, 1e6));
  if (s.terrain.kind == TerrainKind::Dunes) {
    s.terrain.dune_amplitude_m = f.number("terrain.amplitude_m", 0.02, closed(0.0, 1e3));
    s.terrain.dune_wavelength_m = f.number("terrain.wavelength_m", 0.2, positive(1e6));
    s.terrain.dune_components = static_cast<int>(f.integer("terrain.components", 4, 1, 64));
    s.terrain.seed = f.integer("terrain.seed", 1, 0, std::numeric_limits<long long>::max());
  }
  if (s.terrain.kind == TerrainKind::Plane) {
    s.terrain.slope_deg = f.number("terrain.slope_deg", 0.0, closed(0.0, 89.0));
    s.terrain.azimuth_deg = f.number("terrain.azimuth_deg", 0.0, closed(-360.0, 360.0));
  }
  if (s.terrain.kind == TerrainKind::Cone) {
    s.terrain.slope_deg = f.number("terrain.slope_deg", 35.0, closed(1.0, 89.0));
    // At most the volume of a cone whose base is the domain's inscribed circle.
    const double r = 0.5 * std::min(s.domain.size_m.x(), s.domain.size_m.y());
    const double most = std::numbers::pi * r * r * r * std::tan(deg_to_rad(s.terrain.slope_deg)) / 3.0;
    s.terrain.cone_volume_m3 = f.number("terrain.volume_m3", 2e-5, positive(most));
  }
  if (s.terrain.kind == TerrainKind::Heightmap) {
    std::filesystem::path p = f.string("terrain.path", /*required=*/true);
    s.terrain.heightmap_path = p.is_absolute() ? p : base_dir / p;
    s.terrain.vertical_scale_m = f.number("terrain.vertical_scale_m", 0.1, positive(1e6));
  }
}

// [material]
void read_material(Fields& f, Scene& s) {
  s.material.critical_angle_deg = f.number("material.critical_angle_deg", 30.0, open(0.0, 90.0));
  s.material.transfer_fraction = f.number("material.transfer_fraction", 0.5, {0.0, 2.0, true, false});
  s.material.stiffness_n_per_m = f.number("material.stiffness_n_per_m", 800.0, closed(0.0, 1e6));
  s.material.drag_n_s_per_m = f.number("material.drag_n_s_per_m", 5.0, closed(0.0, 1e4));
  s.material.friction = f.number("material.friction", 0.4, closed(0.0, 10.0));
}

// [erosion]
void read_erosion(Fields& f, Scene& s) {
  s.erosion.max_passes_per_step = static_cast<int>(f.integer("erosion.max_passes_per_step", 4, 0, 100000));
  s.erosion.idle_passes = static_cast<int>(f.integer("erosion.idle_passes", 2, 1, 1000));
  s.erosion.settle_tolerance_deg = f.number("erosion.settle_tolerance_deg", 0.1, closed(0.0, 10.0));
  s.erosion.relax_at_end = f.boolean("erosion.relax_at_end", true);
  s.erosion.relax_max_passes = static_cast<int>(f.integer("erosion.relax_max_passes", 20000, 0, 100000000));
  s.erosion.cascade = f.boolean("erosion.cascade", true);
  s.erosion.rule = f.choice("erosion.rule", "gradient", {"gradient", "edge"}) == "gradient" ? ErosionRuleKind::Gradient
                                                                                            : ErosionRuleKind::Edge;
}

// [tool]
void read_tool(Fields& f, Scene& s) {
  const double extent = domain_extent(s);
  const std::string shape = f.choice("tool.shape", "disk", {"disk", "box", "ellipse", "polygon", "pour"});
  ToolSpec& t = s.tool;
  t.shape = *tool_shape_from(shape);
  const Range tool_size = positive(extent * 10.0);
  if (t.shape == ToolShape::Disk || t.shape == ToolShape::Pour) t.radius_m = f.number("tool.radius_m", 0.02, tool_size);
  if (t.shape == ToolShape::Box || t.shape == ToolShape::Ellipse) {
    const Vec2 size = f.vec2("tool.size_m", {0.04, 0.02}, tool_size, /*required=*/true);
    t.half_size_m = size / 2.0;
  }
  if (t.shape == ToolShape::Polygon) {
    t.polygon_m = f.points("tool.polygon_m", 3, /*required=*/true);
    if (!is_simple_polygon(t.polygon_m))
      Fields::fail("tool.polygon_m", "must be a simple polygon (no self-intersections, non-zero area)");
  }
  if (t.shape == ToolShape::Disk || t.shape == ToolShape::Ellipse)
    t.sides = static_cast<int>(f.integer("tool.sides", 32, 3, 4096));
  if (t.shape == ToolShape::Pour) {
    t.pour_volume_m3 = f.number("tool.volume_m3", 0.0, positive(1e9), /*required=*/true);
  } else {
    t.depth_m = f.number("tool.depth_m", 0.01, open(-1e6, 1e6));
    const std::string profile = f.choice("tool.profile", "flat", {"flat", "sphere_cap"});
    t.profile = *bottom_profile_from(profile);
    if (t.profile == BottomProfile::SphereCap) t.sphere_radius_m = f.number("tool.sphere_radius_m", 0.05, tool_size);
    t.rim.width_m = f.number("tool.rim_width_m",
                             0.5 * (t.shape == ToolShape::Disk ? t.radius_m : t.half_size_m.minCoeff()), tool_size);
    t.rim.forward_bias = f.number("tool.rim_forward_bias", 0.8, closed(0.0, 1.0));
    t.rim.model = *displacement_from(f.choice("tool.displacement", "carry", {"rim", "bulldoze", "carry"}));
    t.rim.carry_shed_fraction = f.number("tool.carry_shed_fraction", 0.0, closed(0.0, 1.0));
    t.rim.face_friction = f.number("tool.face_friction", kInf, closed(0.0, kInf));
    t.rim.tan_repose = s.material.tan_critical();  // the front pile stands at the material's angle
  }

  // A footprint whose edges vanish next to the domain cannot be resolved by the TIN (which
  // merges points closer than 1e-12 x extent): refuse it here, for every back-end alike.
  if (t.shape != ToolShape::Pour) {
    const std::vector<Vec2> fp = t.footprint_local();
    double shortest = kInf;
    for (std::size_t i = 0; i < fp.size(); ++i) shortest = std::min(shortest, (fp[(i + 1) % fp.size()] - fp[i]).norm());
    const double least = 1e-9 * extent;
    if (!(shortest >= least)) {
      const std::string key = tool_size_key(t);
      std::ostringstream msg;
      msg << "gives footprint edges of " << shortest << " m, shorter than 1e-9 x the domain extent (" << least
          << " m); use a larger tool"
          << (t.shape == ToolShape::Polygon || t.shape == ToolShape::Box ? "" : " or fewer tool.sides");
      Fields::fail(key, msg.str());
    }
  }
}

// [stroke]
void read_stroke(Fields& f, Scene& s) {
  const double extent = domain_extent(s);
  const ToolSpec& t = s.tool;
  s.stroke.path_m = f.points("stroke.path_m", 1, /*required=*/true);
  s.stroke.z_m = f.numbers("stroke.z_m", 0, 1, open(-1e9, 1e9), false);
  if (!s.stroke.z_m.empty() && s.stroke.z_m.size() != s.stroke.path_m.size())
    Fields::fail("stroke.z_m", "has " + std::to_string(s.stroke.z_m.size()) + " values; it needs one per waypoint (" +
                                   std::to_string(s.stroke.path_m.size()) + ")");
  s.stroke.spacing_m = f.number("stroke.spacing_m", 0.005, positive(extent * 10.0));
  s.stroke.repeat = static_cast<int>(f.integer("stroke.repeat", 1, 1, 1000000));
  const double length = polyline_length(s.stroke.path_m);
  if (length / s.stroke.spacing_m * s.stroke.repeat > 1e7)
    Fields::fail("stroke.spacing_m", "gives more than 1e7 stamps for this path; use a larger spacing");
  // Every stamp costs at least its footprint's vertices on every back-end: refuse runs that
  // would take hours before they start rather than after.
  const double stamps = static_cast<double>(stamp_arc_count(length, s.stroke.spacing_m)) * s.stroke.repeat;
  const double corners = static_cast<double>(t.footprint_corners());
  if (stamps * corners > kMaxStampCorners) {
    std::ostringstream msg;
    msg << "gives " << stamps << " stamps of a " << corners << "-corner footprint (" << stamps * corners
        << " corners, more than " << kMaxStampCorners
        << "); use a larger stroke.spacing_m, a smaller stroke.repeat or fewer tool.sides";
    Fields::fail("stroke.spacing_m", msg.str());
  }
}

// [tin]
void read_tin(Fields& f, Scene& s) {
  const double extent = domain_extent(s);
  s.tin.alpha_flat_deg = f.number("tin.alpha_flat_deg", 0.4, closed(0.0, 45.0));
  s.tin.tolerance_m = f.number("tin.tolerance_m", 0.001, positive(1e6));
  s.tin.conserve_volume = f.boolean("tin.conserve_volume", true);
  s.tin.contour_subdivision_m = f.number("tin.contour_subdivision_m", 0.0, closed(0.0, extent));
  s.tin.snap_m = f.number("tin.snap_m", 1e-6, closed(0.0, 1e-2));
  s.tin.initial_points = f.integer("tin.initial_points", 0, 0, 20000000);
  s.tin.initial_jitter = f.number("tin.initial_jitter", 0.5, closed(0.0, 0.9));
  s.tin.contour_gap_m = f.number("tin.contour_gap_m", 0.0, closed(0.0, extent));
  s.tin.refine_m = f.number("tin.refine_m", 0.0, closed(0.0, extent));
  s.tin.curvature_tolerance_m = f.number("tin.curvature_tolerance_m", 0.0, closed(0.0, 1e6));
  s.tin.curvature_while_stamping = f.choice("tin.curvature_when", "always", {"always", "settling"}) == "always";
  s.tin.refine_min_m = f.number("tin.refine_min_m", 0.0, closed(0.0, extent));
  s.tin.planar_tolerance_m = f.number("tin.planar_tolerance_m", 0.0, closed(0.0, 1e6));
  s.tin.coarsen = f.boolean("tin.coarsen", true);
}

// [grid]
void read_grid(Fields& f, Scene& s) {
  const double extent = domain_extent(s);
  s.grid.cell_m = f.number("grid.cell_m", 0.005, positive(extent));
  const double cells = (s.domain.size_m.x() / s.grid.cell_m + 1) * (s.domain.size_m.y() / s.grid.cell_m + 1);
  if (cells > 2e9) Fields::fail("grid.cell_m", "gives more than 2e9 cells for this domain");
  s.grid.storage =
      f.choice("grid.storage", "double", {"float", "double"}) == "float" ? GridStorage::Float : GridStorage::Double;
  s.grid.neighbours = static_cast<int>(f.integer("grid.neighbours", 8, 4, 8));
  if (s.grid.neighbours != 4 && s.grid.neighbours != 8)
    Fields::fail("grid.neighbours", "= " + std::to_string(s.grid.neighbours) + " is not allowed; must be 4 or 8");
  s.grid.threads = static_cast<int>(f.integer("grid.threads", 1, 1, 2));
}

// [reference]
void read_reference(Fields& f, Scene& s) {
  const ToolSpec& t = s.tool;
  const std::string reference =
      f.choice("reference.kind", "none", {"none", "pile", "crater", "trench", "ridge", "plane"});
  s.reference = reference == "pile"     ? ReferenceKind::Pile
                : reference == "crater" ? ReferenceKind::Crater
                : reference == "trench" ? ReferenceKind::Trench
                : reference == "ridge"  ? ReferenceKind::Ridge
                : reference == "plane"  ? ReferenceKind::Plane
                                        : ReferenceKind::None;
  if (s.reference == ReferenceKind::Pile && t.shape != ToolShape::Pour)
    Fields::fail("reference.kind", "= \"pile\" needs tool.shape = \"pour\"");
  if (s.reference == ReferenceKind::Trench && s.stroke.path_m.size() != 2)
    Fields::fail("reference.kind", "= \"trench\" needs a straight stroke.path_m of 2 points");
  if (s.reference == ReferenceKind::Ridge && (t.shape != ToolShape::Pour || s.stroke.path_m.size() != 2))
    Fields::fail("reference.kind", "= \"ridge\" needs tool.shape = \"pour\" and a straight stroke.path_m of 2 points");
  if (s.reference == ReferenceKind::Plane && s.terrain.kind != TerrainKind::Plane)
    Fields::fail("reference.kind", "= \"plane\" needs terrain.kind = \"plane\"");
  check_reference_fit(s);
}

// [output]
void read_output(Fields& f, Scene& s) {
  const double extent = domain_extent(s);
  // At least 2 samples across the smaller side, by default too.
  const double smaller = s.domain.size_m.minCoeff();
  s.output.raster_m = f.number("output.raster_m", std::min({0.0025, extent / 100.0, smaller}), positive(extent));
  const double samples = (s.domain.size_m.x() / s.output.raster_m + 1) * (s.domain.size_m.y() / s.output.raster_m + 1);
  if (s.output.raster_m > smaller) {
    std::ostringstream msg;
    msg << "= " << s.output.raster_m << " gives fewer than 2 raster samples across the domain's smaller side ("
        << smaller << " m); it must be at most that";
    Fields::fail("output.raster_m", msg.str());
  }
  if (samples > kMaxRasterSamples)
    Fields::fail("output.raster_m", "gives more than 1e8 raster samples for this domain");
  s.output.energy = f.boolean("output.energy", false);
}

// [haptics] (common/haptics/rendering.hpp; only `sandbench interactive` uses them)
void read_haptics(Fields& f, Scene& s) {
  haptics::RenderingOptions& h = s.haptics;
  h.blend_s = 1e-3 * f.number("haptics.blend_ms", 1e3 * h.blend_s, closed(0.0, 1000.0));
  h.max_force_rate_n_per_s = f.number("haptics.max_force_rate_n_per_s", h.max_force_rate_n_per_s, closed(0.0, 1e6));
  h.passivity = f.boolean("haptics.passivity_control", h.passivity);
  h.passivity_max_force_n = f.number("haptics.passivity_max_force_n", h.passivity_max_force_n, closed(0.0, 1e3));
  h.coupling = f.boolean("haptics.coupling", h.coupling);
  h.coupling_stiffness_n_per_m =
      f.number("haptics.coupling_stiffness_n_per_m", h.coupling_stiffness_n_per_m, positive(1e6));
  h.coupling_damping_n_s_per_m =
      f.number("haptics.coupling_damping_n_s_per_m", h.coupling_damping_n_s_per_m, closed(0.0, 1e4));
  h.tool_mass_kg = f.number("haptics.tool_mass_kg", h.tool_mass_kg, positive(100.0));
}
}  // namespace

void read_scene_sections(Fields& f, Scene& s, const std::filesystem::path& base_dir) {
  // In this order: later sections' ranges and checks depend on the domain, the tool and the stroke.
  read_domain(f, s);
  read_terrain(f, s, base_dir);
  read_material(f, s);
  read_erosion(f, s);
  read_tool(f, s);
  read_stroke(f, s);
  read_tin(f, s);
  read_grid(f, s);
  read_reference(f, s);
  read_output(f, s);
  read_haptics(f, s);
}

}  // namespace sb::scene_detail
