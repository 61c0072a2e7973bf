#pragma once
// The one erosion rule (README "Architecture"), stated once for every back-end, in two variants.
//
// Between a centre i and a neighbour j, material moves from the higher to the lower when the
// drop z_i - z_j exceeds the drop the critical slope allows over a run r_j:
//   - edge rule (the paper's, and the related work's): r_j = d_ij, the horizontal distance.
//     A surface at rest then stands up to atan(tan(crit) / cos(a)) where its downhill
//     direction lies at an angle a from the nearest neighbour direction (32 deg on an
//     8-neighbour grid at 22.5 deg, 39 deg on a 4-neighbour grid at 45 deg).
//   - gradient rule: the edge rule, and in addition, where the surface gradient
//     at the centre g (an input: central differences on a grid, area-weighted facet gradients
//     on a TIN) is steeper than tan_settle, a run toward each neighbour on the downhill side
//     equal to its offset projected on the downhill direction u = -g / |g|: r_j = e_ij . u.
//     The drop counted along that run is min(z_i - z_j, |g| r_j): at most what the gradient
//     predicts, so that the curvature of a convex surface (a cone's flank, whose level lines
//     bend away from the centre) does not count as slope (ErosionRule::cap_drop; on a TIN,
//     whose fan gradient averages facets up to an edge length away, the TIN drops the cap:
//     measured on trench_azimuth.toml at 0..90 degrees, the cap leaves the TIN's single
//     cross-sections up to 2.2 degrees flatter than critical, against 1.7 without it, and
//     the mean of the sections 0.30 against 0.18). A plane is then at rest at the
//     critical angle in every azimuth and a steeper plane is not; where |g| <= tan_settle
//     (peaks, pits, kinks, gentle slopes) and toward neighbours sideways or uphill of u, only
//     the edge rule acts, so no edge ever rests steeper than under the edge rule. The
//     gradient only chooses the runs; the amounts stay pairwise and downhill (as in
//     D-infinity flow routing, Tarboton 1997, where the direction comes from the facets).
//
// The pair's excess height is the larger of the two rules' (drop - r_j tan(crit)); its volume
// excess -- the volume that, moved from i to j, would bring the pair exactly to the allowed
// drop -- is e_j = excess * A_i A_j / (A_i + A_j). A pair counts only when its excess height is
// above d_ij (tan_settle - tan_critical): every transfer then moves at least a fixed volume
// downhill, the potential energy falls by a fixed amount, and relaxation ends in a finite
// number of passes. The centre gives away a fraction f of the largest pair excess, split among
// the counted neighbours in proportion to their excess. Each transfer changes heights by
// dz_i = -V / A_i, dz_j = +V / A_j, so A_i dz_i + A_j dz_j = 0: volume is conserved exactly
// (up to rounding).
//
// This header is inline on purpose: back-ends call it from their hot loops.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>
#include <string_view>

#include "common/material.hpp"

namespace sb {

enum class ErosionRuleKind { Gradient, Edge };
inline std::string_view to_string(ErosionRuleKind k) { return k == ErosionRuleKind::Edge ? "edge" : "gradient"; }

struct ErosionRule {
  ErosionRuleKind kind = ErosionRuleKind::Edge;
  double tan_critical = 0.57735026918962573;  // tan(30 deg)
  // Slopes below tan_settle count as stable; tan_settle is slightly above tan_critical so
  // that relaxation ends in a finite number of passes (see erosion.settle_tolerance_deg).
  double tan_settle = 0.57735026918962573;
  double fraction = 0.5;
  // Gradient rule: count at most |g| r_j of the drop along a run (see above); the grid's
  // central differences are smooth enough for it, the TIN's fan gradients are not.
  bool cap_drop = true;

  // Whether erosion_transfers reads its gradient argument (back-ends skip computing it if not).
  bool needs_gradient() const { return kind == ErosionRuleKind::Gradient; }

