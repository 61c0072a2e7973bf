#pragma once
// Scene: everything one run needs, loaded from a commented TOML file, validated field by
// field (unknown keys, wrong types, NaN and out-of-range values raise InputError naming the
// key), with `--set key=value` overrides applied before validation.
#include <filesystem>
#include <string>
#include <vector>

#include "common/erosion.hpp"
#include "common/geometry.hpp"
#include "common/haptics/rendering.hpp"
#include "common/material.hpp"
#include "common/schedule.hpp"
#include "common/tool.hpp"

namespace sb {

enum class TerrainKind { Flat, Dunes, Heightmap, Plane, Cone };
std::string to_string(TerrainKind k);

struct DomainSpec {
  Vec2 origin_m{0.0, 0.0};
  Vec2 size_m{0.7071067811865476, 0.7071067811865476};
  Aabb2 box() const { return {origin_m, origin_m + size_m}; }
  Vec2 centre() const { return origin_m + 0.5 * size_m; }
};

struct TerrainSpec {
  TerrainKind kind = TerrainKind::Flat;
  double height_m = 0.1;  // flat height; base height for dunes and heightmaps
  // dunes: a seeded sum of sinusoidal ridges
  double dune_amplitude_m = 0.02;
  double dune_wavelength_m = 0.2;
  int dune_components = 4;
  long long seed = 1;
  // heightmap: 16-bit grey PNG stretched over the domain; z = height_m + v/65535 * scale
  std::filesystem::path heightmap_path;
  double vertical_scale_m = 0.1;
  // plane: height_m at the domain's centre, falling at slope_deg toward azimuth_deg
  // (counter-clockwise from +x); for the angle-of-repose experiments.
  double slope_deg = 0.0;
  double azimuth_deg = 0.0;
  // cone: a sand cone of cone_volume_m3 standing at slope_deg on height_m, its apex at the
  // domain's centre (a steep one relaxes to the pile reference with no pour dynamics).
  double cone_volume_m3 = 0.0;
};

struct ErosionSpec {
  int max_passes_per_step = 4;        // erosion passes over L_e after each stamp
  int idle_passes = 2;                // an element leaves L_e after this many idle visits
  double settle_tolerance_deg = 0.1;  // slopes up to critical + this count as stable
  bool relax_at_end = true;           // after the stroke, erode until settled
  int relax_max_passes = 20000;
  // Settling starts with the back-end's coarse-to-fine cascade (faster on large disturbances; on
  // a spreading pile it leaves the flank flatter than the fine rule would: README, erosion.cascade).
  bool cascade = true;
  // "gradient" (at rest at the critical angle in every azimuth) or "edge" (the paper's
  // rule: neighbour directions only); see common/erosion.hpp.
  ErosionRuleKind rule = ErosionRuleKind::Gradient;
};

struct TinSpec {
  double alpha_flat_deg = 0.4;         // the paper's alpha_flat, read as degrees
  double tolerance_m = 0.001;          // greedy insertion: max height error of the initial TIN
  bool conserve_volume = true;         // compensate retriangulation volume changes; false: the paper
  double contour_subdivision_m = 0.0;  // outer contour subdivision step; 0: tool polygon only
  double snap_m = 1e-6;                // points closer than this to a vertex reuse it
  // A TIN of about this many vertices from the start (a jittered lattice with heights from
  // the terrain), as in the paper's experiments; 0: as few as the terrain needs.
  long long initial_points = 0;
  double initial_jitter = 0.5;  // lattice jitter, fraction of a cell; 0: exact lattice
  double contour_gap_m = 0.0;   // outer-to-inner contour distance; 0: 5% of the tool size
  double refine_m = 0.0;        // erosion splits edges longer than this that sand flows
                                // across; 0: 4 tolerance_m / tan(critical angle)
  // Where sand flows across an edge between two facets whose gradients differ by dg, linear
  // interpolation along that crease errs by about length * dg / 4: erosion also splits edges
  // whose error exceeds curvature_tolerance_m, down to refine_min_m (0: refine_m / 2; at least refine_m / 4). 0: off.
  double curvature_tolerance_m = 0.0;
  // Whether that refinement also runs while a tool works (true, "always") or only while the
  // sand settles (false, "settling": ErosionBudget::settling), keeping the strokes' steps as
  // cheap as without it and refining the creases of the surface that comes to rest.
  bool curvature_while_stamping = true;
  double refine_min_m = 0.0;
  // coarsen: once the terrain is at rest, simplification also removes vertices within
  // planar_tolerance_m of the plane fitted to their neighbours (volume-preserving; 0:
  // tolerance_m / 4), never tilting a triangle past the stable slope. Off keeps the paper's
  // step 3 alone (alpha_flat_deg, every step), as the alpha_flat experiment does.
  double planar_tolerance_m = 0.0;
  bool coarsen = true;
};

enum class GridStorage { Float, Double };
struct GridSpec {
  double cell_m = 0.005;
  GridStorage storage = GridStorage::Double;
  int neighbours = 8;  // 4 or 8
  // Threads a large dense erosion pass may use (1 or 2): time only, the heights are the same.
  int threads = 1;
};

// The analytic shape the run is measured against (common/reference.hpp).
enum class ReferenceKind { None, Pile, Crater, Trench, Ridge, Plane };
std::string to_string(ReferenceKind k);

struct OutputSpec {
  double raster_m = 0.0025;  // spacing of the common comparison raster
  // Record the sand's potential energy after every step (costs one raster sample per step);
  // used to detect oscillating erosion, whose energy rises.
  bool energy = false;
};

struct Scene {
  std::string path;                    // as given
  std::string text;                    // the file's text, verbatim
  std::vector<std::string> overrides;  // "key=value" as given to --set
  std::string resolved;                // the effective scene (TOML) after overrides

