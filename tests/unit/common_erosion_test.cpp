#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "common/erosion.hpp"

namespace sb {
namespace {

ErosionRule rule30(double fraction = 0.5) {
  Material m;
  m.critical_angle_deg = 30.0;
  m.transfer_fraction = fraction;
  return ErosionRule::from(m, 0.0);
}

TEST(ErosionRule, NothingMovesBelowTheCriticalSlope) {
  const double d = 0.01;
  const double just_below = d * std::tan(deg_to_rad(29.9));
  std::array<ErosionNeighbour, 2> n{{{0.0, d, 1e-4}, {0.0, d, 1e-4}}};
  std::array<double, 2> out{};
  EXPECT_EQ(erosion_transfers(just_below, 1e-4, n, rule30(), out), 0.0);
  EXPECT_EQ(out[0], 0.0);
  const double just_above = d * std::tan(deg_to_rad(30.1));
  EXPECT_GT(erosion_transfers(just_above, 1e-4, n, rule30(), out), 0.0);
}

TEST(ErosionRule, TransfersConserveVolumeWithUnequalAreas) {
  const double zi = 0.05, ai = 3e-5;
  std::array<ErosionNeighbour, 3> n{{{0.0, 0.01, 1e-5}, {0.02, 0.012, 4e-5}, {0.06, 0.01, 2e-5}}};
  std::array<double, 3> out{};
  const double total = erosion_transfers(zi, ai, n, rule30(), out);
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
  const double total = erosion_transfers(zi, a, n, rule30(1.0), out);
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
  EXPECT_EQ(erosion_transfers(d * std::tan(deg_to_rad(30.3)), 1e-4, n, r, out), 0.0);
}

}  // namespace
}  // namespace sb
