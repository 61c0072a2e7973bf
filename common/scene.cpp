#include "common/scene.hpp"

#include <toml++/toml.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <set>
#include <sstream>

#include "common/input_error.hpp"
#include "common/scene_keys.hpp"

namespace sb {

std::string to_string(TerrainKind k) {
  switch (k) {
    case TerrainKind::Flat:
      return "flat";
    case TerrainKind::Dunes:
      return "dunes";
    case TerrainKind::Heightmap:
      return "heightmap";
    case TerrainKind::Plane:
      return "plane";
    case TerrainKind::Cone:
      return "cone";
  }
  return "?";
}

std::string to_string(ReferenceKind k) {
  switch (k) {
    case ReferenceKind::None:
      return "none";
    case ReferenceKind::Pile:
      return "pile";
    case ReferenceKind::Crater:
      return "crater";
    case ReferenceKind::Trench:
      return "trench";
    case ReferenceKind::Ridge:
      return "ridge";
    case ReferenceKind::Plane:
      return "plane";
  }
  return "?";
}

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// An interval with open or closed ends, printed in error messages as "(0, 10]".
struct Range {
  double lo = -kInf, hi = kInf;
  bool lo_open = false, hi_open = false;
  bool contains(double v) const { return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi); }
  std::string str() const {
    auto num = [](double v) {
      if (std::isinf(v)) return std::string(v > 0 ? "inf" : "-inf");
      std::ostringstream s;
      s << v;
      return s.str();
    };
    return (lo_open ? "(" : "[") + num(lo) + ", " + num(hi) + (hi_open ? ")" : "]");
  }
};
Range positive(double hi = kInf) { return {0.0, hi, true, hi == kInf}; }
Range closed(double lo, double hi) { return {lo, hi, false, false}; }
Range open(double lo, double hi) { return {lo, hi, true, true}; }

std::string describe(const toml::node& n) {
  std::ostringstream s;
  if (n.is_string()) {
    s << '"' << *n.value<std::string>() << '"';
  } else if (n.is_table()) {
    s << "a table";
  } else {
    n.visit([&](auto&& v) { s << v; });
  }
  return s.str();
}

// Reads typed fields by dotted key, remembers which keys were read, and at the end reports
// any key that nothing read (a typo, or a key of another version).
class Fields {
 public:
  explicit Fields(const toml::table& root, std::vector<SceneKey>* catalogue = nullptr)
      : root_(root), catalogue_(catalogue) {}

  const toml::node* find(const std::string& key) {
    seen_.insert(key);
    return root_.at_path(key).node();
  }

  double number(const std::string& key, double fallback, Range range, bool required = false) {
    note(key, "number", required ? "" : text(fallback), range.str());
    const toml::node* n = find(key);
    if (!n) {
      if (required) fail(key, "is missing; it must be a number in " + range.str());
      return fallback;
    }
    if (!n->is_number()) fail(key, "= " + describe(*n) + " must be a number in " + range.str());
    const double v = *n->value<double>();
    if (!std::isfinite(v)) fail(key, "= " + describe(*n) + " must be a finite number in " + range.str());
    if (!range.contains(v)) fail(key, "= " + describe(*n) + " is out of range " + range.str());
    return v;
  }

