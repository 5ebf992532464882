#include "detector/accumulator_list.h"

#include <gtest/gtest.h>

#include <cmath>

#include "base/angles.h"

namespace oal {
namespace {

constexpr double kTol = 1e-9;

// Votes for the line (rho, theta) as the detector does: with its unit normal.
int VoteFor(OrderedAccumulatorList* list, double rho, double theta, int border = 0) {
  return list->Vote(std::cos(theta), std::sin(theta), rho, border);
}

TEST(OrderedAccumulatorList, NewEntryHasWeightOneCountZero) {
  OrderedAccumulatorList list(2 * kRadPerDeg, 4.0, 20, 40);
  EXPECT_EQ(VoteFor(&list, 10.0, 0.5), 0);
  ASSERT_EQ(list.entries().size(), 1u);
  EXPECT_EQ(list.entries()[0].weight, 1);
  EXPECT_EQ(list.entries()[0].count, 0);
  EXPECT_NEAR(list.entries()[0].Line().theta_rad, 0.5, kTol);
  EXPECT_NEAR(list.entries()[0].rho_px, 10.0, kTol);
}

TEST(OrderedAccumulatorList, MatchesAverageWeightedByPriorVotes) {
  OrderedAccumulatorList list(2 * kRadPerDeg, 4.0, 20, 40);
  VoteFor(&list, 10.0, 0.50);
  EXPECT_EQ(VoteFor(&list, 12.0, 0.51), 0);  // (10*1 + 12) / 2, (0.50*1 + 0.51) / 2
  EXPECT_NEAR(list.entries()[0].rho_px, 11.0, kTol);
  EXPECT_NEAR(list.entries()[0].Line().theta_rad, 0.505, kTol);
  EXPECT_EQ(VoteFor(&list, 14.0, 0.52), 0);  // (11*2 + 14) / 3, (0.505*2 + 0.52) / 3
  EXPECT_NEAR(list.entries()[0].rho_px, 12.0, kTol);
  EXPECT_NEAR(list.entries()[0].Line().theta_rad, 0.51, kTol);
  EXPECT_NEAR(list.entries()[0].cos_theta, std::cos(0.51), kTol);
  EXPECT_NEAR(list.entries()[0].sin_theta, std::sin(0.51), kTol);
  EXPECT_EQ(list.entries()[0].weight, 3);
}

// With a wide anglechange (Check() allows up to 45 deg) the mean is still exact: the step's
// angle and rotation leave the small-angle series for the library functions.
TEST(OrderedAccumulatorList, WideAngleChangeStillAveragesExactly) {
  OrderedAccumulatorList list(40 * kRadPerDeg, 4.0, 20, 40);
  VoteFor(&list, 10.0, 0.5);
  EXPECT_EQ(VoteFor(&list, 12.0, 0.5 + 35 * kRadPerDeg), 0);
  EXPECT_NEAR(list.entries()[0].Line().theta_rad, 0.5 + 17.5 * kRadPerDeg, kTol);
  EXPECT_EQ(VoteFor(&list, 11.0, 0.5 + 3 * kRadPerDeg), 0);  // (2 * 17.5 + 3) / 3 = 12.67 deg
  EXPECT_NEAR(list.entries()[0].Line().theta_rad, 0.5 + (38.0 / 3.0) * kRadPerDeg, kTol);
  EXPECT_NEAR(std::hypot(list.entries()[0].cos_theta, list.entries()[0].sin_theta), 1.0, 1e-15);
}

TEST(OrderedAccumulatorList, ThresholdsOfEquationsOneAndTwo) {
  OrderedAccumulatorList list(2 * kRadPerDeg, 4.0, 20, 40);
  VoteFor(&list, 10.0, 0.5);
  EXPECT_EQ(VoteFor(&list, 10.0, 0.5 + 2.1 * kRadPerDeg), 1);  // angle just beyond anglechange
  EXPECT_EQ(VoteFor(&list, 14.5, 0.5), 2);                     // rho just beyond rchange
  EXPECT_EQ(VoteFor(&list, 13.9, 0.5 + 1.9 * kRadPerDeg), 0);  // within both
}

TEST(OrderedAccumulatorList, AveragesAcrossTheThetaWrap) {
  OrderedAccumulatorList list(2 * kRadPerDeg, 4.0, 20, 40);
  VoteFor(&list, 5.0, 0.01);
  // theta = pi - 0.01 with rho = -5 is theta = -0.01 with rho = 5: the same family.
  EXPECT_EQ(VoteFor(&list, -5.0, kPi - 0.01), 0);
  EXPECT_NEAR(list.entries()[0].Line().theta_rad, 0.0, kTol);
  EXPECT_NEAR(list.entries()[0].rho_px, 5.0, kTol);
  // Another vote at -0.02 pulls the mean below 0: it is stored as pi - 0.00667, rho -5.
  EXPECT_EQ(VoteFor(&list, -5.0, kPi - 0.02), 0);
  EXPECT_NEAR(list.entries()[0].Line().theta_rad, kPi - 0.02 / 3.0, kTol);
  EXPECT_NEAR(list.entries()[0].rho_px, -5.0, kTol);
  EXPECT_GE(list.entries()[0].Line().theta_rad, 0.0);
  EXPECT_LT(list.entries()[0].Line().theta_rad, kPi);
}

TEST(OrderedAccumulatorList, ReordersByWeightMinusHalfCount) {
  OrderedAccumulatorList list(1 * kRadPerDeg, 2.0, 20, 40);
  VoteFor(&list, 0.0, 0.2);   // A: 1 vote
  VoteFor(&list, 50.0, 1.0);  // B: 3 votes
  VoteFor(&list, 50.0, 1.0);
  VoteFor(&list, 50.0, 1.0);
  VoteFor(&list, 90.0, 2.0);  // C: 2 votes
  VoteFor(&list, 90.0, 2.0);
  list.EndBorder([](const OalEntry&) { return true; });
  ASSERT_EQ(list.entries().size(), 3u);
  EXPECT_NEAR(list.entries()[0].rho_px, 50.0, kTol);  // 3 - 0.5
  EXPECT_NEAR(list.entries()[1].rho_px, 90.0, kTol);  // 2 - 0.5
  EXPECT_NEAR(list.entries()[2].rho_px, 0.0, kTol);   // 1 - 0.5
  for (const OalEntry& entry : list.entries()) EXPECT_EQ(entry.count, 1);
}

TEST(OrderedAccumulatorList, MostLikelyEntryGetsTheVote) {
  OrderedAccumulatorList list(3 * kRadPerDeg, 4.0, 20, 40);
  VoteFor(&list, 0.0, 1.0);  // weak entry first
  VoteFor(&list, 7.0, 1.0);  // strong entry
  VoteFor(&list, 7.0, 1.0);
  list.EndBorder([](const OalEntry&) { return true; });
  ASSERT_NEAR(list.entries()[0].rho_px, 7.0, kTol);
  // 3.5 is within rchange of both: the better-ordered one takes it.
  EXPECT_EQ(VoteFor(&list, 3.5, 1.0), 0);
  EXPECT_EQ(list.entries()[0].weight, 3);
  EXPECT_EQ(list.entries()[1].weight, 1);
}

TEST(OrderedAccumulatorList, CullsNegativeScoresOnlyBeyondMaxLines) {
  OrderedAccumulatorList list(1 * kRadPerDeg, 2.0, /*max_lines=*/2, 40);
  for (int i = 0; i < 3; ++i) VoteFor(&list, 0.0, 0.3);  // A: 3 votes
  VoteFor(&list, 40.0, 0.3);                             // B, C, D: 1 vote each
  VoteFor(&list, 80.0, 0.3);
  VoteFor(&list, 120.0, 0.3);
  auto all = [](const OalEntry&) { return true; };
  list.EndBorder(all);  // scores 2.5, 0.5, 0.5, 0.5: nothing negative
  list.EndBorder(all);  // 2, 0, 0, 0: still nothing below zero
  EXPECT_EQ(list.entries().size(), 4u);
  list.EndBorder(all);  // 1.5, -0.5, -0.5, -0.5: cull down to max_lines
  ASSERT_EQ(list.entries().size(), 2u);
  EXPECT_NEAR(list.entries()[0].rho_px, 0.0, kTol);
  EXPECT_NEAR(list.entries()[1].rho_px, 40.0, kTol);  // negative, but the list is not over 2
  EXPECT_LT(list.entries()[1].Score(), 0.0);
}

TEST(OrderedAccumulatorList, CountsOnlyWhereThePredicateHolds) {
  OrderedAccumulatorList list(1 * kRadPerDeg, 2.0, 20, 40);
  VoteFor(&list, 0.0, 0.3);
  VoteFor(&list, 40.0, 0.3);
  list.EndBorder([](const OalEntry& entry) { return entry.rho_px > 20.0; });
  EXPECT_EQ(list.entries()[0].count, 0);  // rho 0: not counted, so now first (1 > 0.5)
  EXPECT_NEAR(list.entries()[0].rho_px, 0.0, kTol);
  EXPECT_EQ(list.entries()[1].count, 1);
}

TEST(OrderedAccumulatorList, FullListDropsNewVotes) {
  OrderedAccumulatorList list(1 * kRadPerDeg, 2.0, 2, 3);
  EXPECT_EQ(VoteFor(&list, 0.0, 0.1), 0);
  EXPECT_EQ(VoteFor(&list, 10.0, 0.1), 1);
  EXPECT_EQ(VoteFor(&list, 20.0, 0.1), 2);
  EXPECT_EQ(VoteFor(&list, 30.0, 0.1), -1);
  EXPECT_EQ(VoteFor(&list, 20.5, 0.1), 2);  // matches still count
  EXPECT_EQ(list.entries().size(), 3u);
}

TEST(OrderedAccumulatorList, BordersCountsDistinctBorders) {
  OrderedAccumulatorList list(1 * kRadPerDeg, 2.0, 20, 40);
  VoteFor(&list, 0.0, 0.3, 0);
  VoteFor(&list, 0.0, 0.3, 0);
  VoteFor(&list, 0.0, 0.3, 1);
  EXPECT_EQ(list.entries()[0].borders, 2);
  EXPECT_EQ(list.entries()[0].weight, 3);
}

}  // namespace
}  // namespace oal
