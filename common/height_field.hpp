#pragma once
// HeightField: the scene's initial surface as a function z(x, y) over the domain -- flat,
// a tilted plane, a sand cone, seeded procedural dunes, or a 16-bit PNG heightmap stretched over the domain. Back-ends
// build their models from it; schedules use it for the tool depth. Evaluation is O(1).
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "common/scene.hpp"

namespace sb {

// The base radius of a cone of `volume` (m^3) whose flank rises at tan_angle. O(1).
inline double cone_radius(double volume, double tan_angle) {
  return std::cbrt(3.0 * volume / (std::numbers::pi * tan_angle));
}

class HeightField {
 public:
  static HeightField from_scene(const Scene& scene);  // throws InputError for a bad PNG
  static HeightField flat(const DomainSpec& domain, double height_m);

  double operator()(const Vec2& p) const;
  const DomainSpec& domain() const { return domain_; }
  // The smallest horizontal detail worth resolving: the heightmap pixel, a fraction of the
  // shortest dune wavelength or of the cone's radius, or the domain for a flat terrain.
  double feature_m() const { return feature_m_; }

 private:
  struct Ridge {
    Vec2 wave;  // direction * 2 pi / wavelength
    double phase;
    double weight;
  };
  DomainSpec domain_;
  TerrainKind kind_ = TerrainKind::Flat;
  double base_m_ = 0.0;
  double amplitude_m_ = 0.0;
  Vec2 plane_gradient_{0.0, 0.0};                // plane: dz/dx, dz/dy
  double cone_radius_m_ = 0.0, cone_tan_ = 0.0;  // cone: base radius, tan(flank slope)
  std::vector<Ridge> ridges_;
  double ridge_weight_sum_ = 1.0;
  std::size_t img_w_ = 0, img_h_ = 0;
  std::vector<double> img_;  // heights, row 0 at the domain's minimum y
  double feature_m_ = 1.0;
};

}  // namespace sb
