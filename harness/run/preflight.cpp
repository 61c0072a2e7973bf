#include "harness/run/preflight.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <numbers>
#include <sstream>

#include "common/format_bytes.hpp"
#include "common/input_error.hpp"
#include "common/metrics.hpp"
#include "common/png_io.hpp"
#include "common/raster.hpp"
#include "grid/grid_layout.hpp"
#include "tin/tin_terrain.hpp"

namespace sb {

namespace {

// The back-ends' own figures (their headers): bytes a dense grid node holds (height, active
// state), a sparse grid's block table and active bits per node and a stored node, a TIN
// vertex with its share of triangles and CGAL's faces (the build notice's measured figure).
constexpr double kDenseExtraBytesPerNode = 2.0;
constexpr double kSparseBytesPerNode = 9.0 / 64.0 + 0.25;
constexpr double kSparseExtraBytesPerStoredNode = 0.625;
constexpr double kTinBytesPerVertex = 290.0;
// A PNG heightmap: the decoded rows (2 bytes a channel), the 16-bit values, the double heights.
constexpr double kHeightmapBytesPerPixelBeyondRows = 2.0 + 8.0;
// The TIN may add this many times its estimated vertices before it is stopped: the estimate
// is of an even mesh at its finest length, and the stamps' contours come and go on top of it.
constexpr double kTinAllowanceFactor = 8.0;
constexpr double kTinAllowanceSlack = 200000.0;

std::mutex context_mutex;
std::string context;  // out_of_memory_context()

double nodes_of(const Scene& s) {
  return static_cast<double>(grid::GridLayout::covering(s.domain.box(), s.grid.cell_m).nodes());
}

double raster_samples(const Scene& s) {
  const auto shape = Raster::shape_covering(s.domain.box(), s.output.raster_m);
  return static_cast<double>(shape[0]) * static_cast<double>(shape[1]);
}

// How far from the stroke's axis a stamp reaches: the footprint's farthest corner and its rim
// band, or a pour's radius.
double tool_reach(const ToolSpec& t) {
  if (t.shape == ToolShape::Pour) return t.radius_m;
  double r = 0.0;
  for (const Vec2& p : t.footprint_local()) r = std::max(r, p.norm());
  return r + t.rim.width_m;
}

// The area a run's sand may move over: the band around the stroke that the tool reaches,
// widened by the slope the moved sand comes to rest at (a pour: the cone of all its volume),
// within the domain. Any terrain other than flat sand may avalanche by itself, and a replayed
// session's path is not the scene's: the whole domain.
double disturbed_area(const Scene& s, double stamps, bool replay) {
  const double domain_area = s.domain.size_m.x() * s.domain.size_m.y();
  if (replay || s.terrain.kind != TerrainKind::Flat) return domain_area;
  const double tan_c = std::max(s.material.tan_critical(), 1e-3);
  double reach = tool_reach(s.tool);
  if (s.tool.shape == ToolShape::Pour) {
    const double volume = s.tool.pour_volume_m3 * stamps;
    reach = std::max(reach, std::cbrt(3.0 * volume / (std::numbers::pi * tan_c)));
  } else {
    double depth = std::fabs(s.tool.depth_m);
    for (double z : s.stroke.z_m) depth = std::max(depth, std::fabs(z - s.terrain.height_m));
    reach += depth / tan_c;
  }
  const double length = polyline_length(s.stroke.path_m);
  return std::min(domain_area, 2.0 * reach * length + std::numbers::pi * reach * reach);
}

// Vertices of an even mesh of edge `edge_m` over `area`: an equilateral triangle's vertex
// stands for sqrt(3)/2 edge^2.
double even_mesh_vertices(double area, double edge_m) { return area / (std::sqrt(3.0) / 2.0 * edge_m * edge_m); }

std::string refinement_keys(const Scene& s) {
  return s.tin.curvature_tolerance_m > 0.0 ? "tin.refine_m, tin.refine_min_m, tin.curvature_tolerance_m"
                                           : "tin.refine_m";
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

void add(ResourceEstimate& e, std::string what, std::string keys, double elements, double bytes) {
  if (bytes > 0.0) e.items.push_back({std::move(what), std::move(keys), elements, bytes});
}

std::string describe(const ResourceItem& item) {
  return item.keys + ": " + item.what + ", " + number(item.elements) + ", about " + format_bytes(item.bytes);
}

// The scene's stamp count when it is its own stroke's (a replay passes the session's).
double model_vertices(const Scene& s, double stamps, bool replay) {
  const tin::Refinement r = tin::refinement_of(s);
  return even_mesh_vertices(disturbed_area(s, stamps, replay), r.fine_m);
}

}  // namespace

double ResourceEstimate::bytes() const {
  double total = 0.0;
  for (const ResourceItem& i : items) total += i.bytes;
  return total;
}

const ResourceItem* ResourceEstimate::largest() const {
  const ResourceItem* best = nullptr;
  for (const ResourceItem& i : items)
    if (!best || i.bytes > best->bytes) best = &i;
  return best;
}

ResourceEstimate estimate_resources(const std::vector<PlannedRun>& runs, std::size_t stamps, bool replay) {
  ResourceEstimate e;
  if (runs.empty()) return e;
  const auto n = static_cast<double>(stamps);
  // Shared by the runs: the initial surface and the comparison raster's template.
  const Scene& base = runs.front().scene;
  if (base.terrain.kind == TerrainKind::Heightmap) {
    const Png16Size png = read_png16_size(base.terrain.heightmap_path, "terrain.path");
    const double pixels = static_cast<double>(png.width) * static_cast<double>(png.height);
    add(e, "heightmap pixels (" + std::to_string(png.width) + " x " + std::to_string(png.height) + ")", "terrain.path",
        pixels, pixels * (2.0 * static_cast<double>(png.channels) + kHeightmapBytesPerPixelBeyondRows));
  }
  for (const PlannedRun& run : runs) {
    const Scene& s = run.scene;
    const std::string label = "[" + run.backend + "] ";
    // Each run keeps its initial and final raster, and its step records (stamps and settling).
    const double samples = raster_samples(s);
    add(e, label + "raster samples (initial, final)", "output.raster_m, domain.size_m", 2.0 * samples,
        2.0 * samples * sizeof(double));
    const double steps = n + static_cast<double>(s.erosion.relax_max_passes) / 64.0;
    add(e, label + "step records", "stroke.spacing_m, stroke.repeat, erosion.relax_max_passes", steps,
        steps * sizeof(StepRecord));
    const double real_bytes = s.grid.storage == GridStorage::Float ? 4.0 : 8.0;
    if (run.backend == "grid") {
      const double nodes = nodes_of(s);
      add(e, label + "grid nodes", "grid.cell_m, domain.size_m", nodes, nodes * (real_bytes + kDenseExtraBytesPerNode));
    } else if (run.backend == "sparse") {
      const double nodes = nodes_of(s);
      const double cell_area = s.grid.cell_m * s.grid.cell_m;
      const double stored = std::min(nodes, disturbed_area(s, n, replay) / cell_area);
      add(e, label + "sparse grid nodes (all, and stored where disturbed)", "grid.cell_m, domain.size_m", nodes,
          nodes * kSparseBytesPerNode + stored * (real_bytes + kSparseExtraBytesPerStoredNode));
    } else if (run.backend == "tin") {
      const double initial = static_cast<double>(s.tin.initial_points);
      add(e, label + "TIN initial vertices", "tin.initial_points", initial, initial * kTinBytesPerVertex);
      const double refined = model_vertices(s, n, replay);
      add(e, label + "TIN vertices refined over the disturbed area", refinement_keys(s), refined,
          refined * kTinBytesPerVertex);
    }
  }
  return e;
}

std::size_t tin_vertex_allowance(const Scene& scene, std::size_t stamps, bool replay,
                                 std::uint64_t memory_limit_bytes) {
  double v = kTinAllowanceFactor * model_vertices(scene, static_cast<double>(stamps), replay) + kTinAllowanceSlack;
  if (memory_limit_bytes > 0) v = std::min(v, static_cast<double>(memory_limit_bytes) / kTinBytesPerVertex);
  return v >= 1e18 ? std::size_t{1} << 60 : static_cast<std::size_t>(v);
}

std::optional<std::uint64_t> available_memory_bytes() {
  std::optional<std::uint64_t> out;
  {
    std::ifstream in("/proc/meminfo");
    std::string key;
    std::uint64_t kib = 0;
    std::string unit;
    while (in >> key >> kib) {
      std::getline(in, unit);
      if (key == "MemAvailable:") {
        out = kib * 1024;
        break;
      }
    }
  }
  // cgroup v2: the group's limit less what it uses ("max": no limit).
  std::ifstream max_file("/sys/fs/cgroup/memory.max"), current_file("/sys/fs/cgroup/memory.current");
  std::string max_text;
  std::uint64_t current = 0;
  if (max_file >> max_text && max_text != "max" && current_file >> current) {
    try {
      const std::uint64_t limit = std::stoull(max_text);
      const std::uint64_t left = limit > current ? limit - current : 0;
      out = out ? std::min(*out, left) : left;
    } catch (const std::exception&) {
    }
  }
  return out;
}

std::optional<std::uint64_t> parse_memory_size(const std::string& text) {
  // Decimal digits only (no sign, hex, inf or spaces), then an optional unit.
  const std::size_t end = text.find_first_not_of("0123456789.eE+");
  const std::string digits = text.substr(0, end);
  const std::string suffix = end == std::string::npos ? std::string() : text.substr(end);
  if (digits.empty() || !(std::isdigit(static_cast<unsigned char>(digits[0])) || digits[0] == '.')) return std::nullopt;
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(digits, &used);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (used != digits.size()) return std::nullopt;
  double scale = 1.0;
  if (suffix == "K" || suffix == "k")
    scale = 1024.0;
  else if (suffix == "M")
    scale = 1024.0 * 1024.0;
  else if (suffix == "G")
    scale = 1024.0 * 1024.0 * 1024.0;
  else if (suffix == "T")
    scale = 1024.0 * 1024.0 * 1024.0 * 1024.0;
  else if (!suffix.empty())
    return std::nullopt;
  const double bytes = v * scale;
  if (!std::isfinite(bytes) || !(bytes >= 1.0) || bytes > 1.8e19) return std::nullopt;
  return static_cast<std::uint64_t>(bytes);
}

std::uint64_t preflight(const ResourceEstimate& estimate, std::optional<std::uint64_t> max_memory) {
  const ResourceItem* largest = estimate.largest();
  {
    std::lock_guard<std::mutex> lock(context_mutex);
    context = largest ? describe(*largest) : std::string();
  }
  const std::optional<std::uint64_t> available = max_memory ? max_memory : available_memory_bytes();
  if (!largest) return available.value_or(0);
  const double total = estimate.bytes();
  const std::string limit_name =
      max_memory ? "--max-memory (" + format_bytes(static_cast<double>(*max_memory)) + ")"
                 : "the memory available (" + (available ? format_bytes(static_cast<double>(*available)) : "?") + ")";
  // The items that make up most of the total, largest first.
  std::vector<const ResourceItem*> order;
  for (const ResourceItem& i : estimate.items) order.push_back(&i);
  std::sort(order.begin(), order.end(),
            [](const ResourceItem* a, const ResourceItem* b) { return a->bytes > b->bytes; });
  std::string parts;
  for (std::size_t i = 0; i < order.size() && i < 3 && order[i]->bytes >= 0.1 * total; ++i)
    parts += (parts.empty() ? "" : "; ") + describe(*order[i]);
  if (available && total > static_cast<double>(*available))
    throw InputError("this run needs about " + format_bytes(total) + ", more than " + limit_name + ": " + parts +
                     "; change those keys (a larger grid.cell_m, tin.refine_m or output.raster_m, a smaller "
                     "heightmap or domain)" +
                     (max_memory ? "" : ", or give --max-memory to set the limit yourself"));
  if (total > kLargeRunBytes || (available && total > 0.5 * static_cast<double>(*available)))
    std::fprintf(stderr, "sandbench: warning: a large run: about %s of %s: %s\n", format_bytes(total).c_str(),
                 limit_name.c_str(), parts.c_str());
  return available.value_or(0);
}

std::string out_of_memory_context() {
  std::lock_guard<std::mutex> lock(context_mutex);
  return context;
}

void set_out_of_memory_context(std::string what) {
  std::lock_guard<std::mutex> lock(context_mutex);
  context = std::move(what);
}

}  // namespace sb
