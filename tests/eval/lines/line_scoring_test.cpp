#include "eval/lines/line_scoring.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace oal {
namespace {

// A vertical reference line u = 100 seen from v = 0 to v = 200.
ReferenceLine Vertical(double u) {
  return {LineParams{u, 0.0}, {u, 0.0}, {u, 200.0}};
}

TEST(LineScoring, ErrorOfIsTheAngleAndTheFarthestChordEnd) {
  const ReferenceLine reference = Vertical(100.0);
  // Tilted by atan(2 / 200) about the chord's first end: 0 px there, 2 px at the other.
  const LineParams tilted = LineThrough({100.0, 0.0}, {102.0, 200.0});
  const auto [angle_deg, offset_px] =
      ErrorOf(tilted, reference.line, reference.end_a, reference.end_b);
  EXPECT_NEAR(angle_deg, std::atan2(2.0, 200.0) * 180.0 / kPi, 1e-9);
  EXPECT_NEAR(offset_px, 2.0 * std::cos(std::atan2(2.0, 200.0)), 1e-9);
}

TEST(LineScoring, MatchesOneToOneBestPairsFirstWithinBothBounds) {
  const std::vector<ReferenceLine> references = {Vertical(100.0), Vertical(110.0)};
  const std::vector<LineParams> lines = {
      LineParams{100.4, 0.0},  // 0.4 px from the first reference, 9.6 from the second
      LineParams{100.1, 0.0},  // the first reference's best
      LineParams{150.0, 0.0},  // near none
  };
  const std::vector<LineMatch> matches = MatchLines(references, lines, 1.0, 2.0);
  ASSERT_EQ(matches.size(), 1u);  // the second reference has no line within 2 px
  EXPECT_EQ(matches[0].reference, 0u);
  EXPECT_EQ(matches[0].line, 1u);
  EXPECT_NEAR(matches[0].offset_px, 0.1, 1e-9);

  // Once its reference is taken, a line is not matched again.
  const std::vector<LineMatch> two =
      MatchLines({Vertical(100.0), Vertical(100.5)}, {LineParams{100.1, 0.0}}, 1.0, 2.0);
  ASSERT_EQ(two.size(), 1u);
  EXPECT_EQ(two[0].reference, 0u);
}

TEST(LineScoring, MidlineLiesHalfWayBetweenTwoEdges) {
  const Point2d centre{100.0, 100.0};
  const LineParams a{90.0, 0.0}, b{96.0, 0.0};
  const LineParams mid = Midline(a, b, centre);
  EXPECT_NEAR(std::fabs(mid.SignedDistance(93.0, 50.0)), 0.0, 1e-9);
  EXPECT_NEAR(DistanceAt(a, b, centre), 6.0, 1e-9);
  const Point2d foot = Foot(a, centre);
  EXPECT_NEAR(foot.u, 90.0, 1e-9);
  EXPECT_NEAR(foot.v, 100.0, 1e-9);
}

}  // namespace
}  // namespace oal
