#include "common/height_field.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "common/bilinear.hpp"
#include "common/png_io.hpp"

namespace sb {

namespace {
// Portable uniform [0, 1) from the raw 64-bit engine (std distributions differ by library).
double unit(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }
}  // namespace

HeightField HeightField::flat(const DomainSpec& domain, double height_m) {
  HeightField f;
  f.domain_ = domain;
  f.kind_ = TerrainKind::Flat;
  f.base_m_ = height_m;
  f.feature_m_ = std::max(domain.size_m.x(), domain.size_m.y());
  return f;
}

HeightField HeightField::from_scene(const Scene& scene) {
  HeightField f = flat(scene.domain, scene.terrain.height_m);
  f.kind_ = scene.terrain.kind;
  if (f.kind_ == TerrainKind::Dunes) {
    std::mt19937_64 rng(static_cast<std::uint64_t>(scene.terrain.seed));
    f.amplitude_m_ = scene.terrain.dune_amplitude_m;
    f.ridge_weight_sum_ = 0.0;
    const double main_dir = 2.0 * std::numbers::pi * unit(rng);
    double shortest = scene.terrain.dune_wavelength_m;
    for (int k = 0; k < scene.terrain.dune_components; ++k) {
      // The first ridge dominates; later ones are shorter, weaker and turned a little.
      const double wavelength = scene.terrain.dune_wavelength_m / (1.0 + 0.7 * k * unit(rng) + 0.3 * k);
      const double dir = main_dir + (unit(rng) - 0.5) * (k == 0 ? 0.0 : 1.2);
      const double weight = 1.0 / (1.0 + k);
      f.ridges_.push_back({Vec2(std::cos(dir), std::sin(dir)) * (2.0 * std::numbers::pi / wavelength),
                           2.0 * std::numbers::pi * unit(rng), weight});
      f.ridge_weight_sum_ += weight;
      shortest = std::min(shortest, wavelength);
    }
    f.feature_m_ = shortest / 8.0;
  } else if (f.kind_ == TerrainKind::Plane) {
    const double a = deg_to_rad(scene.terrain.azimuth_deg);
    f.plane_gradient_ = -std::tan(deg_to_rad(scene.terrain.slope_deg)) * Vec2(std::cos(a), std::sin(a));
  } else if (f.kind_ == TerrainKind::Cone) {
    f.cone_tan_ = std::tan(deg_to_rad(scene.terrain.slope_deg));
    f.cone_radius_m_ = cone_radius(scene.terrain.cone_volume_m3, f.cone_tan_);
    f.feature_m_ = f.cone_radius_m_ / 8.0;
  } else if (f.kind_ == TerrainKind::Heightmap) {
    const Png16 png = read_png16(scene.terrain.heightmap_path, "terrain.path");
    f.img_w_ = png.width;
    f.img_h_ = png.height;
    f.img_.resize(png.values.size());
    // PNG row 0 is the top of the image, i.e. the domain's maximum y.
    for (std::size_t r = 0; r < png.height; ++r)
      for (std::size_t c = 0; c < png.width; ++c)
        f.img_[(png.height - 1 - r) * png.width + c] =
            scene.terrain.height_m + png.values[r * png.width + c] / 65535.0 * scene.terrain.vertical_scale_m;
    f.feature_m_ = std::min(scene.domain.size_m.x() / std::max<std::size_t>(1, png.width - 1),
                            scene.domain.size_m.y() / std::max<std::size_t>(1, png.height - 1));
  }
  return f;
}

double HeightField::operator()(const Vec2& p) const {
  switch (kind_) {
    case TerrainKind::Flat:
      return base_m_;
    case TerrainKind::Plane:
      return base_m_ + plane_gradient_.dot(p - domain_.centre());
    case TerrainKind::Cone:
      return base_m_ + cone_tan_ * std::max(0.0, cone_radius_m_ - (p - domain_.centre()).norm());
    case TerrainKind::Dunes: {
      double sum = 0.0;
      for (const Ridge& r : ridges_) {
        // A skewed sine: gentle windward slope, steeper lee side, in [0, 1].
        const double t = r.wave.dot(p - domain_.origin_m) + r.phase;
        sum += r.weight * 0.5 * (1.0 + std::sin(t + 0.45 * std::sin(t)));
      }
      return base_m_ + amplitude_m_ * sum / ridge_weight_sum_;
    }
    case TerrainKind::Heightmap: {
      const Vec2 g = (p - domain_.origin_m).cwiseQuotient(domain_.size_m);
      return bilinear(std::clamp(g.x(), 0.0, 1.0) * static_cast<double>(img_w_ - 1),
                      std::clamp(g.y(), 0.0, 1.0) * static_cast<double>(img_h_ - 1), img_w_, img_h_,
                      [&](std::size_t x, std::size_t y) { return static_cast<double>(img_[y * img_w_ + x]); });
    }
  }
  return base_m_;
}

}  // namespace sb
