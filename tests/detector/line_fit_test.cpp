#include "detector/line_fit.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <vector>

#include "base/angles.h"

namespace oal {
namespace {

// The line v = 100: its normal points along +v, so a point's distance from it is v - 100.
const LineParams kLine{100.0, 0.5 * kPi};

// Points along u = 0, 20, ..., 380 at v = 100 + the parabola with sagitta `sagitta` (positive:
// the middle towards +v) plus a small fixed wobble standing in for noise.
std::vector<FramePoint> BentPoints(double sagitta) {
  std::vector<FramePoint> points;
  for (int i = 0; i < 20; ++i) {
    const double x = -1.0 + 2.0 * i / 19.0;  // -1 .. 1 along the stretch
    FramePoint point;
    point.p = Point2d{20.0 * i, 100.0 + sagitta * (1.0 - x * x) + 0.05 * std::sin(3.0 * i)};
    points.push_back(point);
  }
  return points;
}

// FitLineBend's bend beyond one standard error (0 within it), signed.
double Sagitta(const LineParams& line, const std::vector<FramePoint>& points,
               const std::optional<LineExtent>& extent = std::nullopt) {
  const LineBend bend = FitLineBend(line, points, 3.0, extent);
  if (!bend.Tells()) return 0.0;
  return std::copysign(std::max(0.0, std::fabs(bend.k_px) - bend.k_error_px), bend.k_px);
}

TEST(FitLineBend, MeasuresABendAndNoneOnAStraightLine) {
  // The parabola's k is negative when the middle lies towards +v (d = a + k x^2, a = sagitta).
  EXPECT_NEAR(Sagitta(kLine, BentPoints(0.8)), -0.8, 0.1);
  EXPECT_NEAR(Sagitta(kLine, BentPoints(0.0)), 0.0, 0.05);
}

// One run cut short by a mark lies a pixel off: it does not make the line bent.
TEST(FitLineBend, LeavesAStrayPointOut) {
  std::vector<FramePoint> points = BentPoints(0.0);
  points[5].p.v += 1.2;
  EXPECT_NEAR(Sagitta(kLine, points), 0.0, 0.05);
  points[16].p.v -= 0.9;  // a second one
  EXPECT_NEAR(Sagitta(kLine, points), 0.0, 0.05);
}

// A run around a border's corner gives the midpoint of its ends, off the centre line.
TEST(FitLineBend, IgnoresRunsAroundACorner) {
  std::vector<FramePoint> points = BentPoints(0.0);
  for (int i = 0; i < 6; ++i) {
    FramePoint corner;
    corner.p = Point2d{150.0 + 15.0 * i, 101.5};
    corner.straight = false;
    points.push_back(corner);
  }
  EXPECT_NEAR(Sagitta(kLine, points), 0.0, 0.05);
}

// Beyond a stripe's printed ends its line runs over the bench: points there do not count.
TEST(FitLineBend, KeepsToTheLinesExtent) {
  std::vector<FramePoint> points = BentPoints(0.0);
  for (int i = 0; i < 8; ++i) {
    FramePoint beyond;
    beyond.p = Point2d{400.0 + 10.0 * i, 100.0 + 0.15 * i * i / 8.0};
    points.push_back(beyond);
  }
  EXPECT_GT(std::fabs(Sagitta(kLine, points)), 0.2);
  const LineExtent stripe{Point2d{0.0, 100.0}, Point2d{380.0, 100.0}};
  EXPECT_NEAR(Sagitta(kLine, points, stripe), 0.0, 0.05);
}

// Points bunched at the two ends tell little of a curvature: a wobble there is not a bend.
TEST(FitLineBend, SaysNothingOfPointsBunchedAtTheEnds) {
  std::vector<FramePoint> points;
  for (int i = 0; i < 5; ++i) {
    FramePoint left, right;
    left.p = Point2d{10.0 * i, 100.0 + (i % 2 == 0 ? 0.1 : -0.1)};
    right.p = Point2d{400.0 - 10.0 * i, 100.0 + (i % 2 == 0 ? -0.1 : 0.1) + 0.25};
    points.push_back(left);
    points.push_back(right);
  }
  EXPECT_LT(std::fabs(Sagitta(kLine, points)), 0.1);
}

// A '#' of four straight lines seen through a camera model whose kdu is off by `kdu_error`
// (principal point (320, 240), focal 600 px): each point moved by kdu_error r^2 from the
// principal point, plus a small fixed wobble; `mark_px` bends the first line alone, as a mark
// beside it would.
constexpr double kFocal = 600.0;
const Point2d kCentre{320.0, 240.0};
const std::array<LineParams, 4> kHash{LineParams{150.0, 0.5 * kPi}, LineParams{340.0, 0.5 * kPi},
                                      LineParams{220.0, 0.0}, LineParams{430.0, 0.0}};

std::vector<FramePoint> HashPoints(double kdu_error, double mark_px = 0.0) {
  std::vector<FramePoint> points;
  for (std::size_t k = 0; k < kHash.size(); ++k) {
    const double c = std::cos(kHash[k].theta_rad), s = std::sin(kHash[k].theta_rad);
    // Along the line from the foot of the perpendicular from the principal point.
    const double rho = kHash[k].rho_px - (kCentre.u * c + kCentre.v * s);
    for (int i = 0; i < 24; ++i) {
      const double x = -1.0 + 2.0 * i / 23.0, t = 180.0 * x;
      const double offset = rho + (k == 0 ? mark_px * (1.0 - x * x) : 0.0);
      const double du = offset * c - t * s, dv = offset * s + t * c + 0.04 * std::sin(2.7 * i + k);
      const double factor = 1.0 + kdu_error * (du * du + dv * dv) / (kFocal * kFocal);
      FramePoint point;
      point.p = Point2d{kCentre.u + du * factor, kCentre.v + dv * factor};
      points.push_back(point);
    }
  }
  return points;
}

TEST(RadialBendOfFour, TellsTheCameraModelsKduError) {
  for (double error : {-0.1, 0.05, 0.1}) {
    const RadialBend bend = RadialBendOfFour(kHash, HashPoints(error), 3.0, {}, kCentre, kFocal);
    EXPECT_EQ(bend.lines, 4);
    EXPECT_NEAR(bend.kdu_error, error, 0.01) << error;
    EXPECT_LT(bend.kdu_error_sd, 0.01);
    EXPECT_GT(bend.bend_px, 0.1) << error;
  }
}

TEST(RadialBendOfFour, SeesNoneOnStraightLines) {
  const RadialBend bend = RadialBendOfFour(kHash, HashPoints(0.0), 3.0, {}, kCentre, kFocal);
  EXPECT_NEAR(bend.kdu_error, 0.0, 0.01);
  EXPECT_LT(bend.bend_px, 0.02);
}

// A bend the other three lines do not share is a mark beside a stripe, not a lens.
TEST(RadialBendOfFour, LeavesOutALineBentAlone) {
  const RadialBend bend = RadialBendOfFour(kHash, HashPoints(0.0, 0.8), 3.0, {}, kCentre, kFocal);
  EXPECT_EQ(bend.lines, 3);
  EXPECT_NEAR(bend.kdu_error, 0.0, 0.01);
  EXPECT_LT(bend.bend_px, 0.02);
}

// Lines through the principal point do not bend under a radial lens: they tell nothing.
TEST(RadialBendOfFour, CannotTellFromLinesThroughThePrincipalPoint) {
  const std::array<LineParams, 4> through{LineParams{240.0, 0.5 * kPi}, LineParams{320.0, 0.0},
                                          LineParams{240.0, 0.5 * kPi}, LineParams{320.0, 0.0}};
  std::vector<FramePoint> points;
  for (int i = 0; i < 24; ++i) {
    FramePoint horizontal, vertical;
    horizontal.p = Point2d{140.0 + 15.0 * i, 240.0 + 0.04 * std::sin(2.7 * i)};
    vertical.p = Point2d{320.0 + 0.04 * std::cos(1.9 * i), 60.0 + 15.0 * i};
    points.push_back(horizontal);
    points.push_back(vertical);
  }
  const RadialBend bend = RadialBendOfFour(through, points, 3.0, {}, kCentre, kFocal);
  EXPECT_FALSE(std::isfinite(bend.kdu_error_sd));
  EXPECT_EQ(bend.bend_px, 0.0);
}

}  // namespace
}  // namespace oal
