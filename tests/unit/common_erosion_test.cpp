#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include "common/erosion.hpp"

namespace sb {
namespace {

ErosionRule rule30(double fraction = 0.5, ErosionRuleKind kind = ErosionRuleKind::Gradient, double settle_deg = 0.0) {
  Material m;
  m.critical_angle_deg = 30.0;
  m.transfer_fraction = fraction;
  return ErosionRule::from(m, settle_deg, kind);
}

// The ring of neighbours of the origin on z = slope * (-u . p), u the downhill direction at
// `azimuth_deg`: 8 grid neighbours (spacing h), or an irregular counter-clockwise ring.
std::vector<ErosionNeighbour> plane_ring(double slope, double azimuth_deg, bool irregular) {
  const double a = azimuth_deg * std::numbers::pi / 180.0;
  const double ux = std::cos(a), uy = std::sin(a);
  const double h = 0.0025;
  std::vector<ErosionNeighbour> ring;
  const int count = irregular ? 7 : 8;
  for (int k = 0; k < count; ++k) {
    double angle = 2.0 * std::numbers::pi * k / count, r = h;
    if (irregular) {
      angle += 0.35 * std::sin(3.1 * k);
      r *= 1.0 + 0.4 * std::cos(1.7 * k);
    } else if (k % 2 == 1) {
      r *= std::sqrt(2.0);
    }
    const double dx = r * std::cos(angle), dy = r * std::sin(angle);
    ring.push_back({-slope * (ux * dx + uy * dy), r, h * h, dx, dy});
  }
  return ring;
}

double transfers_on_plane(double slope_deg, double azimuth_deg, bool irregular, const ErosionRule& rule) {
  const auto ring = plane_ring(std::tan(deg_to_rad(slope_deg)), azimuth_deg, irregular);
  std::vector<double> out(ring.size());
  return erosion_transfers(0.0, 0.0025 * 0.0025, fan_gradient(0.0, ring), ring, rule, out);
}

TEST(ErosionRule, NothingMovesBelowTheCriticalSlope) {
  const double d = 0.01;
  const double just_below = d * std::tan(deg_to_rad(29.9));
  std::array<ErosionNeighbour, 2> n{{{0.0, d, 1e-4}, {0.0, d, 1e-4}}};
  std::array<double, 2> out{};
  EXPECT_EQ(erosion_transfers(just_below, 1e-4, {}, n, rule30(), out), 0.0);
  EXPECT_EQ(out[0], 0.0);
  const double just_above = d * std::tan(deg_to_rad(30.1));
  EXPECT_GT(erosion_transfers(just_above, 1e-4, {}, n, rule30(), out), 0.0);
}

TEST(ErosionRule, TransfersConserveVolumeWithUnequalAreas) {
  const double zi = 0.05, ai = 3e-5;
  std::array<ErosionNeighbour, 3> n{{{0.0, 0.01, 1e-5}, {0.02, 0.012, 4e-5}, {0.06, 0.01, 2e-5}}};
  std::array<double, 3> out{};
  const double total = erosion_transfers(zi, ai, {}, n, rule30(), out);
  ASSERT_GT(total, 0.0);
  EXPECT_EQ(out[2], 0.0);  // higher neighbour receives nothing
  // Height changes A_i dz_i + sum A_j dz_j = 0.
  const double dzi = -total / ai;
  double balance = ai * dzi;
  for (std::size_t k = 0; k < n.size(); ++k) balance += n[k].area * (out[k] / n[k].area);
  EXPECT_NEAR(balance, 0.0, 1e-20);
  EXPECT_NEAR(out[0] + out[1] + out[2], total, 1e-18);
}

TEST(ErosionRule, SplitInProportionToExcessAndNeverOvershootsTheSteepestPair) {
  const double a = 1e-4, d = 0.01, t = std::tan(deg_to_rad(30.0));
  std::array<ErosionNeighbour, 2> n{{{0.0, d, a}, {0.004, d, a}}};
  std::array<double, 2> out{};
  const double zi = 0.02;
  const double total = erosion_transfers(zi, a, {}, n, rule30(1.0), out);
  const double e0 = (zi - 0.0 - d * t) * a / 2, e1 = (zi - 0.004 - d * t) * a / 2;
  EXPECT_NEAR(out[0] / out[1], e0 / e1, 1e-12);
  EXPECT_NEAR(total, e0, 1e-18);  // fraction 1 of the largest pair excess
  // The steepest pair gets gentler but not below the critical slope (no overshoot).
  const double zi_after = zi - total / a, z0_after = 0.0 + out[0] / a;
  EXPECT_GE((zi_after - z0_after) / d, t - 1e-12);
  EXPECT_LT((zi_after - z0_after) / d, (zi - 0.0) / d);
}

TEST(ErosionRule, SettleToleranceWidensTheStableBand) {
  Material m;
  const ErosionRule r = ErosionRule::from(m, 0.5);
  EXPECT_NEAR(r.tan_settle, std::tan(deg_to_rad(30.5)), 1e-15);
  const double d = 0.01;
  std::array<ErosionNeighbour, 1> n{{{0.0, d, 1e-4}}};
  std::array<double, 1> out{};
  EXPECT_EQ(erosion_transfers(d * std::tan(deg_to_rad(30.3)), 1e-4, {}, n, r, out), 0.0);
}

TEST(ErosionRule, FanGradientIsExactOnPlanesAndIgnoresTheBorderGap) {
  for (bool irregular : {false, true})
    for (double az : {0.0, 22.5, 45.0, 101.0, 250.0}) {
      const auto ring = plane_ring(0.7, az, irregular);
      const SurfaceGradient g = fan_gradient(0.0, ring);
      const double a = az * std::numbers::pi / 180.0;
      EXPECT_NEAR(g.x, -0.7 * std::cos(a), 1e-12) << az;
      EXPECT_NEAR(g.y, -0.7 * std::sin(a), 1e-12) << az;
    }
  // A border vertex: neighbours over a half-turn only; the pair across the outside (180
  // degrees) is no facet.
  std::vector<ErosionNeighbour> half{{0.1, 1.0, 1.0, 1.0, 0.0}, {0.2, 1.0, 1.0, 0.0, 1.0}, {-0.1, 1.0, 1.0, -1.0, 0.0}};
  const SurfaceGradient g = fan_gradient(0.0, half);
  EXPECT_NEAR(g.x, 0.1, 1e-15);
  EXPECT_NEAR(g.y, 0.2, 1e-15);
  EXPECT_EQ(fan_gradient(0.0, std::span(half).first(1)).x, 0.0);
}

// The coefficients give fan_gradient's answer for any heights, the border vertex's gap included.
TEST(ErosionRule, FanGradientCoefficientsReproduceTheFanGradient) {
  std::vector<ErosionNeighbour> ring = plane_ring(0.7, 101.0, true);
  std::vector<ErosionNeighbour> half{{0.1, 1.0, 1.0, 1.0, 0.0}, {0.2, 1.0, 1.0, 0.0, 1.0}, {-0.1, 1.0, 1.0, -1.0, 0.0}};
  for (std::vector<ErosionNeighbour>* r : {&ring, &half}) {
    for (std::size_t k = 0; k < r->size(); ++k) (*r)[k].z = 0.05 * std::sin(3.0 * k + 1.0);  // not a plane
    std::vector<double> cx(r->size()), cy(r->size());
    fan_gradient_coefficients(*r, cx, cy);
    const double z_i = 0.02;
    SurfaceGradient linear;
    for (std::size_t k = 0; k < r->size(); ++k) {
      linear.x += cx[k] * ((*r)[k].z - z_i);
      linear.y += cy[k] * ((*r)[k].z - z_i);
    }
    const SurfaceGradient g = fan_gradient(z_i, *r);
    EXPECT_NEAR(linear.x, g.x, 1e-12);
    EXPECT_NEAR(linear.y, g.y, 1e-12);
  }
}

// The gradient rule's promise: a plane at the critical angle rests in every azimuth, a
// steeper one does not; the edge rule lets planes between neighbour directions stand steeper.
TEST(ErosionRule, GradientRuleRestsPlanesAtTheCriticalAngleInEveryAzimuth) {
  ErosionRule gradient = rule30(0.5, ErosionRuleKind::Gradient, 0.1);
  const ErosionRule edge = rule30(0.5, ErosionRuleKind::Edge, 0.1);
  for (bool cap : {true, false})  // on a plane the drop is what the gradient predicts
    for (bool irregular : {false, true})
      for (double az = 0.0; az < 360.0; az += 7.5) {
        gradient.cap_drop = cap;
        EXPECT_EQ(transfers_on_plane(30.0, az, irregular, gradient), 0.0) << az;
        EXPECT_EQ(transfers_on_plane(29.0, az, irregular, gradient), 0.0) << az;
        EXPECT_GT(transfers_on_plane(30.3, az, irregular, gradient), 0.0) << az;
      }
  gradient.cap_drop = true;
  // 22.5 degrees off the grid's directions: the edge rule holds 31.5 degrees, the gradient
  // rule does not.
  EXPECT_EQ(transfers_on_plane(31.5, 22.5, false, edge), 0.0);
  EXPECT_GT(transfers_on_plane(31.5, 22.5, false, gradient), 0.0);
  EXPECT_GT(transfers_on_plane(30.3, 0.0, false, edge), 0.0);
}

TEST(ErosionRule, GradientRuleSendsOnlyDownhillAndConservesVolume) {
  const ErosionRule rule = rule30(1.0);
  for (double az : {0.0, 22.5, 67.0, 200.0}) {
    const auto ring = plane_ring(std::tan(deg_to_rad(40.0)), az, true);
    std::vector<double> out(ring.size());
    const double total = erosion_transfers(0.0, 1e-5, fan_gradient(0.0, ring), ring, rule, out);
    ASSERT_GT(total, 0.0);
    double sum = 0.0;
    for (std::size_t k = 0; k < ring.size(); ++k) {
      if (out[k] > 0.0) {
        EXPECT_LT(ring[k].z, 0.0) << "sand sent uphill at azimuth " << az;
      }
      EXPECT_GE(out[k], 0.0);
      sum += out[k];
    }
    EXPECT_NEAR(sum, total, 1e-15 * total);
  }
}

// A neighbour 60 degrees off the downhill direction and lower than the plane predicts (a
// convex surface): with the cap it counts only the gradient's drop, without it its own.
TEST(ErosionRule, CapDropCountsAtMostTheGradientsDrop) {
  ErosionRule rule = rule30(0.5, ErosionRuleKind::Gradient);
  const double d = 0.01, s = std::tan(deg_to_rad(31.0));
  const double dx = d * 0.5, dy = d * std::sqrt(3.0) / 2.0;          // run d / 2 along +x
  std::array<ErosionNeighbour, 1> n{{{-0.4 * d, d, 1e-4, dx, dy}}};  // drop 0.4 d < d tan 30
  std::array<double, 1> out{};
  const SurfaceGradient g{-s, 0.0};  // downhill +x at 31 degrees
  const double capped = erosion_transfers(0.0, 1e-4, g, n, rule, out);
  rule.cap_drop = false;
  const double full = erosion_transfers(0.0, 1e-4, g, n, rule, out);
  const double a = 1e-4 * 1e-4 / 2e-4;  // A_i A_j / (A_i + A_j)
  EXPECT_NEAR(capped, 0.5 * (s - std::tan(deg_to_rad(30.0))) * 0.5 * d * a, 1e-18);
  EXPECT_NEAR(full, 0.5 * (0.4 * d - 0.5 * d * std::tan(deg_to_rad(30.0))) * a, 1e-18);
}

// The TIN's cap (ErosionRule::cap_drop with SurfaceGradient::steepest, the steepest facet):
// on a plane every facet has the plane's slope, so it caps as the gradient does; on a cone's
// flank, whose level lines bend away from the apex, sideways neighbours lie lower than the slope
// predicts, and uncapped that curvature counts as slope: a vertex 20 mm from the apex with
// neighbours 7 mm away sent 2-6.5x what a plane of the same slope sends, capped 1.3-2.8x.
TEST(ErosionRule, SteepestFacetCapsTheConesCurvature) {
  for (double az : {0.0, 40.0, 135.0}) {
    const auto ring = plane_ring(0.6, az, true);
    const SurfaceGradient g = fan_gradient(0.0, ring, true);
    EXPECT_NEAR(g.steepest, 0.6, 1e-12) << az;
    EXPECT_NEAR(g.steepest, std::hypot(g.x, g.y), 1e-12) << az;
    EXPECT_EQ(fan_gradient(0.0, ring).steepest, -1.0);  // not asked for
  }
  ErosionRule rule = rule30();
  for (double deg : {30.5, 31.0, 32.0}) {
    const double t = std::tan(deg_to_rad(deg)), apex = 0.02, d = 0.007;
    std::vector<ErosionNeighbour> cone;
    for (int k = 0; k < 7; ++k) {
      const double a = 2.0 * std::numbers::pi * k / 7.0 + 0.2, dx = d * std::cos(a), dy = d * std::sin(a);
      cone.push_back({-t * (std::hypot(apex + dx, dy) - apex), d, 4e-5, dx, dy});
    }
    std::vector<double> out(cone.size());
    rule.cap_drop = false;
    const double uncapped = erosion_transfers(0.0, 4e-5, fan_gradient(0.0, cone), cone, rule, out);
    rule.cap_drop = true;
    const SurfaceGradient g = fan_gradient(0.0, cone, true);
    EXPECT_GT(g.steepest, t) << deg;  // a facet with an inner vertex is steeper than the cone
    const double capped = erosion_transfers(0.0, 4e-5, g, cone, rule, out);
    EXPECT_GT(capped, 0.0) << deg;  // steeper than critical: it still flows
    EXPECT_LT(capped, 0.7 * uncapped) << deg;
  }
}

// erosion_transfers takes the gradient rule's branch exactly where sqrt(gx^2 + gy^2) > tan_settle,
// as the grid kernel decides it (grid/erosion_kernel.hpp), also within rounding of the threshold.
TEST(ErosionRule, GradientRuleDecidesSteepnessAsTheGridKernelDoes) {
  const ErosionRule rule = rule30(0.5, ErosionRuleKind::Gradient);  // tan_settle = tan_critical
  const double d = 0.01;
  std::array<double, 1> out{};
  int steep = 0, gentle = 0;
  for (double azimuth_deg = 0.0; azimuth_deg < 360.0; azimuth_deg += 7.3) {
    const double a = deg_to_rad(azimuth_deg), ux = std::cos(a), uy = std::sin(a);
    // A neighbour 60 degrees off the downhill direction u, lower than the edge rule allows
    // for: only the gradient rule (run d / 2 along u) moves anything to it.
    const double nx = d * (0.5 * ux - std::sqrt(0.75) * uy), ny = d * (0.5 * uy + std::sqrt(0.75) * ux);
    const std::array<ErosionNeighbour, 1> n{{{-0.9 * d * rule.tan_critical, d, 1e-4, nx, ny}}};
    for (double r : {1.0 - 1e-6, 1.0 - 1e-12, 1.0 - 4e-16, 1.0, 1.0 + 4e-16, 1.0 + 1e-12, 1.0 + 1e-6}) {
      const SurfaceGradient g{-r * rule.tan_settle * ux, -r * rule.tan_settle * uy};
      const bool moved = erosion_transfers(0.0, 1e-4, g, n, rule, out) > 0.0;
      EXPECT_EQ(moved, std::sqrt(g.x * g.x + g.y * g.y) > rule.tan_settle)
          << "azimuth " << azimuth_deg << ", ratio " << r;
      (moved ? steep : gentle) += 1;
    }
  }
  EXPECT_GT(steep, 100);
  EXPECT_GT(gentle, 100);
}

TEST(ErosionRule, EdgeRuleIgnoresTheGradient) {
  const ErosionRule edge = rule30(0.5, ErosionRuleKind::Edge);
  const double d = 0.01;
  std::array<ErosionNeighbour, 1> n{{{0.0, d, 1e-4, d, 0.0}}};
  std::array<double, 1> out{};
  EXPECT_EQ(erosion_transfers(d * std::tan(deg_to_rad(29.9)), 1e-4, {-5.0, 0.0}, n, edge, out), 0.0);
  EXPECT_FALSE(edge.needs_gradient());
  EXPECT_TRUE(rule30().needs_gradient());
}

}  // namespace
}  // namespace sb
