#include "detector/detector.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>
#include <stdexcept>

#include "base/angles.h"
#include "scene/scene.h"
#include "test_images.h"

// Counts heap allocations so a test can check that steady-state detection allocates nothing.
namespace {
std::atomic<long> g_allocations{0};
}  // namespace
// Every non-aligned form is replaced, so that each allocation is freed by the function that
// matches it (a sanitizer reports malloc freed by a default operator delete[] as a mismatch).
namespace {
void* CountedAllocation(std::size_t size) noexcept {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(size == 0 ? 1 : size);
}
}  // namespace
void* operator new(std::size_t size) {
  if (void* p = CountedAllocation(size)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) {
  if (void* p = CountedAllocation(size)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  return CountedAllocation(size);
}
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  return CountedAllocation(size);
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete(void* p, const std::nothrow_t&) noexcept {
  std::free(p);
}
void operator delete[](void* p, const std::nothrow_t&) noexcept {
  std::free(p);
}

namespace oal {
namespace {

struct LineError {
  double angle_deg = 1e9;
  double offset_px = 1e9;  ///< largest distance of the truth chord's ends from the line
};

LineError ErrorOf(const LineParams& detected, const LineParams& truth, const Point2d& a,
                  const Point2d& b) {
  LineError error;
  error.angle_deg = AngleBetween(detected, truth) * kDegPerRad;
  error.offset_px = std::max(std::fabs(detected.SignedDistance(a.u, a.v)),
                             std::fabs(detected.SignedDistance(b.u, b.v)));
  return error;
}

// A stripe 72 px wide across the image's corner, through a strong lens the detector corrects:
// its runs, undistorted with their points, are wider than max_width_px (80) on the ideal
// image, as wide as the lens stretches them there; the pair test holds them against the
// limit stretched so.
TEST(OalDetector, AWideStripeNearTheCornerOfAStrongLensIsFound) {
  testing::TestImage image(640, 480, 210);
  const LineParams stripe = LineThrough(Point2d{0.0, 190.0}, Point2d{190.0, 0.0});
  testing::PaintStripe(&image, stripe, 72.0, 40);
  OalDetector detector(DetectorOptions(),
                       Lens::WithKdu(600.0, 600.0, 319.5, 239.5, 0.33, 640, 480));
  const std::vector<DetectedLine>& lines = detector.Detect(image.View());
  ASSERT_FALSE(lines.empty());
  EXPECT_GT(lines.front().width_px, 80.0);
}

TEST(OalDetector, EmptyViewThrows) {
  OalDetector detector;
  EXPECT_THROW(detector.Detect(GrayImageView{}), std::invalid_argument);
}

TEST(OalDetector, InvalidOptionsThrowNamingTheField) {
  DetectorOptions options;
  options.step_px = 0;
  try {
    OalDetector detector(options);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("step_px = 0"), std::string::npos) << error.what();
  }
}

// For an image whose lines are 2.3 times as many pixels across (1920x1080 at 70 degrees,
// against 640x480 at 56): every length in pixels 2.3 times, the region's borders read every
// second pixel, counts and angles as they were; a third as many pixels keeps a pixel's spacing
// and narrowest run.
TEST(OalDetector, OptionsScaledWithTheImageScaleTheirLengthsOnly) {
  const DetectorOptions options;
  const DetectorOptions scaled = options.ScaledBy(2.285);
  EXPECT_EQ(scaled.start_px, 23);
  EXPECT_EQ(scaled.step_px, 11);
  EXPECT_DOUBLE_EQ(scaled.max_width_px, options.max_width_px * 2.285);
  EXPECT_DOUBLE_EQ(scaled.min_width_px, options.min_width_px * 2.285);
  EXPECT_DOUBLE_EQ(scaled.r_change_px, options.r_change_px * 2.285);
  EXPECT_DOUBLE_EQ(scaled.support_tolerance_px, options.support_tolerance_px * 2.285);
  EXPECT_DOUBLE_EQ(scaled.duplicate_r_px, options.duplicate_r_px * 2.285);
  EXPECT_EQ(scaled.region_sample_step, 2);
  EXPECT_EQ(scaled.max_lines, options.max_lines);
  EXPECT_EQ(scaled.min_support, options.min_support);
  EXPECT_DOUBLE_EQ(scaled.angle_change_deg, options.angle_change_deg);
  EXPECT_NO_THROW(scaled.Check());
  const DetectorOptions small = options.ScaledBy(0.3);
  EXPECT_EQ(small.step_px, 2);
  EXPECT_DOUBLE_EQ(small.min_width_px, 1.0);
  EXPECT_EQ(small.region_sample_step, 1);
  EXPECT_NO_THROW(small.Check());
  EXPECT_THROW(options.ScaledBy(0.0), std::invalid_argument);
}

TEST(OalDetector, ImageSmallerThanFirstBorderGivesNoLine) {
  testing::TestImage image(15, 15, 200);
  OalDetector detector;
  EXPECT_TRUE(detector.Detect(image.View()).empty());
}

TEST(OalDetector, UniformAndNoiseOnlyImagesGiveNoLine) {
  OalDetector detector;
  testing::TestImage flat(320, 240, 128);
  EXPECT_TRUE(detector.Detect(flat.View()).empty());
  testing::TestImage noisy(320, 240, 128);
  testing::AddNoise(&noisy, 8.0, 7);
  EXPECT_TRUE(detector.Detect(noisy.View()).empty());
}

// A frame exposed at a third of the right level: paper at 60, ink at 28, their classes 32 grey
// levels apart, under min_contrast. The contrast needed falls with the paper's level; a noise-only
// frame as dim still gives no line.
TEST(OalDetector, ADimFrameNeedsLessContrastInProportionToItsPaper) {
  testing::TestImage image(320, 240, 60);
  const LineParams first{100.0, 0.2}, second = Normalized(-60.0, 2.5);
  testing::PaintStripe(&image, first, 8.0, 28);
  testing::PaintStripe(&image, second, 6.0, 28);
  testing::AddNoise(&image, 3.0, 3);
  EXPECT_GE(OalDetector().Detect(image.View()).size(), 2u);
  DetectorOptions absolute;
  absolute.min_relative_contrast = 1.0;  // min_contrast wherever the paper is lighter than it
  EXPECT_TRUE(OalDetector(absolute).Detect(image.View()).empty());

  testing::TestImage noisy(320, 240, 40);
  testing::AddNoise(&noisy, 8.0, 7);
  EXPECT_TRUE(OalDetector().Detect(noisy.View()).empty());
}

TEST(OalDetector, TheContrastNeededFollowsADimLightButNeverExceedsMinContrast) {
  DetectorOptions options;
  EXPECT_DOUBLE_EQ(options.ContrastNeededAt(200.0), options.min_contrast);
  EXPECT_NEAR(options.ContrastNeededAt(66.0), 66.0 * options.min_relative_contrast, 1e-12);
  options.min_relative_contrast = 0.0;
  EXPECT_DOUBLE_EQ(options.ContrastNeededAt(66.0), 0.0);
}

TEST(OalDetector, FindsTwoStripesWithSubPixelAccuracyAndWidth) {
  testing::TestImage image(320, 240, 210);
  const LineParams first{100.0, 0.2}, second = Normalized(-60.0, 2.5);
  testing::PaintStripe(&image, first, 8.0, 30);
  testing::PaintStripe(&image, second, 5.0, 30);
  testing::AddNoise(&image, 4.0, 3);

  OalDetector detector;
  const auto& lines = detector.Detect(image.View());
  ASSERT_GE(lines.size(), 2u);
  for (const auto& [truth, width] : {std::pair{first, 8.0}, std::pair{second, 5.0}}) {
    const auto found = std::find_if(lines.begin(), lines.begin() + 2, [&](const DetectedLine& l) {
      return AngleBetween(l.line, truth) < 0.5 / kDegPerRad;
    });
    ASSERT_NE(found, lines.begin() + 2) << "no line near theta " << truth.theta_rad;
    Point2d a, b;
    ASSERT_TRUE(ClipToRect(truth, 0, 0, 319, 239, &a, &b));
    const LineError error = ErrorOf(found->line, truth, a, b);
    EXPECT_LT(error.angle_deg, 0.2);
    EXPECT_LT(error.offset_px, 0.5);
    EXPECT_NEAR(found->width_px, width, 1.0);
    EXPECT_GT(found->support, 20);
    EXPECT_NEAR(found->end_a.u, a.u, 2.0);
  }
}

TEST(OalDetector, PaperModeFindsCleanStripes) {
  testing::TestImage image(320, 240, 210);
  const LineParams first{120.0, 0.1}, second{200.0, 0.1};
  testing::PaintStripe(&image, first, 6.0, 30);
  testing::PaintStripe(&image, second, 6.0, 30);
  OalDetector detector(DetectorOptions::Paper());
  const auto& lines = detector.Detect(image.View());
  ASSERT_GE(lines.size(), 2u);
  for (int i = 0; i < 2; ++i) {
    const LineParams& truth = std::fabs(lines[i].line.rho_px - 120.0) < 10.0 ? first : second;
    EXPECT_LT(AngleBetween(lines[i].line, truth) * kDegPerRad, 1.0);
    EXPECT_NEAR(lines[i].line.rho_px, truth.rho_px, 2.0);
  }
}

TEST(OalDetector, LightLinesOnDark) {
  testing::TestImage image(320, 240, 40);
  const LineParams truth{150.0, 1.2};
  testing::PaintStripe(&image, truth, 6.0, 220);
  DetectorOptions options;
  options.polarity = Polarity::kLightLines;
  OalDetector detector(options);
  const auto& lines = detector.Detect(image.View());
  ASSERT_FALSE(lines.empty());
  EXPECT_LT(AngleBetween(lines[0].line, truth) * kDegPerRad, 0.3);
  EXPECT_NEAR(lines[0].line.rho_px, truth.rho_px, 0.5);
}

TEST(OalDetector, SteadyStateAllocatesNothing) {
  testing::TestImage image(320, 240, 210);
  testing::PaintStripe(&image, LineParams{100.0, 0.3}, 6.0, 30);
  testing::PaintStripe(&image, LineParams{50.0, 1.4}, 6.0, 30);
  testing::AddNoise(&image, 6.0, 11);
  OalDetector detector;
  detector.Detect(image.View());  // first frame of this size sizes the working memory
  const long before = g_allocations.load();
  for (int i = 0; i < 5; ++i) detector.Detect(image.View());
  EXPECT_EQ(g_allocations.load() - before, 0);
}

// Rendered frames of the shipped targets at random poses, with and without lens distortion:
// every target line must be among the first N lines, within 0.5 deg and 1 px.
struct RenderedCase {
  const char* target;
  double kdu;
  bool correct_distortion;
};

class RenderedFrames : public ::testing::TestWithParam<RenderedCase> {};

TEST_P(RenderedFrames, EveryTargetLineWithinHalfDegreeAndOnePixel) {
  const RenderedCase& param = GetParam();
  RenderOptions render;
  render.camera = Lens::WithKudKdu(600.0, 600.0, 319.5, 239.5, 0.0, param.kdu);
  render.noise_sigma = 4.0;
  render.blur_sigma_px = 0.8;
  const SceneRenderer renderer(TargetByName(param.target), render);
  PoseSampling sampling;
  sampling.max_tilt_deg = 25.0;
  sampling.min_visible_length_px = 250.0;
  std::uint64_t state = 20261123;

  OalDetector detector = param.correct_distortion ? OalDetector(DetectorOptions(), render.camera)
                                                  : OalDetector(DetectorOptions());
  const int frames = 12;
  for (int frame = 0; frame < frames; ++frame) {
    const RenderedFrame rendered = renderer.Render(SamplePose(renderer, sampling, &state), frame);
    const auto& lines = detector.Detect(rendered.image);
    const std::size_t n = rendered.truth.size();
    ASSERT_GE(lines.size(), n) << "frame " << frame;
    for (const TruthLine& truth : rendered.truth) {
      const LineParams& reference = param.correct_distortion ? truth.ideal : truth.distorted_fit;
      // With correction the chord ends are compared in undistorted coordinates.
      Point2d a = truth.end_a, b = truth.end_b;
      if (param.correct_distortion) {
        const PointUndistorter undistorter(render.camera);
        a = undistorter.Undistort(a);
        b = undistorter.Undistort(b);
      }
      LineError best;
      for (std::size_t i = 0; i < n; ++i) {
        const LineError error = ErrorOf(lines[i].line, reference, a, b);
        if (error.angle_deg + error.offset_px < best.angle_deg + best.offset_px) best = error;
      }
      EXPECT_LT(best.angle_deg, 0.5) << "frame " << frame << " line " << truth.index;
      EXPECT_LT(best.offset_px, 1.0) << "frame " << frame << " line " << truth.index;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    Targets, RenderedFrames,
    ::testing::Values(RenderedCase{"two-line", 0.0, false}, RenderedCase{"four-line", 0.0, false},
                      RenderedCase{"two-line", 0.33, true}, RenderedCase{"four-line", 0.33, true}),
    [](const ::testing::TestParamInfo<RenderedCase>& test) {
      std::string name = std::string(test.param.target) +
                         (test.param.correct_distortion ? "_distorted_corrected" : "_pinhole");
      for (char& c : name)
        if (c == '-') c = '_';
      return name;
    });

}  // namespace
}  // namespace oal

namespace oal {
namespace {

// Two parallel stripes of very different widths: the pairs that join a point of one with a
// point of the other are tilted chords, and their runs' widths across those chords differ
// five-fold, so with the width check none of them enters the list.
TEST(OalDetector, PairWidthCheckKeepsCrossPairsOutOfTheList) {
  testing::TestImage image(320, 240, 210);
  testing::PaintStripe(&image, LineParams{100.0, 0.0}, 4.0, 30);
  testing::PaintStripe(&image, LineParams{200.0, 0.0}, 20.0, 30);
  auto tilted_entries = [&](double ratio) {
    DetectorOptions options;
    options.max_pair_width_ratio = ratio;
    OalDetector detector(options);
    detector.Detect(image.View());
    int tilted = 0;
    for (const OalEntry& entry : detector.accumulator_list().entries()) {
      tilted += AngleBetween(entry.Line(), LineParams{0.0, 0.0}) > 2.0 / kDegPerRad;
    }
    return tilted;
  };
  EXPECT_GT(tilted_entries(0.0), 0);  // without the check the cross pairs are there
  EXPECT_EQ(tilted_entries(1.6), 0);
}

TEST(LineFit, WidthAcrossUsesTheSideTheRunLiesOn) {
  FramePoint top;  // a 10 px run along a horizontal side
  top.across_u = 10.0f;
  EXPECT_NEAR(WidthAcross(top, std::cos(0.5), std::sin(0.5)), 10.0 * std::cos(0.5), 1e-6);
  FramePoint left;  // ... along a vertical side
  left.across_v = -10.0f;
  EXPECT_NEAR(WidthAcross(left, std::cos(0.5), std::sin(0.5)), 10.0 * std::sin(0.5), 1e-6);
  FramePoint slanted;  // ... along a side at 30 degrees: the width is the run times |e . n|
  slanted.across_u = static_cast<float>(10.0 * std::cos(kPi / 6));
  slanted.across_v = static_cast<float>(10.0 * std::sin(kPi / 6));
  EXPECT_NEAR(WidthAcross(slanted, std::cos(0.5), std::sin(0.5)),
              10.0 * std::fabs(std::cos(kPi / 6 - 0.5)), 1e-5);
  EXPECT_EQ(WidthAcross(FramePoint{}, 1.0, 0.0), 0.0);  // a corner run: unknown
}

}  // namespace
}  // namespace oal
