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
//     The drop counted along that run is min(z_i - z_j, s r_j), s = |g| on a grid: at most
//     what the gradient predicts, so that the curvature of a convex surface (a cone's flank,
//     whose level lines bend away from the centre) does not count as slope (ErosionRule::
//     cap_drop). On a TIN, whose fan gradient averages facets up to an edge length away, s is
//     the steepest facet slope around the centre (SurfaceGradient::steepest: on a plane the
//     same), and the TIN caps only where the sand comes to rest (steps without a tool):
//     capped by |g| always, trench walls come out flatter than critical and the poured pile
//     lobed; capped by the steepest facet at rest, the pile's flank and the relaxed cones
//     come closer to critical, at the price of single trench sections a little steeper
//     (results/orientation_worst.md, results/pile_relax.md: the cap holds back transfers a
//     noisy facet would have made). A plane is then at rest at the
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
// number of passes. Each transfer changes heights by dz_i = -V / A_i, dz_j = +V / A_j, so
// A_i dz_i + A_j dz_j = 0: volume is conserved exactly (up to rounding).
//
// How much, and to whom. The counted neighbours share the transfer in proportion to
// c_j * excess_j, c_j the pair's conductance: a finite-volume flux, conductance times the excess
// height. The total is f times the largest pair excess, lowered if need be so that no pair gets
// more than f times its own volume excess e_j (so no pair is inverted for f <= 1). Conductances:
//   - NeighbourLayout::Stencil: equal (1): a regular grid's stencil, whose 8 directions with
//     equal weights already transport isotropically (sum_j e_j e_j^T = 6 h^2 I); with equal
//     areas the split is then in proportion to the pair excesses, as the grid kernel computes it.
//   - NeighbourLayout::Fan (a TIN vertex's ring, counter-clockwise): the cotangent weight
//     (cot a + cot b) / 2 of the angles facing the edge, the dual edge's length over the edge's,
//     for which sum_j c_j e_j e_j^T = 2 A I on any triangulation: transport without a preferred
//     direction. Splitting by volume excess instead (pair areas) sent the sand of a pour along
//     the mesh's directions: on pile.toml the TIN's cone came out lobed (roundness 0.075, RMSE
//     164 um, flank 26.8 degrees; 0.034, 75 um and 29.0 degrees with cotangent weights), and on
//     a regular lattice, whose diagonal edges have weight 0, elongated along the diagonal
//     (roundness 0.22). Weights are floored at kMinConductance (obtuse and border facets), so
//     a vertex whose only over-critical pair has weight 0 still gives to it.
//
// This header is inline on purpose: back-ends call it from their hot loops.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>
#include <string_view>

#include "common/material.hpp"

