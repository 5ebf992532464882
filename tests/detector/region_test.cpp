// Regions of interest: their insets, the loops sampled along convex polygons, and the
// detector scanning a region's borders or borders given one by one.
#include "detector/region.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "detector/border_scan.h"
#include "detector/detector.h"
#include "tests/detector/test_images.h"

namespace oal {
namespace {

using testing::PaintStripe;
using testing::TestImage;

constexpr double kTight = 1e-9;

std::vector<Point2d> Square(double u0, double v0, double side) {
  return {{u0, v0}, {u0 + side, v0}, {u0 + side, v0 + side}, {u0, v0 + side}};
}

// A square turned by `angle_rad` about (cu, cv), half side h.
std::vector<Point2d> TurnedSquare(double cu, double cv, double h, double angle_rad) {
  std::vector<Point2d> square;
  for (int k = 0; k < 4; ++k) {
    const double a = angle_rad + k * kPi / 2.0 - 3.0 * kPi / 4.0;
    square.push_back(
        {cu + h * std::sqrt(2.0) * std::cos(a), cv + h * std::sqrt(2.0) * std::sin(a)});
  }
  return square;
}

double Distance(const Point2d& a, const Point2d& b) {
  return std::hypot(a.u - b.u, a.v - b.v);
}

TEST(Region, ConvexHullTurnsLikeTheImageBordersAndDropsInnerPoints) {
  const std::vector<Point2d> hull =
      ConvexHull({{10, 10}, {50, 10}, {30, 20}, {50, 40}, {10, 40}, {30, 10}, {20, 30}});
  ASSERT_EQ(hull.size(), 4u);  // the inner points and the collinear (30, 10) are gone
  EXPECT_GT(SignedArea(hull), 0.0);
  EXPECT_NEAR(SignedArea(hull), 40.0 * 30.0, kTight);
  // Reversing the input's order changes nothing.
  const std::vector<Point2d> again = ConvexHull({{10, 40}, {50, 40}, {50, 10}, {10, 10}});
  EXPECT_NEAR(SignedArea(again), 1200.0, kTight);
}

TEST(Region, InsetOfASquareIsTheSquareMovedInward) {
  const ScanRegion region{Square(100, 100, 200)};
  const std::vector<Point2d> inset = InsetRegion(region, 10.0, 640, 480);
  ASSERT_EQ(inset.size(), 4u);
  EXPECT_NEAR(std::fabs(SignedArea(inset)), 180.0 * 180.0, 1e-6);
  for (const Point2d& p : inset) {
    EXPECT_TRUE(std::fabs(p.u - 110.0) < 1e-9 || std::fabs(p.u - 290.0) < 1e-9) << p.u;
    EXPECT_TRUE(std::fabs(p.v - 110.0) < 1e-9 || std::fabs(p.v - 290.0) < 1e-9) << p.v;
  }
  EXPECT_TRUE(InsetRegion(region, 99.5, 640, 480).empty());  // less than 2 px across is left
}

TEST(Region, InsetStopsAtTheImageMovedInwardByTheSameDistance) {
  // A square leaving the image on the left: its inset at 10 px runs along u = 10 there.
  const ScanRegion region{Square(-100, 100, 300)};
  const std::vector<Point2d> inset = InsetRegion(region, 10.0, 640, 480);
  ASSERT_GE(inset.size(), 4u);
  double lowest_u = 1e9, highest_u = -1e9;
  for (const Point2d& p : inset) {
    lowest_u = std::min(lowest_u, p.u);
    highest_u = std::max(highest_u, p.u);
  }
  EXPECT_NEAR(lowest_u, 10.0, kTight);
  EXPECT_NEAR(highest_u, 190.0, kTight);
}

TEST(Region, CheckRejectsWhatIsNotAConvexPolygon) {
  EXPECT_THROW((ScanRegion{{{0, 0}, {10, 0}}}.Check()), std::invalid_argument);
  EXPECT_THROW((ScanRegion{{{0, 0}, {10, 0}, {5, 2}, {10, 10}, {0, 10}}}.Check()),
               std::invalid_argument);  // a dent
  EXPECT_THROW((ScanRegion{{{0, 0}, {NAN, 0}, {10, 10}}}.Check()), std::invalid_argument);
  EXPECT_NO_THROW(ScanRegion{Square(0, 0, 10)}.Check());
  EXPECT_NO_THROW(ScanRegion{TurnedSquare(50, 50, 20, 0.3)}.Check());
}

TEST(PolygonLoop, AnAxisAlignedSquareSamplesItsPixelsInTheImageBordersOrder) {
  TestImage image(40, 40, 0);
  for (int v = 0; v < 40; ++v)
    for (int u = 0; u < 40; ++u) image.At(u, v) = static_cast<std::uint8_t>(u + 4 * v);
  const PolygonLoop loop(Square(5, 5, 10));
  ASSERT_EQ(loop.Perimeter(), 40);
  std::vector<std::uint8_t> samples;
  loop.Gather(image.View(), &samples);
  // Top row left to right from (5, 5), then down the right side from (15, 5).
  EXPECT_EQ(samples[0], 5 + 4 * 5);
  EXPECT_EQ(samples[9], 14 + 4 * 5);
  EXPECT_EQ(samples[10], 15 + 4 * 5);
  EXPECT_EQ(samples[11], 15 + 4 * 6);
  Point2d p;
  EXPECT_EQ(loop.Locate(3.0, &p), 1u);  // edge 0 only
  EXPECT_NEAR(p.u, 8.0, kTight);
  EXPECT_NEAR(p.v, 5.0, kTight);
  EXPECT_EQ(loop.Locate(9.5, &p), 3u);  // at the corner between edges 0 and 1
  EXPECT_TRUE(loop.HasCornerInside(8.0, 11.0));
  EXPECT_FALSE(loop.HasCornerInside(1.0, 8.0));
}

TEST(PolygonLoop, SamplesLieOnTheEdgeAndInterpolateAcrossIt) {
  // A vertical gradient: an edge of slope 0.25 samples grey = 2 v exactly at its position.
  TestImage image(100, 100, 0);
  for (int v = 0; v < 100; ++v)
    for (int u = 0; u < 100; ++u) image.At(u, v) = static_cast<std::uint8_t>(2 * v);
  const PolygonLoop loop({{10, 20}, {90, 40}, {50, 80}});
  std::vector<std::uint8_t> samples;
  loop.Gather(image.View(), &samples);
  for (int k = 0; k < 70; k += 7) {
    Point2d p;
    loop.Locate(k, &p);
    EXPECT_NEAR(p.v, 20.0 + 0.25 * (p.u - 10.0), 1e-9) << k;  // on the first edge
    EXPECT_NEAR(samples[static_cast<std::size_t>(k)], 2.0 * p.v, 0.51) << k;
  }
}

TEST(PolygonLoop, AStripeAcrossATurnedBorderGivesAPointOnItsCentreLine) {
  TestImage image(300, 300, 210);
  const LineParams stripe = LineThrough({40, 250}, {260, 70});
  PaintStripe(&image, stripe, 9.0, 30);
  for (const double angle : {0.0, 0.2, 0.55, 0.785, 1.1}) {
    const PolygonLoop loop(ConvexHull(TurnedSquare(150, 150, 80, angle)));
    std::vector<std::uint8_t> samples;
    loop.Gather(image.View(), &samples);
    DetectorOptions options;
    std::vector<BorderPoint> points;
    FindBorderPoints(samples, loop, 120, options, &points);
    ASSERT_EQ(points.size(), 2u) << angle;
    const double c = std::cos(stripe.theta_rad), s = std::sin(stripe.theta_rad);
    for (const BorderPoint& point : points) {
      // Off the centre line by a tenth of a pixel at most where the border crosses the stripe
      // steeply; a shallow crossing (a long run) places its point less well, and so does a
      // run around a corner (the midpoint of its ends, read across the corner).
      const double crossing = std::fabs(point.along.u * c + point.along.v * s);  // sin of its angle
      const double tolerance = !point.straight ? 0.3 : crossing > 0.5 ? 0.1 : 0.5;
      EXPECT_NEAR(stripe.SignedDistance(point.pixel.u, point.pixel.v), 0.0, tolerance) << angle;
      // The run's length across the stripe: its width (a run around a corner has none).
      if (point.straight && crossing > 0.0) {
        EXPECT_NEAR(point.run_px * crossing, 9.0, 0.3) << angle;
      }
    }
  }
}

// Read every third pixel along: a third of the samples, each where the every-pixel loop has
// its sample 3k, and a stripe's point and width as the every-pixel loop gives them (its
// width in pixels, not in samples), its run read again at every pixel.
TEST(PolygonLoop, ASampleStepReadsEveryNthPixelAndPlacesAStripeAsWell) {
  TestImage image(300, 300, 210);
  const LineParams stripe = LineThrough({40, 250}, {260, 70});
  PaintStripe(&image, stripe, 21.0, 30);
  for (const double angle : {0.0, 0.3, 0.9}) {
    const std::vector<Point2d> polygon = ConvexHull(TurnedSquare(150, 150, 80, angle));
    const PolygonLoop every(polygon), third(polygon, 3);
    EXPECT_EQ(third.SampleStep(), 3);
    EXPECT_NEAR(third.Perimeter(), every.Perimeter() / 3.0, 4.0) << angle;
    Point2d a, b;
    third.Locate(2.0, &a);
    every.Locate(6.0, &b);
    EXPECT_NEAR(Distance(a, b), 0.0, 1e-9) << angle;
    EXPECT_NEAR(third.Spacing(2.0), 3.0 * every.Spacing(6.0), 1e-9) << angle;

    DetectorOptions options;
    std::array<std::vector<BorderPoint>, 2> points;
    std::vector<std::uint8_t> samples;
    every.Gather(image.View(), &samples);
    FindBorderPoints(samples, every, 120, options, &points[0]);
    third.Gather(image.View(), &samples);
    const GrayImageView view = image.View();
    FindBorderPoints(samples, third, 120, options, &points[1], &view);
    ASSERT_EQ(points[0].size(), 2u) << angle;
    ASSERT_EQ(points[1].size(), 2u) << angle;
    for (std::size_t i = 0; i < 2; ++i) {
      if (!points[1][i].straight) continue;
      EXPECT_NEAR(stripe.SignedDistance(points[1][i].pixel.u, points[1][i].pixel.v), 0.0, 0.3)
          << angle;
      EXPECT_NEAR(points[1][i].run_px, points[0][i].run_px, 1.0) << angle;
    }
  }
}

// Two crossing stripes on a light square with a cluttered surround: the full image scan sees
// the clutter, a region on the square does not.
TestImage SquareSheetWithClutter() {
  TestImage image(640, 480, 60);
  for (int v = 120; v <= 400; ++v)
    for (int u = 180; u <= 460; ++u) image.At(u, v) = 215;
  // Clutter: dark bars all over the surround.
  for (int k = 0; k < 12; ++k) {
    PaintStripe(&image, LineParams{30.0 + 50.0 * k, 0.3 + 0.1 * k}, 6.0, 20);
  }
  for (int v = 120; v <= 400; ++v)
    for (int u = 180; u <= 460; ++u) image.At(u, v) = 215;
  TestImage stripes(640, 480, 215);
  PaintStripe(&stripes, LineThrough({200, 200}, {440, 240}), 10.0, 30);
  PaintStripe(&stripes, LineThrough({300, 130}, {340, 390}), 12.0, 30);
  for (int v = 125; v <= 395; ++v)
    for (int u = 185; u <= 455; ++u) image.At(u, v) = stripes.At(u, v);
  return image;
}

TEST(RegionDetect, ARegionOnTheSheetFindsItsLinesAndNothingOfTheClutter) {
  const TestImage image = SquareSheetWithClutter();
  OalDetector detector;
  const ScanRegion region{Square(185, 125, 270)};
  const std::vector<DetectedLine>& lines = detector.Detect(image.View(), {}, region);
  ASSERT_GE(lines.size(), 2u);
  const LineParams a = LineThrough({200, 200}, {440, 240}), b = LineThrough({300, 130}, {340, 390});
  int matched = 0;
  for (const DetectedLine& line : lines) {
    const bool is_a =
        AngleBetween(line.line, a) < 0.01 &&
        std::fabs(a.SignedDistance(320.0, 220.0) - line.line.SignedDistance(320.0, 220.0)) < 1.0;
    const bool is_b =
        AngleBetween(line.line, b) < 0.01 &&
        std::fabs(b.SignedDistance(320.0, 260.0) - line.line.SignedDistance(320.0, 260.0)) < 1.0;
    matched += is_a || is_b;
  }
  EXPECT_EQ(matched, 2) << "the two stripes are the lines found";
  EXPECT_EQ(static_cast<int>(lines.size()), 2) << "nothing else: the clutter is outside";
  // Every border lies inside the region, and the lines end on its outline.
  EXPECT_GT(detector.region_borders().count(), 10);
  for (const Point2d& p : detector.region_borders().Polygon(0)) {
    EXPECT_TRUE(Contains(region.vertices, p));
  }
  for (const DetectedLine& line : lines) {
    EXPECT_TRUE(Contains(GrowPolygon(region.vertices, 0.5), line.end_a));
    EXPECT_LE(Distance(line.support_a, line.support_b), Distance(line.end_a, line.end_b) + 1e-9);
  }
}

TEST(RegionDetect, NoRegionScansTheWholeImageAsBefore) {
  const TestImage image = SquareSheetWithClutter();
  OalDetector with_region, plain;
  with_region.Detect(image.View(), {}, ScanRegion{Square(185, 125, 270)});
  const std::vector<DetectedLine> after = with_region.Detect(image.View(), {}, ScanRegion{});
  const std::vector<DetectedLine>& reference = plain.Detect(image.View());
  ASSERT_EQ(after.size(), reference.size());
  for (std::size_t i = 0; i < after.size(); ++i) {
    EXPECT_EQ(after[i].line.rho_px, reference[i].line.rho_px);
    EXPECT_EQ(after[i].line.theta_rad, reference[i].line.theta_rad);
  }
  EXPECT_EQ(with_region.region_borders().count(), 0);
}

TEST(RegionDetect, BordersGivenOneByOneAreScannedAsGiven) {
  const TestImage image = SquareSheetWithClutter();
  ScanBorders borders;
  for (int k = 0; k < 12; ++k) {
    borders.polygons.push_back(ConvexHull(TurnedSquare(320, 260, 90 - 4 * k, 0.1 * k)));
  }
  OalDetector detector;
  const std::vector<DetectedLine>& lines = detector.Detect(image.View(), {}, borders);
  EXPECT_EQ(detector.region_borders().count(), 12);
  ASSERT_EQ(lines.size(), 2u);
  // A border leaving the image is cut by the image moved inward by image_margin_px +
  // k image_margin_step_px.
  ScanBorders leaving;
  leaving.polygons = {Square(-50, 100, 300), Square(-50, 100, 300), Square(-50, 100, 300)};
  leaving.image_margin_px = 4;
  leaving.image_margin_step_px = 2;
  detector.Detect(image.View(), {}, leaving);
  ASSERT_EQ(detector.region_borders().count(), 3);
  for (int k = 0; k < 3; ++k) {
    double lowest_u = 1e9;
    for (const Point2d& p : detector.region_borders().Polygon(k))
      lowest_u = std::min(lowest_u, p.u);
    EXPECT_NEAR(lowest_u, 4 + 2 * k, kTight) << k;
  }
  ScanBorders degenerate;
  degenerate.polygons = {{{0, 0}, {1, 1}}};
  EXPECT_THROW(detector.Detect(image.View(), {}, degenerate), std::invalid_argument);
  ScanBorders negative_margin;
  negative_margin.polygons = {Square(-50, 100, 300)};
  negative_margin.image_margin_px = -1;
  EXPECT_THROW(detector.Detect(image.View(), {}, negative_margin), std::invalid_argument);
}

TEST(RegionDetect, ManyBordersOfALargeRegionAreThinnedToTheLimit) {
  const TestImage image = SquareSheetWithClutter();
  DetectorOptions options;
  options.region_max_borders = 8;
  OalDetector detector(options);
  detector.Detect(image.View(), {}, ScanRegion{Square(0, 0, 480)});
  EXPECT_EQ(detector.region_borders().count(), 8);
  options.region_max_borders = 0;  // no limit: every step_px
  OalDetector unlimited(options);
  unlimited.Detect(image.View(), {}, ScanRegion{Square(0, 0, 480)});
  EXPECT_GT(unlimited.region_borders().count(), 40);
}

}  // namespace
}  // namespace oal