  long long integer(const std::string& key, long long fallback, long long lo, long long hi) {
    note(key, "integer", std::to_string(fallback), "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    const toml::node* n = find(key);
    if (!n) return fallback;
    const std::string allowed = "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    if (!n->is_integer()) fail(key, "= " + describe(*n) + " must be " + allowed);
    const long long v = *n->value<long long>();
    if (v < lo || v > hi) fail(key, "= " + describe(*n) + " is out of range: must be " + allowed);
    return v;
  }

  bool boolean(const std::string& key, bool fallback) {
    note(key, "boolean", fallback ? "true" : "false", "true | false");
    const toml::node* n = find(key);
    if (!n) return fallback;
    if (!n->is_boolean()) fail(key, "= " + describe(*n) + " must be true or false");
    return *n->value<bool>();
  }

  std::string choice(const std::string& key, const std::string& fallback, const std::vector<std::string>& allowed) {
    const toml::node* n = find(key);
    std::string list;
    for (const auto& a : allowed) list += (list.empty() ? "" : " | ") + a;
    note(key, "choice", "\"" + fallback + "\"", list);
    if (!n) return fallback;
    if (!n->is_string()) fail(key, "= " + describe(*n) + " must be one of " + list);
    const std::string v = *n->value<std::string>();
    for (const auto& a : allowed)
      if (a == v) return v;
    fail(key, "= \"" + v + "\" is not allowed; must be one of " + list);
    return v;
  }

  std::string string(const std::string& key, bool required) {
    note(key, "string", "", "non-empty string");
    const toml::node* n = find(key);
    if (!n) {
      if (required) fail(key, "is missing; it must be a string");
      return {};
    }
    if (!n->is_string() || n->value<std::string>()->empty())
      fail(key, "= " + describe(*n) + " must be a non-empty string");
    return *n->value<std::string>();
  }

  // An array of numbers; `count` 0 means any length >= min_count.
  std::vector<double> numbers(const std::string& key, std::size_t count, std::size_t min_count, Range range,
                              bool required, std::vector<double> fallback = {}) {
    std::string def;
    for (double v : fallback) def += (def.empty() ? "" : ", ") + text(v);
    note(key, count == 2 ? "[x, y]" : "array", required || fallback.empty() ? "" : "[" + def + "]",
         (count ? std::to_string(count) : "at least " + std::to_string(min_count)) + " numbers in " + range.str());
    const toml::node* n = find(key);
    const std::string shape =
        count ? std::to_string(count) + " numbers" : "at least " + std::to_string(min_count) + " numbers";
    if (!n) {
      if (required) fail(key, "is missing; it must be an array of " + shape + " in " + range.str());
      return fallback;
    }
    const toml::array* arr = n->as_array();
    if (!arr) fail(key, "= " + describe(*n) + " must be an array of " + shape);
    if ((count && arr->size() != count) || arr->size() < min_count)
      fail(key, "has " + std::to_string(arr->size()) + " elements; it must have " + shape);
    std::vector<double> out;
    for (std::size_t i = 0; i < arr->size(); ++i) {
      const toml::node& e = *arr->get(i);
      const std::string at = key + "[" + std::to_string(i) + "]";
      if (!e.is_number()) fail(at, "= " + describe(e) + " must be a number in " + range.str());
      const double v = *e.value<double>();
      if (!std::isfinite(v) || !range.contains(v))
        fail(at, "= " + describe(e) + " must be a finite number in " + range.str());
      out.push_back(v);
    }
    return out;
  }

  Vec2 vec2(const std::string& key, Vec2 fallback, Range range, bool required = false) {
    auto v = numbers(key, 2, 2, range, required, {fallback.x(), fallback.y()});
    return {v[0], v[1]};
  }

  std::vector<Vec2> points(const std::string& key, std::size_t min_count, bool required) {
    note(key, "points", "", "at least " + std::to_string(min_count) + " [x, y] pairs of finite numbers");
    const toml::node* n = find(key);
    if (!n) {
      if (required) fail(key, "is missing; it must be an array of [x, y] points");
      return {};
    }
    const toml::array* arr = n->as_array();
    if (!arr || arr->size() < min_count)
      fail(key, "must be an array of at least " + std::to_string(min_count) + " [x, y] points");
    std::vector<Vec2> out;
    for (std::size_t i = 0; i < arr->size(); ++i) {
      const toml::array* p = arr->get(i)->as_array();
      const std::string at = key + "[" + std::to_string(i) + "]";
      if (!p || p->size() != 2 || !p->get(0)->is_number() || !p->get(1)->is_number())
        fail(at, "= " + describe(*arr->get(i)) + " must be an [x, y] pair of numbers");
      const double x = *p->get(0)->value<double>(), y = *p->get(1)->value<double>();
      if (!std::isfinite(x) || !std::isfinite(y)) fail(at, "must hold finite numbers");
      out.emplace_back(x, y);
    }
    return out;
  }

  // Every leaf key present in the file must have been read.
  void reject_unknown() const { walk(root_, ""); }

  [[noreturn]] static void fail(const std::string& key, const std::string& what) {
    throw InputError("scene: " + key + " " + what);
  }

 private:
  void walk(const toml::table& t, const std::string& prefix) const {
    for (auto&& [k, v] : t) {
      const std::string key = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
      if (const toml::table* sub = v.as_table()) {
        walk(*sub, key);
      } else if (!seen_.count(key)) {
        // A key of the format that these settings do not read (tool.profile with a pour tool,
        // terrain.amplitude_m on flat sand) is a different mistake from a misspelt one.
        if (!scene_key_meaning(key).empty())
          fail(key,
               "does not apply with this scene's terrain.kind, tool.shape or tool.profile (see the scene "
               "format in README.md)");
        fail(key, "is not a known key (see the scene format in README.md)");
      }
    }
  }

  // In catalogue mode every read key is noted (once) with its type, default and range.
  void note(const std::string& key, const std::string& type, const std::string& fallback, const std::string& allowed) {
    if (!catalogue_) return;
    // Keys seen only in a later pass (another tool shape) go after the key read before them.
    for (std::size_t i = 0; i < catalogue_->size(); ++i)
      if ((*catalogue_)[i].key == key) {
        next_ = i + 1;
        return;
      }
    next_ = std::min(next_, catalogue_->size());
    catalogue_->insert(catalogue_->begin() + static_cast<std::ptrdiff_t>(next_), {key, type, fallback, allowed, {}});
    ++next_;
  }
  static std::string text(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
  }

  const toml::table& root_;
  std::vector<SceneKey>* catalogue_;
  std::size_t next_ = 0;
  std::set<std::string> seen_;
};

// "unset KEY" (what --unset KEY adds) removes a key, so that a default applies again or a
// key that belongs to another tool shape goes away.
void apply_unset(toml::table& root, const std::string& key) {
  toml::table* t = &root;
  std::size_t start = 0;
  for (std::size_t dot; (dot = key.find('.', start)) != std::string::npos; start = dot + 1) {
    toml::node* child = t->get(key.substr(start, dot - start));
    t = child ? child->as_table() : nullptr;
    if (!t) return;  // nothing to remove
  }
  t->erase(key.substr(start));
}

void apply_override(toml::table& root, const std::string& assignment) {
  if (assignment.rfind(kUnsetPrefix, 0) == 0) {
    const std::string key = assignment.substr(std::string(kUnsetPrefix).size());
    if (key.empty() || key.find_first_of(" =") != std::string::npos)
      throw InputError("--unset " + key + ": expected a key, e.g. tool.radius_m");
    apply_unset(root, key);
    return;
  }
  const auto eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError("--set " + assignment + ": expected key=value, e.g. tool.radius_m=0.02");
  const std::string key = assignment.substr(0, eq);
  const std::string value = assignment.substr(eq + 1);
  // The value is TOML ("0.02", "[1, 2]", "true", "\"disk\""); a bare word is a string.
  toml::table parsed;
  try {
    parsed = toml::parse("v = " + value);
  } catch (const toml::parse_error&) {
    parsed = toml::table{{"v", value}};
  }
  toml::table* t = &root;
  std::size_t start = 0;
  for (std::size_t dot; (dot = key.find('.', start)) != std::string::npos; start = dot + 1) {
    const std::string part = key.substr(start, dot - start);
    toml::node* child = t->get(part);
    if (!child) {
      t->insert(part, toml::table{});
      child = t->get(part);
    }
    t = child->as_table();
    if (!t) throw InputError("--set " + assignment + ": " + key.substr(0, dot) + " is not a table");
  }
  t->insert_or_assign(key.substr(start), std::move(*parsed.get("v")));
}

void read_scene(Fields& f, Scene& s, const std::filesystem::path& base_dir) {
  // [domain]
  s.domain.origin_m = f.vec2("domain.origin_m", {0.0, 0.0}, open(-1e9, 1e9));
  s.domain.size_m = f.vec2("domain.size_m", {}, positive(1e6), /*required=*/true);
  s.crs = f.string("domain.crs", /*required=*/false);
  const double extent = std::max(s.domain.size_m.x(), s.domain.size_m.y());

  // [terrain]
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

  // [material]
  s.material.critical_angle_deg = f.number("material.critical_angle_deg", 30.0, open(0.0, 90.0));
  s.material.transfer_fraction = f.number("material.transfer_fraction", 0.5, {0.0, 2.0, true, false});
  s.material.stiffness_n_per_m = f.number("material.stiffness_n_per_m", 800.0, closed(0.0, 1e6));
  s.material.drag_n_s_per_m = f.number("material.drag_n_s_per_m", 5.0, closed(0.0, 1e4));
  s.material.friction = f.number("material.friction", 0.4, closed(0.0, 10.0));

  // [erosion]
  s.erosion.max_passes_per_step = static_cast<int>(f.integer("erosion.max_passes_per_step", 4, 0, 100000));
  s.erosion.idle_passes = static_cast<int>(f.integer("erosion.idle_passes", 2, 1, 1000));
  s.erosion.settle_tolerance_deg = f.number("erosion.settle_tolerance_deg", 0.1, closed(0.0, 10.0));
  s.erosion.relax_at_end = f.boolean("erosion.relax_at_end", true);
  s.erosion.relax_max_passes = static_cast<int>(f.integer("erosion.relax_max_passes", 20000, 0, 100000000));
  s.erosion.cascade = f.boolean("erosion.cascade", true);
  s.erosion.rule = f.choice("erosion.rule", "gradient", {"gradient", "edge"}) == "gradient" ? ErosionRuleKind::Gradient
                                                                                            : ErosionRuleKind::Edge;

  // [tool]
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
    t.rim.model = *displacement_from(f.choice("tool.displacement", "rim", {"rim", "bulldoze"}));
  }