namespace sb {

enum class ErosionRuleKind { Gradient, Edge };

// How erosion_transfers' neighbours are laid out, which decides their conductances (above).
enum class NeighbourLayout { Stencil, Fan };
inline constexpr double kMinConductance = 1e-3;
inline std::string_view to_string(ErosionRuleKind k) { return k == ErosionRuleKind::Edge ? "edge" : "gradient"; }

struct ErosionRule {
  ErosionRuleKind kind = ErosionRuleKind::Edge;
  double tan_critical = 0.57735026918962573;  // tan(30 deg)
  // Slopes below tan_settle count as stable; tan_settle is slightly above tan_critical so
  // that relaxation ends in a finite number of passes (see erosion.settle_tolerance_deg).
  double tan_settle = 0.57735026918962573;
  double fraction = 0.5;
  // Gradient rule: count at most s r_j of the drop along a run, s = |g| or the gradient's
  // `steepest` (see above); the TIN sets it where the sand comes to rest.
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

// The surface gradient (dz/dx, dz/dy) at the centre: it points uphill. `steepest`: the
// slope that caps the drop counted along a run (ErosionRule::cap_drop) where it is not |g|
// (a TIN's steepest facet around the centre, fan_gradient); < 0: |g|.
struct SurfaceGradient {
  double x = 0.0, y = 0.0;
  double steepest = -1.0;
};

// Facet (centre, j, k), neighbours counter-clockwise: twice its area (`cross`) and twice its
// area times its gradient (`gx`, `gy`); false (outputs unset) when the pair spans 180 degrees
// or more and forms no facet. The gradient is (gx, gy) / cross. O(1).
inline bool facet_moment(double z_i, const ErosionNeighbour& j, const ErosionNeighbour& k, double& gx, double& gy,
                         double& cross) {
  // area * gradient = ((z_j - z_i) perp(e_k) - (z_k - z_i) perp(e_j)) / 2, perp(x, y) = (y, -x).
  cross = j.dx * k.dy - j.dy * k.dx;
  if (!(cross > 1e-9 * j.distance * k.distance)) return false;
  const double hj = j.z - z_i, hk = k.z - z_i;
  gx = hj * k.dy - hk * j.dy;
  gy = hk * j.dx - hj * k.dx;
  return true;
}

// Area-weighted mean of the facet gradients of the fan the centre forms with consecutive
// neighbours of `ring` (counter-clockwise around the centre, last to first included), and,
// `with_steepest`, the steepest facet's slope (`steepest`; else -1). Pairs that span 180
// degrees or more (the gap at a border vertex) form no facet and are skipped; zero (steepest
// 0) when none does. Exact for a plane. O(ring size).
inline SurfaceGradient fan_gradient(double z_i, std::span<const ErosionNeighbour> ring, bool with_steepest = false) {
  // One division per fan (facet_moment), the steepest compared squared and cross-multiplied.
  double sx = 0.0, sy = 0.0, area2 = 0.0, top2 = 0.0, top_cross2 = 1.0;
  const std::size_t n = ring.size();
  for (std::size_t a = 0; a < n && n >= 2; ++a) {
    double gx = 0.0, gy = 0.0, cross = 0.0;
    if (!facet_moment(z_i, ring[a], ring[a + 1 < n ? a + 1 : 0], gx, gy, cross)) continue;  // (no modulo)
    sx += gx;
    sy += gy;
    area2 += cross;
    if (!with_steepest) continue;
    const double g2 = gx * gx + gy * gy, c2 = cross * cross;
    if (g2 * top_cross2 > top2 * c2) top2 = g2, top_cross2 = c2;
  }
  if (area2 <= 0.0) return {.steepest = with_steepest ? 0.0 : -1.0};
  return {sx / area2, sy / area2, with_steepest ? std::sqrt(top2 / top_cross2) : -1.0};
}

// fan_gradient as a linear map of the height differences, for a caller that evaluates the same
// ring's gradient many times: fan_gradient(z_i, ring) = sum_k (cx[k], cy[k]) (ring[k].z - z_i),
// the coefficients from the ring's offsets alone (facet_moment's terms over twice the fan's
// area; zero when no pair forms a facet). `cx`, `cy`: the ring's size. O(ring size).
inline void fan_gradient_coefficients(std::span<const ErosionNeighbour> ring, std::span<double> cx,
                                      std::span<double> cy) {
  const std::size_t n = ring.size();
  std::fill(cx.begin(), cx.end(), 0.0);
  std::fill(cy.begin(), cy.end(), 0.0);
  double area2 = 0.0;
  for (std::size_t a = 0; a < n && n >= 2; ++a) {
    const std::size_t b = a + 1 < n ? a + 1 : 0;
    const ErosionNeighbour &p = ring[a], &q = ring[b];
    double gx = 0.0, gy = 0.0, cross = 0.0;
    if (!facet_moment(0.0, p, q, gx, gy, cross)) continue;
    area2 += cross;
    // facet_moment: gx = h_p q.dy - h_q p.dy, gy = h_q p.dx - h_p q.dx.
    cx[a] += q.dy;
    cy[a] -= q.dx;
    cx[b] -= p.dy;
    cy[b] += p.dx;
  }
  for (std::size_t a = 0; a < n; ++a) {
    cx[a] = area2 > 0.0 ? cx[a] / area2 : 0.0;
    cy[a] = area2 > 0.0 ? cy[a] / area2 : 0.0;
  }
}

// The cotangent weight of the edge from the centre to ring[k] in a counter-clockwise ring
// (NeighbourLayout::Fan): (cot a + cot b) / 2 over the facets beside it that exist, floored at
// kMinConductance. O(1).
inline double fan_conductance(std::span<const ErosionNeighbour> ring, std::size_t k) {
  const std::size_t n = ring.size();
  const ErosionNeighbour& j = ring[k];
  double c = 0.0;
  // Facet (centre, j, next) has j's edge facing the angle at next; facet (centre, prev, j) at prev.
  const ErosionNeighbour* sides[2] = {&ring[k + 1 < n ? k + 1 : 0], &ring[k > 0 ? k - 1 : n - 1]};
  for (int s = 0; s < 2 && n >= 2; ++s) {
    const ErosionNeighbour& o = *sides[s];
    const double cross = s == 0 ? j.dx * o.dy - j.dy * o.dx : o.dx * j.dy - o.dy * j.dx;
    if (!(cross > 1e-9 * j.distance * o.distance)) continue;  // no facet (a border's gap)
    // cot of the angle at o between (centre - o) and (j - o).
    c += 0.5 * (o.dx * o.dx + o.dy * o.dy - (o.dx * j.dx + o.dy * j.dy)) / cross;
  }
  return std::max(c, kMinConductance);
}

// Computes the volume (m^3, >= 0) the centre sends to each neighbour into `out` (same size
// as `nbrs`) and returns the total. Zero when every slope is stable. `gradient` is read by
// the gradient rule only; `layout` decides the conductances (above). `conductances` (Fan only,
// optional): fan_conductance(nbrs, k) for every k, computed beforehand by a caller that visits
// the same ring many times. O(neighbours).
inline double erosion_transfers(double z_i, double area_i, SurfaceGradient gradient,
                                std::span<const ErosionNeighbour> nbrs, const ErosionRule& rule, std::span<double> out,
                                NeighbourLayout layout = NeighbourLayout::Stencil,
                                const double* conductances = nullptr) {
  // Downhill unit vector, where the gradient rule applies.
  double ux = 0.0, uy = 0.0, steepness = 0.0;
  bool along_gradient = false;
  if (rule.kind == ErosionRuleKind::Gradient) {
    // The square root of the squared norm, as the grid kernel computes it: std::hypot's guard
    // against overflow is useless for slopes and cost about a seventh of a TIN visit's time.
    steepness = std::sqrt(gradient.x * gradient.x + gradient.y * gradient.y);
    if (steepness > rule.tan_settle) {
      ux = -gradient.x / steepness;
      uy = -gradient.y / steepness;
      along_gradient = true;
    }
  }
  const double margin = rule.tan_settle - rule.tan_critical;
  const double cap_slope = gradient.steepest >= 0.0 ? gradient.steepest : steepness;
  double largest = 0.0;
  double sum_excess = 0.0;
  double sum_share = 0.0, min_ratio = std::numeric_limits<double>::infinity();  // Fan only
  for (std::size_t k = 0; k < nbrs.size(); ++k) {
    const ErosionNeighbour& n = nbrs[k];
    out[k] = 0.0;
    const double drop = z_i - n.z;
    // The edge rule's excess, then the gradient rule's where it asks for more.
    double excess_h = drop > n.distance * rule.tan_settle ? drop - n.distance * rule.tan_critical : 0.0;
    const double run = along_gradient ? n.dx * ux + n.dy * uy : 0.0;
    if (run > 0.0) {
      const double along = (rule.cap_drop ? std::min(drop, cap_slope * run) : drop) - run * rule.tan_critical;
      if (along > n.distance * margin) excess_h = std::max(excess_h, along);
    }
    if (excess_h <= 0.0) continue;
    const double pair_weight = area_i * n.area / (area_i + n.area);
    const double excess_v = excess_h * pair_weight;
    sum_excess += excess_v;
    largest = std::max(largest, excess_v);
    if (layout == NeighbourLayout::Stencil) {
      out[k] = excess_v;
    } else {
      const double c = conductances ? conductances[k] : fan_conductance(nbrs, k);
      out[k] = c * excess_h;  // the share
      sum_share += out[k];
      min_ratio = std::min(min_ratio, pair_weight / c);  // e_j / share_j
    }
  }
  if (sum_excess <= 0.0) return 0.0;
  // Stencil: shares in proportion to the volume excesses (equal conductances, and on the grid
  // equal areas), which never gives a pair more than f e_j. Fan: shares c_j x_j; total f * largest
  // unless that would give some pair more than f e_j (total <= f e_j sum_share / share_j).
  const bool fan = layout == NeighbourLayout::Fan;
  const double total = rule.fraction * (fan ? std::min(largest, sum_share * min_ratio) : largest);
  const double scale = total / (fan ? sum_share : sum_excess);
  for (std::size_t k = 0; k < nbrs.size(); ++k) out[k] *= scale;
  return total;
}

}  // namespace sb
