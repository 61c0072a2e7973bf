#pragma once
// The one erosion rule (README "Architecture"), stated once for every back-end.
//
// Between a centre i and a neighbour j at horizontal distance d, material moves from the
// higher to the lower when (z_i - z_j) / d > tan(critical angle). The pair's volume
// excess -- the volume that, moved from i to j, would bring the pair exactly to the critical
// slope -- is e_j = (z_i - z_j - d tan) * A_i A_j / (A_i + A_j). The centre gives away a
// fraction f of the largest pair excess, split among its lower neighbours in proportion to
// their excess. Each transfer changes heights by dz_i = -V / A_i, dz_j = +V / A_j, so
// A_i dz_i + A_j dz_j = 0: volume is conserved exactly (up to rounding).
//
// This header is inline on purpose: back-ends call it from their hot loops.
#include <algorithm>
#include <cstddef>
#include <span>

#include "common/material.hpp"

namespace sb {

struct ErosionRule {
  double tan_critical = 0.57735026918962573;  // tan(30 deg)
  // Slopes below tan_settle count as stable; tan_settle is slightly above tan_critical so
  // that relaxation ends in a finite number of passes (see erosion.settle_tolerance_deg).
  double tan_settle = 0.57735026918962573;
  double fraction = 0.5;

  static ErosionRule from(const Material& m, double settle_tolerance_deg) {
    ErosionRule r;
    r.tan_critical = m.tan_critical();
    r.tan_settle = std::tan(deg_to_rad(m.critical_angle_deg + settle_tolerance_deg));
    r.fraction = m.transfer_fraction;
    return r;
  }
};

struct ErosionNeighbour {
  double z;         // neighbour height, m
  double distance;  // horizontal distance to the centre, m
  double area;      // the neighbour's area weight, m^2 (cell area or barycentric area)
};

// Computes the volume (m^3, >= 0) the centre sends to each neighbour into `out` (same size
// as `nbrs`) and returns the total. Zero when every slope is stable. O(neighbours).
inline double erosion_transfers(double z_i, double area_i, std::span<const ErosionNeighbour> nbrs,
                                const ErosionRule& rule, std::span<double> out) {
  double largest = 0.0;
  double sum_excess = 0.0;
  for (std::size_t k = 0; k < nbrs.size(); ++k) {
    const ErosionNeighbour& n = nbrs[k];
    out[k] = 0.0;
    const double drop = z_i - n.z;
    if (drop <= n.distance * rule.tan_settle) continue;
    const double excess_h = drop - n.distance * rule.tan_critical;
    const double excess_v = excess_h * area_i * n.area / (area_i + n.area);
    out[k] = excess_v;
    sum_excess += excess_v;
    largest = std::max(largest, excess_v);
  }
  if (sum_excess <= 0.0) return 0.0;
  const double total = rule.fraction * largest;
  const double scale = total / sum_excess;
  for (std::size_t k = 0; k < nbrs.size(); ++k) out[k] *= scale;
  return total;
}

}  // namespace sb
