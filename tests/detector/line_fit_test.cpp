#include "detector/line_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace oal {
namespace {

constexpr double kPi = 3.14159265358979323846;
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

TEST(LineSagitta, MeasuresABendAndNoneOnAStraightLine) {
  // The parabola's k is negative when the middle lies towards +v (d = a + k x^2, a = sagitta).
  EXPECT_NEAR(LineSagitta(kLine, BentPoints(0.8), 3.0), -0.8, 0.1);
  EXPECT_NEAR(LineSagitta(kLine, BentPoints(0.0), 3.0), 0.0, 0.05);
}

// One run cut short by a mark lies a pixel off: it does not make the line bent.
TEST(LineSagitta, LeavesAStrayPointOut) {
  std::vector<FramePoint> points = BentPoints(0.0);
  points[5].p.v += 1.2;
  EXPECT_NEAR(LineSagitta(kLine, points, 3.0), 0.0, 0.05);
  points[16].p.v -= 0.9;  // a second one
  EXPECT_NEAR(LineSagitta(kLine, points, 3.0), 0.0, 0.05);
}

// A run around a border's corner gives the midpoint of its ends, off the centre line.
TEST(LineSagitta, IgnoresRunsAroundACorner) {
  std::vector<FramePoint> points = BentPoints(0.0);
  for (int i = 0; i < 6; ++i) {
    FramePoint corner;
    corner.p = Point2d{150.0 + 15.0 * i, 101.5};
    corner.straight = false;
    points.push_back(corner);
  }
  EXPECT_NEAR(LineSagitta(kLine, points, 3.0), 0.0, 0.05);
}

// Beyond a stripe's printed ends its line runs over the bench: points there do not count.
TEST(LineSagitta, KeepsToTheLinesExtent) {
  std::vector<FramePoint> points = BentPoints(0.0);
  for (int i = 0; i < 8; ++i) {
    FramePoint beyond;
    beyond.p = Point2d{400.0 + 10.0 * i, 100.0 + 0.15 * i * i / 8.0};
    points.push_back(beyond);
  }
  EXPECT_GT(std::fabs(LineSagitta(kLine, points, 3.0)), 0.2);
  const LineExtent stripe{Point2d{0.0, 100.0}, Point2d{380.0, 100.0}};
  EXPECT_NEAR(LineSagitta(kLine, points, 3.0, stripe), 0.0, 0.05);
}

// Points bunched at the two ends tell little of a curvature: a wobble there is not a bend.
TEST(LineSagitta, SaysNothingOfPointsBunchedAtTheEnds) {
  std::vector<FramePoint> points;
  for (int i = 0; i < 5; ++i) {
    FramePoint left, right;
    left.p = Point2d{10.0 * i, 100.0 + (i % 2 == 0 ? 0.1 : -0.1)};
    right.p = Point2d{400.0 - 10.0 * i, 100.0 + (i % 2 == 0 ? -0.1 : 0.1) + 0.25};
    points.push_back(left);
    points.push_back(right);
  }
  EXPECT_LT(std::fabs(LineSagitta(kLine, points, 3.0)), 0.1);
}

TEST(StraightnessOfFour, IsTheSecondLargestBend) {
  const std::vector<FramePoint> bent = BentPoints(0.6);
  std::vector<FramePoint> points = bent;
  // Three more lines: v = 300 straight, v = 500 bent by 0.3, v = 700 straight.
  for (double offset : {200.0, 400.0, 600.0}) {
    const std::vector<FramePoint> line = BentPoints(offset == 400.0 ? 0.3 : 0.0);
    for (FramePoint point : line) {
      point.p.v += offset;
      points.push_back(point);
    }
  }
  const std::array<LineParams, 4> lines{kLine, LineParams{300.0, 0.5 * kPi},
                                        LineParams{500.0, 0.5 * kPi}, LineParams{700.0, 0.5 * kPi}};
  EXPECT_NEAR(StraightnessOfFour(lines, points, 3.0), 0.3, 0.08);
}

}  // namespace
}  // namespace oal
