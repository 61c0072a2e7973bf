#pragma once
// Analytic references and the accuracy metrics measured against them on the common raster.
//  - pile:   V poured at a point on flat sand relaxes into a circular cone whose flank stands
//            at the critical angle: radius r = (3V / (pi tan theta))^(1/3), height r tan theta.
//  - crater: one stamp without erosion: the footprint cut to the tool bottom, the cut volume
//            on the rim band by the common rim rule (exact up to the quadrature of the rule).
//  - trench: a straight stroke after relaxation: a trench whose walls stand at most at the
//            critical angle; measured by its fitted wall angle and depth.
// Costs: O(raster samples) per metric; the crater's rim normaliser integrates the rim rule on
// a 1000 x 1000 lattice over the tool's influence box once.
#include <nlohmann/json.hpp>
#include <optional>

#include "common/height_field.hpp"
#include "common/raster.hpp"
#include "common/scene.hpp"
#include "common/schedule.hpp"

namespace sb {

// Heights of the reference shape on the raster's lattice; nullopt for trench (no shape,
// only its metrics) and for scenes without a reference.
std::optional<Raster> reference_raster(const Scene& scene, const StampSchedule& schedule, const HeightField& initial,
                                       const Raster& lattice);

struct PileShape {
  double flank_angle_deg = 0.0;  // fitted slope of height against radius on the flank
  double roundness = 0.0;        // std / mean of the half-height contour's radius
  double radius_m = 0.0;         // mean radius of the foot (height above base > 1% of peak)
  double height_m = 0.0;         // peak above the base
};
// Measures a pile standing on a flat base around `centre`.
PileShape measure_pile(const Raster& heights, const Vec2& centre, double base_m);

struct TrenchShape {
  double wall_angle_deg = 0.0;  // steepest fitted wall slope in cross-sections
  double depth_m = 0.0;         // median depth below the initial surface along the axis
};
TrenchShape measure_trench(const Raster& heights, const Raster& initial, const Vec2& a, const Vec2& b);

// The accuracy metrics (README "Summary metrics") for the scene's reference, as summary entries
// ("reference.rmse_m", "pile.flank_angle_deg", ...). Empty when the scene has none.
nlohmann::ordered_json accuracy_metrics(const Scene& scene, const StampSchedule& schedule, const HeightField& initial,
                                        const Raster& initial_raster, const Raster& final_raster);

}  // namespace sb