  // A footprint whose edges vanish next to the domain cannot be resolved by the TIN (which
  // merges points closer than 1e-12 x extent): refuse it here, for every back-end alike.
  if (t.shape != ToolShape::Pour) {
    const std::vector<Vec2> fp = t.footprint_local();
    double shortest = kInf;
    for (std::size_t i = 0; i < fp.size(); ++i) shortest = std::min(shortest, (fp[(i + 1) % fp.size()] - fp[i]).norm());
    const double least = 1e-9 * extent;
    if (!(shortest >= least)) {
      const std::string key = t.shape == ToolShape::Polygon ? "tool.polygon_m"
                              : t.shape == ToolShape::Disk  ? "tool.radius_m"
                                                            : "tool.size_m";
      std::ostringstream msg;
      msg << "gives footprint edges of " << shortest << " m, shorter than 1e-9 x the domain extent (" << least
          << " m); use a larger tool"
          << (t.shape == ToolShape::Polygon || t.shape == ToolShape::Box ? "" : " or fewer tool.sides");
      Fields::fail(key, msg.str());
    }
  }

  // [stroke]
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

  // [tin]
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

  // [grid]
  s.grid.cell_m = f.number("grid.cell_m", 0.005, positive(extent));
  const double cells = (s.domain.size_m.x() / s.grid.cell_m + 1) * (s.domain.size_m.y() / s.grid.cell_m + 1);
  if (cells > 2e9) Fields::fail("grid.cell_m", "gives more than 2e9 cells for this domain");
  s.grid.storage =
      f.choice("grid.storage", "double", {"float", "double"}) == "float" ? GridStorage::Float : GridStorage::Double;
  s.grid.neighbours = static_cast<int>(f.integer("grid.neighbours", 8, 4, 8));
  if (s.grid.neighbours != 4 && s.grid.neighbours != 8)
    Fields::fail("grid.neighbours", "= " + std::to_string(s.grid.neighbours) + " is not allowed; must be 4 or 8");
  s.grid.threads = static_cast<int>(f.integer("grid.threads", 1, 1, 2));

