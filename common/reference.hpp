#pragma once
// Analytic references and the accuracy metrics measured against them on the common raster.
//  - pile:   V poured at a point on flat sand relaxes into a circular cone whose flank stands
//            at the critical angle: radius r = (3V / (pi tan theta))^(1/3), height r tan theta.
//  - crater: one stamp without erosion: the footprint cut to the tool bottom, the cut volume
//            on the rim band by the common rim rule (exact up to the quadrature of the rule).
//  - trench: a straight stroke after relaxation: a trench whose walls stand at the critical
//            angle; measured by the wall angle fitted in cross-sections (mean, extremes,
//            spread) and its depth.
//  - ridge:  sand poured along a straight stroke relaxes into a ridge whose flanks stand at the
//            critical angle; measured like the trench walls, upside down.
//  - plane:  a plane tilted above the critical angle (terrain.kind = "plane") relaxes to the
//            critical angle; measured by the plane fitted over the middle of the domain.
// Costs: O(raster samples) per metric; the crater's rim normaliser integrates the rim rule on
// a 1000 x 1000 lattice over the tool's influence box once.
#include <algorithm>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

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
  bool found = false;            // a pile above the base whose foot every ray found within the raster
};
// Measures a pile standing on a flat base around `centre`.
PileShape measure_pile(const Raster& heights, const Vec2& centre, double base_m);

// Wall slopes fitted in 22 half cross-sections (11 across the middle half of the stroke, both
// sides), between 20% and 80% of the depth.
struct TrenchShape {
  double wall_angle_deg = 0.0;         // steepest fitted wall slope in cross-sections
  double wall_angle_mean_deg = 0.0;    // their mean
  double wall_angle_min_deg = 0.0;     // the gentlest
  double wall_angle_spread_deg = 0.0;  // their standard deviation
  int sections = 0;                    // half cross-sections with a fitted slope
  double depth_m = 0.0;                // median depth below the initial surface along the axis
  // The largest |wall angle - angle| over the sections.
  double worst_error_deg(double angle) const {
    return sections ? std::max(wall_angle_deg - angle, angle - wall_angle_min_deg) : 0.0;
  }
};
TrenchShape measure_trench(const Raster& heights, const Raster& initial, const Vec2& a, const Vec2& b);
// A ridge along a -> b: its flanks measured as the walls of a trench in the negated surface
// (depth_m is then the crest's height above the initial surface).
TrenchShape measure_ridge(const Raster& heights, const Raster& initial, const Vec2& a, const Vec2& b);

struct PlaneShape {
  double slope_deg = 0.0;    // of the least-squares plane over the middle half of the domain
  double azimuth_deg = 0.0;  // its downhill direction, counter-clockwise from +x, in (-180, 180]
  double rms_m = 0.0;        // residual of the fit
  // Local slopes at the raster samples of the same region (central differences over two
  // spacings), which the fit averages away: their mean and the steepest.
  double slope_mean_deg = 0.0;
  double slope_max_deg = 0.0;
  bool fitted = false;  // false: too few samples for a plane
};
PlaneShape measure_plane(const Raster& heights);

// Why the scene's reference cannot be measured on this lattice (the pile's expected foot, the
// crater's rim band or the middle half of a trench's or ridge's stroke not within it), or
// nullopt when it can.
std::optional<std::string> reference_problem(const Scene& scene, const StampSchedule& schedule, const Raster& lattice);

// The accuracy metrics (README "Summary metrics") for the scene's reference, as summary entries
// ("reference.rmse_m", "pile.flank_angle_deg", ...). Empty when the scene has none. Metrics that
// cannot be computed (reference_problem, no pile found within the raster, no trench wall, no
// plane) are absent, never numbers: only "reference" is given, and `warnings` says why.
nlohmann::ordered_json accuracy_metrics(const Scene& scene, const StampSchedule& schedule, const HeightField& initial,
                                        const Raster& initial_raster, const Raster& final_raster,
                                        std::vector<std::string>* warnings = nullptr);

}  // namespace sb
