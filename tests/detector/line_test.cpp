#include "detector/line.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace oal {
namespace {

constexpr double kTol = 1e-9;

TEST(Line, VerticalLineHasThetaZero) {
  const LineParams line = LineThrough({10.0, 0.0}, {10.0, 50.0});
  EXPECT_NEAR(line.theta_rad, 0.0, kTol);
  EXPECT_NEAR(line.rho_px, 10.0, kTol);
}

TEST(Line, HorizontalLineHasThetaHalfPi) {
  const LineParams line = LineThrough({0.0, 7.0}, {30.0, 7.0});
  EXPECT_NEAR(line.theta_rad, kPi / 2.0, kTol);
  EXPECT_NEAR(line.rho_px, 7.0, kTol);
}

TEST(Line, PointOrderDoesNotMatter) {
  const LineParams ab = LineThrough({3.0, 4.0}, {20.0, -9.0});
  const LineParams ba = LineThrough({20.0, -9.0}, {3.0, 4.0});
  EXPECT_NEAR(ab.theta_rad, ba.theta_rad, kTol);
  EXPECT_NEAR(ab.rho_px, ba.rho_px, kTol);
}

TEST(Line, ThetaStaysInHalfOpenRangeWithNegativeRho) {
  // A line through the origin's left side at a small angle past vertical: theta near pi.
  const LineParams line = LineThrough({-5.0, 0.0}, {-5.0 + 0.01, 100.0});
  EXPECT_GE(line.theta_rad, 0.0);
  EXPECT_LT(line.theta_rad, kPi);
  EXPECT_NEAR(line.SignedDistance(-5.0, 0.0), 0.0, kTol);
  EXPECT_NEAR(line.SignedDistance(-4.99, 100.0), 0.0, kTol);
}

TEST(Line, NormalizedFlipsRhoWhenMovingByPi) {
  const LineParams line = Normalized(4.0, kPi + 0.25);
  EXPECT_NEAR(line.theta_rad, 0.25, kTol);
  EXPECT_NEAR(line.rho_px, -4.0, kTol);
  const LineParams negative = Normalized(4.0, -0.25);
  EXPECT_NEAR(negative.theta_rad, kPi - 0.25, kTol);
  EXPECT_NEAR(negative.rho_px, -4.0, kTol);
}

TEST(Line, AngleAndRhoAcrossTheWrap) {
  const LineParams a{10.0, 0.01};
  const LineParams b{-10.0, kPi - 0.01};  // the same line family seen across theta = 0/pi
  EXPECT_NEAR(AngleBetween(a, b), 0.02, kTol);
  EXPECT_NEAR(RhoAlignedTo(a, b), 10.0, kTol);
}

TEST(Line, IntersectAndParallel) {
  Point2d x;
  ASSERT_TRUE(Intersect({3.0, 0.0}, {5.0, kPi / 2.0}, &x));
  EXPECT_NEAR(x.u, 3.0, kTol);
  EXPECT_NEAR(x.v, 5.0, kTol);
  EXPECT_FALSE(Intersect({3.0, 0.2}, {5.0, 0.2}, &x));
}

TEST(Line, ClipToRectGivesBorderPoints) {
  Point2d a, b;
  ASSERT_TRUE(ClipToRect(LineThrough({0.0, 0.0}, {10.0, 10.0}), 0, 0, 99, 49, &a, &b));
  EXPECT_NEAR(std::min(a.u, b.u), 0.0, 1e-9);
  EXPECT_NEAR(std::max(a.v, b.v), 49.0, 1e-9);
  EXPECT_FALSE(ClipToRect(LineParams{500.0, 0.0}, 0, 0, 99, 49, &a, &b));
}

TEST(Line, NormalizedTinyNegativeAngleKeepsRho) {
  // -1e-17 + 2 pi rounds to 2 pi: the line is still (rho, 0), not (-rho, 0).
  const LineParams line = Normalized(5.0, -1e-17);
  EXPECT_EQ(line.theta_rad, 0.0);
  EXPECT_EQ(line.rho_px, 5.0);
}

TEST(Line, FitLineThroughSymmetricScatterIsItsAxis) {
  // Points spread along a line of normal angle 0.4 rad, offset by +-0.5 px on each side in
  // equal numbers: the total-least-squares fit is that line (an ordinary regression on v
  // or u would tilt it).
  const LineParams truth{12.0, 0.4};
  const double c = std::cos(truth.theta_rad), s = std::sin(truth.theta_rad);
  std::vector<Point2d> points;
  for (int i = -10; i <= 10; ++i) {
    for (const double offset : {-0.5, 0.5}) {
      const double along = 3.0 * i, across = truth.rho_px + offset;
      points.push_back({across * c - along * s, across * s + along * c});
    }
  }
  const LineParams fit = FitLine(points);
  EXPECT_NEAR(fit.theta_rad, truth.theta_rad, kTol);
  EXPECT_NEAR(fit.rho_px, truth.rho_px, kTol);
}

TEST(Line, FitLineOfTwoPointsIsLineThrough) {
  const LineParams fit = FitLine({{3.0, 4.0}, {20.0, -9.0}});
  const LineParams through = LineThrough({3.0, 4.0}, {20.0, -9.0});
  EXPECT_NEAR(AngleBetween(fit, through), 0.0, kTol);
  EXPECT_NEAR(RhoAlignedTo(fit, through), fit.rho_px, kTol);
}

// Two lines through the image centre of a 640x480 frame, 2.5 deg apart: one line for the
// read-off (within 3 deg and 8 px) wherever they point. Measured from the top-left corner,
// their rho gap would be 6.4 px at theta = 1 rad but 17 px at theta = 2 rad.
TEST(Line, NearDuplicateMeasuresRhoFromTheGivenOrigin) {
  const Point2d centre{319.5, 239.5};
  const double angle = 3.0 * kPi / 180.0, gap = 2.5 * kPi / 180.0;
  const auto through_centre = [&](double theta) {
    return LineParams{centre.u * std::cos(theta) + centre.v * std::sin(theta), theta};
  };
  for (const double theta : {1.0, 2.0}) {
    const LineParams a = through_centre(theta), b = through_centre(theta + gap);
    EXPECT_TRUE(NearDuplicate(a, b, centre, angle, 8.0)) << theta;
    EXPECT_EQ(NearDuplicate(a, b, Point2d{0.0, 0.0}, angle, 8.0), theta == 1.0) << theta;
  }
  // Across the 0/pi wrap: theta 0.01 and pi - 0.01 through the centre are 1.1 deg apart.
  const LineParams near_zero = through_centre(0.01);
  const LineParams near_pi = Normalized(through_centre(kPi - 0.01).rho_px, kPi - 0.01);
  EXPECT_TRUE(NearDuplicate(near_zero, near_pi, centre, angle, 8.0));
  // Parallel, 10 px apart; and 4 deg apart: not duplicates.
  const LineParams shifted{near_zero.rho_px + 10.0, near_zero.theta_rad};
  EXPECT_FALSE(NearDuplicate(near_zero, shifted, centre, angle, 8.0));
  EXPECT_FALSE(
      NearDuplicate(near_zero, through_centre(0.01 + 4.0 * kPi / 180.0), centre, angle, 8.0));
}

}  // namespace
}  // namespace oal
