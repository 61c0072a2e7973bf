#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <stdexcept>

#include "common/atomic_file.hpp"
#include "common/format.hpp"
#include "harness/io/export.hpp"

namespace sb {

namespace {

std::string pair(const Vec2& v) {
  std::string out = "[";
  out.append(exact_number(v.x())).append(", ").append(exact_number(v.y())).append("]");
  return out;
}

std::string xml_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '&')
      out += "&amp;";
    else if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '"')
      out += "&quot;";
    else
      out += c;
  }
  return out;
}
}  // namespace

HeightmapKeys heightmap_keys(const Raster& r) {
  if (r.nx < 2 || r.ny < 2 || r.values.size() != r.nx * r.ny)
    throw std::invalid_argument("export_png16: the raster must be at least 2 x 2");
  if (r.nx > 0x7fffffff / 2 || r.ny > 0x7fffffff / 2) throw std::invalid_argument("export_png16: raster too large");
  HeightmapKeys k;
  k.origin_m = r.origin_m;
  k.size_m = Vec2(static_cast<double>(r.nx - 1), static_cast<double>(r.ny - 1)) * r.spacing_m;
  const auto [lo, hi] = std::minmax_element(r.values.begin(), r.values.end());
  k.height_m = *lo;
  // A level raster still needs a positive scale (the scene requires one); every value is 0.
  k.vertical_scale_m = *hi > *lo ? *hi - *lo : 1e-3;
  return k;
}

Png16 quantise(const Raster& r, const HeightmapKeys& k) {
  Png16 png;
  png.width = r.nx;
  png.height = r.ny;
  png.values.resize(r.nx * r.ny);
  for (std::size_t row = 0; row < r.ny; ++row) {
    const std::size_t iy = r.ny - 1 - row;  // PNG row 0 is the domain's maximum y
    for (std::size_t ix = 0; ix < r.nx; ++ix) {
      const double t = (r.at(ix, iy) - k.height_m) / k.vertical_scale_m * 65535.0;
      png.values[row * r.nx + ix] = static_cast<std::uint16_t>(std::lround(std::clamp(t, 0.0, 65535.0)));
    }
  }
  return png;
}

std::string heightmap_scene_snippet(const HeightmapKeys& k, const std::string& png_name) {
  return "[domain]\norigin_m = " + pair(k.origin_m) + "\nsize_m = " + pair(k.size_m) +
         "\n\n[terrain]\nkind = \"heightmap\"\npath = \"" + png_name + "\"\nheight_m = " + exact_number(k.height_m) +
         "\nvertical_scale_m = " + exact_number(k.vertical_scale_m) + "\n";
}

HeightmapKeys export_png16(const std::filesystem::path& file, const Raster& raster, const std::string& source) {
  const HeightmapKeys k = heightmap_keys(raster);
  const Png16 png = quantise(raster, k);
  const double s = raster.spacing_m;
  // GDAL's sidecar: pixel-is-area georeference (pixel centres on the raster points), and the
  // scale and offset that turn values into metres.
  const std::string aux = "<PAMDataset>\n  <GeoTransform>" + exact_number(k.origin_m.x() - s / 2) + ", " +
                          exact_number(s) + ", 0, " + exact_number(k.origin_m.y() + k.size_m.y() + s / 2) + ", 0, " +
                          exact_number(-s) + "</GeoTransform>\n  <Metadata>\n    <MDI key=\"source\">" +
                          xml_escape(source) +
                          "</MDI>\n  </Metadata>\n  <PAMRasterBand band=\"1\">\n    <Description>height</Description>\n"
                          "    <UnitType>m</UnitType>\n    <Offset>" +
                          exact_number(k.height_m) + "</Offset>\n    <Scale>" + exact_number(k.step_m()) +
                          "</Scale>\n  </PAMRasterBand>\n</PAMDataset>\n";
  std::filesystem::path aux_file = file;
  aux_file += ".aux.xml";
  write_text_atomically(aux_file, aux);
  try {
    write_png16(file, png,
                {{"Software", "sandbench"},
                 {"Source", source},
                 {"Description",
                  "sandbench heightmap: z = height_m + value / 65535 * vertical_scale_m (metres); "
                  "column 0 at origin x, row 0 at origin y + size y (maximum y)"},
                 {"sandbench.origin_m", pair(k.origin_m)},
                 {"sandbench.size_m", pair(k.size_m)},
                 {"sandbench.height_m", exact_number(k.height_m)},
                 {"sandbench.vertical_scale_m", exact_number(k.vertical_scale_m)},
                 {"sandbench.scene", heightmap_scene_snippet(k, file.filename().string())}});
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(aux_file, ignored);
    throw;
  }
  return k;
}

}  // namespace sb