  // [reference]
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

  // [output]
  s.output.raster_m = f.number("output.raster_m", std::min(0.0025, extent / 100.0), positive(extent));
  const double samples = (s.domain.size_m.x() / s.output.raster_m + 1) * (s.domain.size_m.y() / s.output.raster_m + 1);
  if (samples > 1e8) Fields::fail("output.raster_m", "gives more than 1e8 raster samples for this domain");
  s.output.energy = f.boolean("output.energy", false);

  // [haptics] (common/haptics/rendering.hpp; only `sandbench interactive` uses them)
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

Scene parse_scene(const std::string& text, const std::string& name, const std::vector<std::string>& overrides,
                  const std::filesystem::path& base_dir) {
  toml::table root;
  try {
    root = toml::parse(text, name);
  } catch (const toml::parse_error& e) {
    std::ostringstream msg;
    msg << name << ":" << e.source().begin.line << ":" << e.source().begin.column
        << ": not valid TOML: " << e.description();
    throw InputError(msg.str());
  }
  for (const auto& o : overrides) apply_override(root, o);

  Scene s;
  s.path = name;
  s.text = text;
  s.overrides = overrides;
  Fields fields(root);
  read_scene(fields, s, base_dir);
  fields.reject_unknown();
  std::ostringstream resolved;
  resolved << root;
  s.resolved = resolved.str();
  return s;
}

std::string scene_crs(const std::string& resolved_text) {
  try {
    const toml::table root = toml::parse(resolved_text);
    return root.at_path("domain.crs").value_or(std::string());
  } catch (const toml::parse_error&) {
    return {};
  }
}

std::vector<SceneKey> scene_keys() {
  // One pass per terrain kind, tool shape and profile reaches every conditional key; the
  // passes run at two domain sizes so that ranges scaled by the domain are shown as such.
  const std::vector<std::vector<std::string>> variants = {
      {},
      {"terrain.kind=dunes"},
      {"terrain.kind=heightmap", "terrain.path=\"terrain.png\""},
      {"terrain.kind=plane"},
      {"terrain.kind=cone"},
      {"tool.shape=box", "tool.size_m=[0.04, 0.02]"},
      {"tool.shape=ellipse", "tool.size_m=[0.04, 0.02]"},
      {"tool.shape=polygon", "tool.polygon_m=[[0,0],[0.01,0],[0,0.01]]"},
      {"tool.shape=pour", "tool.volume_m3=1e-6"},
      {"tool.profile=sphere_cap"}};
  auto collect = [&](double extent) {
    std::vector<SceneKey> keys;
    // Backwards: a later pass's new keys go right after the key before them, so reading the
    // variants in reverse keeps the validator's order (dune keys before heightmap keys).
    for (auto it = variants.rbegin(); it != variants.rend(); ++it) {
      const auto& overrides = *it;
      std::ostringstream text;
      text << "[domain]\nsize_m = [" << extent << ", " << extent << "]\n[stroke]\npath_m = [[0.1, 0.1], [0.2, 0.2]]\n";
      toml::table root = toml::parse(text.str());
      for (const auto& o : overrides) apply_override(root, o);
      Scene scene;
      Fields fields(root, &keys);
      read_scene(fields, scene, {});
    }
    return keys;
  };
  std::vector<SceneKey> keys = collect(1.0);
  const std::vector<SceneKey> doubled = collect(2.0);
  for (std::size_t i = 0; i < keys.size() && i < doubled.size(); ++i) {
    if (keys[i].allowed != doubled[i].allowed) keys[i].allowed += " x domain extent";
    if (keys[i].default_text != doubled[i].default_text) keys[i].default_text += " x domain extent";
    keys[i].meaning = scene_key_meaning(keys[i].key);
  }
  return keys;
}

Scene load_scene(const std::filesystem::path& file, const std::vector<std::string>& overrides) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError("scene: cannot read " + file.string());
  std::ostringstream text;
  text << in.rdbuf();
  return parse_scene(text.str(), file.string(), overrides, file.parent_path());
}

}  // namespace sb
