#include "detector/border_scan.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <utility>
#include <vector>

#include "test_images.h"

namespace oal {
namespace {

constexpr double kSubPixelTol = 1e-9;

DetectorOptions LineOptions() {
  DetectorOptions options;
  options.min_width_px = 2.0;
  options.max_width_px = 20.0;
  options.min_crossing_angle_deg = 90.0;  // max run = max_width_px
  return options;
}

TEST(BorderScan, RectangleGeometryAndCorners) {
  const BorderRect rect = BorderAt(10, 8, 2);
  ASSERT_TRUE(rect.Valid());
  EXPECT_EQ(rect.Width(), 6);
  EXPECT_EQ(rect.Height(), 4);
  EXPECT_EQ(rect.Perimeter(), 16);
  const std::pair<double, Point2d> expected[] = {
      {0, {2, 2}},  {5, {7, 2}},  {6, {7, 3}},  {8, {7, 5}},  {9, {6, 5}},
      {13, {2, 5}}, {14, {2, 4}}, {15, {2, 3}}, {16, {2, 2}}, {5.5, {7, 2.5}}};
  for (const auto& [s, pixel] : expected) {
    EXPECT_NEAR(rect.ToPixel(s).u, pixel.u, kSubPixelTol) << "s = " << s;
    EXPECT_NEAR(rect.ToPixel(s).v, pixel.v, kSubPixelTol) << "s = " << s;
  }
  EXPECT_EQ(rect.Sides(2.0), kTop);
  EXPECT_EQ(rect.Sides(5.0), kTop | kRight);
  EXPECT_EQ(rect.Sides(0.0), kTop | kLeft);
  EXPECT_EQ(rect.Sides(11.0), kBottom);
}

TEST(BorderScan, BordersShrinkUntilTheCentre) {
  EXPECT_TRUE(BorderAt(640, 480, 238).Valid());  // 4 x 4 pixels left
  EXPECT_TRUE(BorderAt(640, 480, 239).Valid());  // the innermost 2-pixel-high ring
  EXPECT_FALSE(BorderAt(640, 480, 240).Valid());
  EXPECT_FALSE(BorderAt(15, 15, 10).Valid());  // smaller than the first border
}

TEST(BorderScan, GatherWalksTheLoopClockwise) {
  testing::TestImage image(9, 7, 0);
  for (int v = 0; v < 7; ++v)
    for (int u = 0; u < 9; ++u) image.At(u, v) = static_cast<std::uint8_t>(10 * v + u);
  const BorderRect rect = BorderAt(9, 7, 1);
  std::vector<std::uint8_t> samples;
  GatherBorder(image.View(), rect, &samples);
  ASSERT_EQ(static_cast<int>(samples.size()), rect.Perimeter());
  for (int i = 0; i < rect.Perimeter(); ++i) {
    const Point2d p = rect.ToPixel(i);
    EXPECT_EQ(samples[i], image.At(static_cast<int>(p.u), static_cast<int>(p.v))) << "i = " << i;
  }
}

TEST(BorderScan, LoopsReadOnceGatherTheSameLoops) {
  testing::TestImage image(37, 29, 0);
  for (int v = 0; v < 29; ++v)
    for (int u = 0; u < 37; ++u) image.At(u, v) = static_cast<std::uint8_t>((7 * u + 13 * v) % 251);
  BorderLoops loops;
  loops.Prepare(37, 29, 2, 3);
  loops.Read(image.View());
  ASSERT_EQ(loops.count(), 4);  // d = 2, 5, 8, 11; at d = 14 the ring would be 1 px high
  std::vector<std::uint8_t> expected;
  for (int k = 0; k < loops.count(); ++k) {
    GatherBorder(image.View(), loops.Rect(k), &expected);
    EXPECT_EQ(loops.Gather(image.View(), k), expected) << "border " << k;
  }
}

TEST(BorderScan, RunMidpointIsIntensityWeighted) {
  const BorderRect rect = BorderAt(100, 100, 0);
  std::vector<std::uint8_t> samples(rect.Perimeter(), 200);
  samples[10] = 100;
  samples[11] = 20;
  samples[12] = 20;
  samples[13] = 60;
  std::vector<BorderPoint> points;
  DetectorOptions options = LineOptions();
  options.centre_from_background = false;
  ASSERT_EQ(FindBorderPoints(samples, rect, 128, options, &points), 1);
  // Weights 128 - I: 28, 108, 108, 68.
  const double expected = (10 * 28.0 + 11 * 108.0 + 12 * 108.0 + 13 * 68.0) / 312.0;
  EXPECT_NEAR(points[0].pixel.u, expected, kSubPixelTol);
  EXPECT_NEAR(points[0].pixel.v, 0.0, kSubPixelTol);
  EXPECT_TRUE(points[0].straight);
  EXPECT_EQ(points[0].sides, kTop);
  // Sub-pixel run ends: 9 + 72/100 and 13 + 68/140.
  EXPECT_NEAR(points[0].run_px, (13.0 + 68.0 / 140.0) - (9.0 + 72.0 / 100.0), kSubPixelTol);
}

TEST(BorderScan, RunCentreWeightedByContrastToThePaperBesideIt) {
  const BorderRect rect = BorderAt(100, 100, 0);
  std::vector<std::uint8_t> samples(rect.Perimeter(), 200);
  samples[10] = 150;  // partly covered, above the threshold: it still counts
  samples[11] = 20;
  samples[12] = 20;
  samples[13] = 20;
  samples[14] = 170;
  std::vector<BorderPoint> points;
  ASSERT_EQ(FindBorderPoints(samples, rect, 128, LineOptions(), &points), 1);
  // The paper beside: samples 8, 9 and 15, 16, all 200. Weights 200 - I over 10..14.
  const double expected = (10 * 50.0 + 11 * 180.0 + 12 * 180.0 + 13 * 180.0 + 14 * 30.0) / 620.0;
  EXPECT_NEAR(points[0].pixel.u, expected, kSubPixelTol);
  // Clipped at the threshold, the partly covered samples would not count: 12.
  DetectorOptions clipped = LineOptions();
  clipped.centre_from_background = false;
  points.clear();
  ASSERT_EQ(FindBorderPoints(samples, rect, 128, clipped, &points), 1);
  EXPECT_NEAR(points[0].pixel.u, 12.0, kSubPixelTol);
}

// How much lighter one side of a run is than the other, over its depth below the lighter: 0
// on even paper, large beside a glare's slope (which moves the run's middle).
TEST(BorderScan, ARunsBackgroundStepComparesItsTwoSides) {
  const BorderRect rect = BorderAt(100, 100, 0);
  std::vector<std::uint8_t> samples(rect.Perimeter(), 200);
  for (int i = 11; i <= 13; ++i) samples[static_cast<std::size_t>(i)] = 20;
  std::vector<BorderPoint> points;
  ASSERT_EQ(FindBorderPoints(samples, rect, 128, LineOptions(), &points), 1);
  EXPECT_EQ(points[0].background_step, 0.0f);
  // One side lit to 250 (samples 14 on), the other at 200: (250 - 200) / (250 - 20).
  for (int i = 14; i < 30; ++i) samples[static_cast<std::size_t>(i)] = 250;
  points.clear();
  ASSERT_EQ(FindBorderPoints(samples, rect, 128, LineOptions(), &points), 1);
  EXPECT_NEAR(points[0].background_step, 50.0 / 230.0, 1e-6);
}

// The weighted centres are summed 16 samples at a time where SSE2 is available: runs spanning
// several windows, short runs, and runs in the last 16 samples of the loop (whose window is
// moved back to end at the loop's end) must give the brute-force centroids, for both
// polarities.
TEST(BorderScan, WeightedCentresOfRunsAnywhereOnTheLoop) {
  const BorderRect rect = BorderAt(60, 40, 0);  // loop of 196 samples, left side 157..195
  const int p = rect.Perimeter();
  std::vector<std::uint8_t> dark(static_cast<std::size_t>(p));
  std::uint32_t state = 12345;  // a fixed linear congruential sequence: deterministic
  auto next = [&state](int range) {
    state = state * 1664525u + 1013904223u;
    return static_cast<int>((state >> 16) % static_cast<std::uint32_t>(range));
  };
  for (std::uint8_t& value : dark) value = static_cast<std::uint8_t>(190 + next(20));
  const std::vector<std::pair<int, int>> runs = {{5, 9}, {20, 45}, {100, 103}, {180, 195}};
  for (const auto& [first, last] : runs) {
    for (int i = first; i <= last; ++i) dark[static_cast<std::size_t>(i)] = 20 + next(80);
  }
  DetectorOptions options = LineOptions();
  options.max_width_px = 40.0;
  options.centre_from_background = false;  // the weights clipped at the threshold, within the run
  for (const Polarity polarity : {Polarity::kDarkLines, Polarity::kLightLines}) {
    options.polarity = polarity;
    const bool light = polarity == Polarity::kLightLines;
    std::vector<std::uint8_t> samples = dark;
    if (light) {
      for (std::uint8_t& value : samples) value = static_cast<std::uint8_t>(255 - value);
    }
    const int threshold = light ? 127 : 128;
    std::vector<BorderPoint> points;
    ASSERT_EQ(FindBorderPoints(samples, rect, threshold, options, &points),
              static_cast<int>(runs.size()));
    for (std::size_t k = 0; k < runs.size(); ++k) {
      double weight_sum = 0.0, weighted = 0.0;
      for (int i = runs[k].first; i <= runs[k].second; ++i) {
        const int value = samples[static_cast<std::size_t>(i)];
        const double weight = std::max(0, light ? value - threshold : threshold - value);
        weight_sum += weight;
        weighted += weight * i;
      }
      const Point2d expected = rect.ToPixel(weighted / weight_sum);
      EXPECT_NEAR(points[k].pixel.u, expected.u, kSubPixelTol) << "run " << k;
      EXPECT_NEAR(points[k].pixel.v, expected.v, kSubPixelTol) << "run " << k;
    }
  }
}

TEST(BorderScan, DeadPixelsAndTooWideRunsGiveNoPoint) {
  const BorderRect rect = BorderAt(100, 100, 0);
  std::vector<std::uint8_t> samples(rect.Perimeter(), 200);
  samples[30] = 0;                                 // a dead pixel
  for (int i = 150; i < 180; ++i) samples[i] = 0;  // 30 px: wider than max_width_px
  std::vector<BorderPoint> points;
  EXPECT_EQ(FindBorderPoints(samples, rect, 128, LineOptions(), &points), 0);
}

TEST(BorderScan, WideRunsAllowedAtShallowCrossingAngles) {
  const BorderRect rect = BorderAt(100, 100, 0);
  std::vector<std::uint8_t> samples(rect.Perimeter(), 200);
  for (int i = 150; i < 180; ++i) samples[i] = 0;  // 30 px run of a 20 px line at ~42 deg
  DetectorOptions options = LineOptions();
  options.min_crossing_angle_deg = 30.0;  // runs up to 40 px
  std::vector<BorderPoint> points;
  EXPECT_EQ(FindBorderPoints(samples, rect, 128, options, &points), 1);
}

TEST(BorderScan, NoiseGapInsideALineIsBridged) {
  const BorderRect rect = BorderAt(100, 100, 0);
  std::vector<std::uint8_t> samples(rect.Perimeter(), 200);
  for (int i = 40; i < 48; ++i) samples[i] = 10;
  samples[44] = 180;  // one bright noise pixel inside the line
  std::vector<BorderPoint> points;
  ASSERT_EQ(FindBorderPoints(samples, rect, 128, LineOptions(), &points), 1);
  EXPECT_NEAR(points[0].pixel.u, 43.5, 0.2);
}

TEST(BorderScan, RunAroundACornerIsOneRunWithEndMidpoint) {
  const BorderRect rect = BorderAt(100, 100, 0);  // top-right corner at loop index 99
  std::vector<std::uint8_t> samples(rect.Perimeter(), 255);
  for (int i = 96; i <= 102; ++i) samples[i] = 0;
  std::vector<BorderPoint> points;
  ASSERT_EQ(FindBorderPoints(samples, rect, 128, LineOptions(), &points), 1);
  const double s_a = 95.0 + 127.0 / 255.0, s_b = 102.0 + 128.0 / 255.0;
  EXPECT_FALSE(points[0].straight);
  EXPECT_NEAR(points[0].pixel.u, 0.5 * (s_a + 99.0), kSubPixelTol);
  EXPECT_NEAR(points[0].pixel.v, 0.5 * (0.0 + (s_b - 99.0)), kSubPixelTol);
  EXPECT_EQ(points[0].sides, kTop | kRight);
}

TEST(BorderScan, RunAcrossTheLoopSeamIsOneRun) {
  const BorderRect rect = BorderAt(100, 100, 0);
  std::vector<std::uint8_t> samples(rect.Perimeter(), 255);
  const int p = rect.Perimeter();
  for (int i : {p - 3, p - 2, p - 1, 0, 1, 2, 3}) samples[i] = 0;  // around the top-left corner
  std::vector<BorderPoint> points;
  ASSERT_EQ(FindBorderPoints(samples, rect, 128, LineOptions(), &points), 1);
  EXPECT_FALSE(points[0].straight);
  EXPECT_EQ(points[0].sides, kTop | kLeft);
}

TEST(BorderScan, LightLinesAndEdgesPolarities) {
  const BorderRect rect = BorderAt(100, 100, 0);
  std::vector<std::uint8_t> samples(rect.Perimeter(), 30);
  for (int i = 20; i < 26; ++i) samples[i] = 220;
  DetectorOptions options = LineOptions();
  options.polarity = Polarity::kLightLines;
  std::vector<BorderPoint> points;
  ASSERT_EQ(FindBorderPoints(samples, rect, 128, options, &points), 1);
  EXPECT_NEAR(points[0].pixel.u, 22.5, kSubPixelTol);

  // Half the loop dark, half light: two edges.
  std::vector<std::uint8_t> halves(rect.Perimeter(), 220);
  for (int i = 50; i < 250; ++i) halves[i] = 30;
  options.polarity = Polarity::kEdges;
  points.clear();
  ASSERT_EQ(FindBorderPoints(halves, rect, 125, options, &points), 2);
  EXPECT_NEAR(points[0].pixel.u, 49.5, kSubPixelTol);
  EXPECT_EQ(points[0].run_px, 0.0);
}

TEST(BorderScan, UniformBorderHasNoPoint) {
  const BorderRect rect = BorderAt(50, 50, 0);
  std::vector<BorderPoint> points;
  EXPECT_EQ(FindBorderPoints(std::vector<std::uint8_t>(rect.Perimeter(), 0), rect, 128,
                             LineOptions(), &points),
            0);
  EXPECT_EQ(FindBorderPoints(std::vector<std::uint8_t>(rect.Perimeter(), 255), rect, 128,
                             LineOptions(), &points),
            0);
}

TEST(BorderScan, PointsPerBorderAreCapped) {
  const BorderRect rect = BorderAt(200, 200, 0);
  std::vector<std::uint8_t> samples(rect.Perimeter(), 255);
  for (int i = 0; i + 4 < rect.Perimeter(); i += 10) samples[i + 2] = samples[i + 3] = 0;
  DetectorOptions options = LineOptions();
  options.max_points_per_border = 5;
  std::vector<BorderPoint> points;
  EXPECT_EQ(FindBorderPoints(samples, rect, 128, options, &points), 5);
}

TEST(BorderScan, OtsuSplitsTwoLevels) {
  std::vector<std::uint8_t> samples(300, 200);
  for (int i = 0; i < 40; ++i) samples[i] = 50;
  int contrast = 0;
  const int threshold = OtsuThreshold(samples, &contrast);
  EXPECT_GT(threshold, 50);
  EXPECT_LE(threshold, 200);
  EXPECT_NEAR(contrast, 150, 8);  // 32 bins of 8 grey levels
}

}  // namespace
}  // namespace oal