  static ErosionRule from(const Material& m, double settle_tolerance_deg,
                          ErosionRuleKind kind = ErosionRuleKind::Edge) {
    ErosionRule r;
    r.kind = kind;
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
  // Horizontal offset from the centre to the neighbour, m (|(dx, dy)| = distance). Zero
  // offsets make the gradient rule treat the neighbour by the edge rule.
  double dx = 0.0, dy = 0.0;
};

// The surface gradient (dz/dx, dz/dy) at the centre: it points uphill.
struct SurfaceGradient {
  double x = 0.0, y = 0.0;
};

// Area-weighted mean of the facet gradients of the fan the centre forms with consecutive
// neighbours of `ring` (counter-clockwise around the centre, last to first included). Pairs
// that span 180 degrees or more (the gap at a border vertex) form no facet and are skipped;
// zero when none does. Exact for a plane. O(ring size).
inline SurfaceGradient fan_gradient(double z_i, std::span<const ErosionNeighbour> ring) {
  // For a facet (i, j, k): area * gradient = ((z_j - z_i) perp(e_k) - (z_k - z_i) perp(e_j)) / 2,
  // perp(x, y) = (y, -x); no division per facet.
  double sx = 0.0, sy = 0.0, area2 = 0.0;
  const std::size_t n = ring.size();
  for (std::size_t a = 0; a < n && n >= 2; ++a) {
    const ErosionNeighbour& j = ring[a];
    const ErosionNeighbour& k = ring[a + 1 < n ? a + 1 : 0];  // (no division in the hot loop)
    const double cross = j.dx * k.dy - j.dy * k.dx;
    if (!(cross > 1e-9 * j.distance * k.distance)) continue;
    const double hj = j.z - z_i, hk = k.z - z_i;
    sx += hj * k.dy - hk * j.dy;
    sy += hk * j.dx - hj * k.dx;
    area2 += cross;
  }
  if (area2 <= 0.0) return {};
  return {sx / area2, sy / area2};
}

// Computes the volume (m^3, >= 0) the centre sends to each neighbour into `out` (same size
// as `nbrs`) and returns the total. Zero when every slope is stable. `gradient` is read by
// the gradient rule only. O(neighbours).
inline double erosion_transfers(double z_i, double area_i, SurfaceGradient gradient,
                                std::span<const ErosionNeighbour> nbrs, const ErosionRule& rule,
                                std::span<double> out) {
  // Downhill unit vector, where the gradient rule applies.
  double ux = 0.0, uy = 0.0, steepness = 0.0;
  bool along_gradient = false;
  if (rule.kind == ErosionRuleKind::Gradient) {
    // Most centres are gentler than tan_settle, and hypot is the costliest call here: the
    // squared norm tells so first where it is below tan_settle^2 by far more than its rounding
    // (the result is then the same as with hypot).
    const double g2 = gradient.x * gradient.x + gradient.y * gradient.y;
    const bool clearly_gentle = rule.tan_settle > 1e-100 && g2 < (1.0 - 1e-12) * rule.tan_settle * rule.tan_settle;
    steepness = clearly_gentle ? 0.0 : std::hypot(gradient.x, gradient.y);
    if (steepness > rule.tan_settle) {
      ux = -gradient.x / steepness;
      uy = -gradient.y / steepness;
      along_gradient = true;
    }
  }
  const double margin = rule.tan_settle - rule.tan_critical;
  double largest = 0.0;
  double sum_excess = 0.0;
  for (std::size_t k = 0; k < nbrs.size(); ++k) {
    const ErosionNeighbour& n = nbrs[k];
    out[k] = 0.0;
    const double drop = z_i - n.z;
    // The edge rule's excess, then the gradient rule's where it asks for more.
    double excess_h = drop > n.distance * rule.tan_settle ? drop - n.distance * rule.tan_critical : 0.0;
    const double run = along_gradient ? n.dx * ux + n.dy * uy : 0.0;
    if (run > 0.0) {
      const double along = (rule.cap_drop ? std::min(drop, steepness * run) : drop) - run * rule.tan_critical;
      if (along > n.distance * margin) excess_h = std::max(excess_h, along);
    }
    if (excess_h <= 0.0) continue;
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
