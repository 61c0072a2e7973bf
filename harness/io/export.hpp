#pragma once
// Exports of a run's surface for the tools researchers already use:
//   PLY    binary little-endian; vertex x y z (float, metres, z up), triangular faces
//          (counter-clockwise seen from above) and every unique edge with a `constrained`
//          flag (MeshLab, Blender, QGIS through MDAL).
//   OBJ    text; v and f, constrained edges as `l` lines in group constrained_edges.
//   PNG16  16-bit grey heightmap of the common raster that reloads as a scene heightmap:
//          z = height_m + value / 65535 * vertical_scale_m, PNG row 0 at the domain's
//          maximum y, stretched over [domain] origin_m / size_m. The keys are stored as PNG
//          text chunks (with a ready-to-paste scene snippet), and a GDAL sidecar
//          FILE.aux.xml gives QGIS the georeference, scale and offset.
// Each file is written whole or not at all. Costs: O(V + T log T) for PLY (edges),
// O(V + T) for OBJ, O(raster points) for PNG16.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "common/geometry.hpp"
#include "common/png_io.hpp"
#include "common/raster.hpp"
#include "common/terrain.hpp"

namespace sb {

enum class ExportFormat { Ply, Obj, Png16 };
// The formats by name: ply, obj, png16.
const std::map<std::string, ExportFormat>& export_formats();

// `comments`: one line each (newlines become spaces), e.g. the back-end and the scene.
void export_ply(const std::filesystem::path& file, const SurfaceMesh& mesh, const std::vector<std::string>& comments);
void export_obj(const std::filesystem::path& file, const SurfaceMesh& mesh, const std::vector<std::string>& comments);

// How a raster maps to a 16-bit heightmap (the scene keys that reload it).
struct HeightmapKeys {
  Vec2 origin_m{0.0, 0.0};
  Vec2 size_m{0.0, 0.0};                                        // (nx - 1, ny - 1) * spacing
  double height_m = 0.0;                                        // the lowest height (value 0)
  double vertical_scale_m = 0.0;                                // value 65535 is height_m + this
  double step_m() const { return vertical_scale_m / 65535.0; }  // one quantisation step
};
HeightmapKeys heightmap_keys(const Raster& raster);
Png16 quantise(const Raster& raster, const HeightmapKeys& keys);
// The [domain] and [terrain] tables that load the file back as a heightmap.
std::string heightmap_scene_snippet(const HeightmapKeys& keys, const std::string& png_name);
// Writes FILE (PNG) and FILE.aux.xml (GDAL); `source` goes into the PNG's Source chunk.
HeightmapKeys export_png16(const std::filesystem::path& file, const Raster& raster, const std::string& source);

}  // namespace sb