  DomainSpec domain;
  std::string crs;  // domain.crs: coordinate reference system for GIS exports ("EPSG:32633"); "" none
  TerrainSpec terrain;
  Material material;
  ErosionSpec erosion;
  ToolSpec tool;
  Stroke stroke;
  TinSpec tin;
  GridSpec grid;
  OutputSpec output;
  haptics::RenderingOptions haptics;  // [haptics]: how the interactive servo renders forces
  ReferenceKind reference = ReferenceKind::None;
};

// Largest stamp count x footprint corners a scene may ask for: beyond it a run takes hours.
inline constexpr double kMaxStampCorners = 2e9;

// An override "unset KEY" (what `--unset KEY` adds to the overrides) removes KEY, e.g. so
// that `--unset tool.radius_m --set tool.shape=box --set tool.size_m=[0.04,0.02]` switches a
// disk scene to a box. Overrides apply in order.
inline constexpr const char* kUnsetPrefix = "unset ";
inline std::string unset_override(const std::string& key) { return kUnsetPrefix + key; }

// One scene key as the validator reads it: `sandbench scene-keys` prints these, and the
// README's scene table is checked against them.
struct SceneKey {
  std::string key;           // dotted, e.g. "tool.radius_m"
  std::string type;          // number | integer | boolean | string | choice | [x, y] | array | points
  std::string default_text;  // "" when required or depending on other keys (see meaning)
  std::string allowed;       // range or choices, as in error messages ("x domain extent" when scaled)
  std::string meaning;
};
// Every key, in file order, collected by running the validator over one scene per terrain
// kind, tool shape and profile (so conditional keys are included). O(keys).
std::vector<SceneKey> scene_keys();

// domain.crs of a resolved scene's text (what run files store), or "" when absent or unreadable.
std::string scene_crs(const std::string& resolved_text);

// Loads and validates a scene; throws InputError naming the offending key.
Scene load_scene(const std::filesystem::path& file, const std::vector<std::string>& overrides = {});
// Same, from text (base_dir resolves relative heightmap paths).
Scene parse_scene(const std::string& text, const std::string& name, const std::vector<std::string>& overrides = {},
                  const std::filesystem::path& base_dir = {});

}  // namespace sb
