// The lens from straight lines (calibration/plumb_line.h): exactly from lines bent by ViSP's
// own model, within a few per cent from the A3 sheet's stripes in rendered bench frames seen
// through a lens the camera knows nothing of; lines that cannot tell refused with the reason.
#include "calibration/plumb_line.h"

#include <gtest/gtest.h>
#include <visp3/core/vpImage.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "detector/image_view.h"
#include "scene/bench_scene.h"
#include "scene/scene.h"
#include "servo/target_tracker.h"

namespace oal {
namespace {

constexpr double kPx = 600.0, kU0 = 319.5, kV0 = 239.5;

// The distorted pixel whose ViSP correction x_d (1 + kdu r_d^2) is the ideal point (x, y).
Point2d Distort(double x, double y, double kdu) {
  double xd = x, yd = y;
  for (int i = 0; i < 200; ++i) {
    const double factor = 1.0 + kdu * (xd * xd + yd * yd);
    xd = x / factor, yd = y / factor;
  }
  return {kU0 + kPx * xd, kV0 + kPx * yd};
}

// Points along the ideal line through (x0, y0) in direction (dx, dy), distorted, with noise.
std::vector<Point2d> BentLine(double x0, double y0, double dx, double dy, double kdu,
                              double noise_px, std::mt19937* random) {
  std::normal_distribution<double> noise(0.0, noise_px);
  std::vector<Point2d> points;
  for (int i = -40; i <= 40; ++i) {
    Point2d p = Distort(x0 + dx * i / 80.0, y0 + dy * i / 80.0, kdu);
    p.u += noise(*random), p.v += noise(*random);
    points.push_back(p);
  }
  return points;
}

std::vector<std::vector<Point2d>> Hash(double kdu, double noise_px, unsigned seed) {
  std::mt19937 random(seed);
  return {BentLine(-0.2, 0.0, 0.1, 0.6, kdu, noise_px, &random),
          BentLine(0.25, 0.02, -0.05, 0.6, kdu, noise_px, &random),
          BentLine(0.0, -0.18, 0.7, 0.05, kdu, noise_px, &random),
          BentLine(0.01, 0.2, 0.7, -0.02, kdu, noise_px, &random)};
}

TEST(PlumbLine, RecoversViSPsLensFromLinesItBent) {
  for (const double kdu : {0.0, 0.15, 0.35, -0.1}) {
    const PlumbLineResult result = EstimateRadialDistortion(Hash(kdu, 0.0, 1), kPx, kPx, kU0, kV0);
    EXPECT_NEAR(result.kdu, kdu, 1e-6) << "kdu " << kdu;
    // kud undoes it, as the camera files pair them.
    EXPECT_NEAR(result.kud, Lens::WithKdu(kPx, kPx, kU0, kV0, kdu, 640, 480).kud(), 1e-3);
    EXPECT_LT(result.rms_after_px, 1e-4);
    if (kdu != 0.0) {
      EXPECT_GT(result.rms_before_px, 0.1);
    }
  }
}

TEST(PlumbLine, WithNoiseAndStrayPointsStaysWithinAPercent) {
  std::vector<std::vector<Point2d>> lines = Hash(0.2, 0.2, 7);
  lines[1][10].u += 6.0;  // a mark beside the stripe
  lines[2][70].v -= 9.0;
  const PlumbLineResult result = EstimateRadialDistortion(lines, kPx, kPx, kU0, kV0);
  EXPECT_NEAR(result.kdu, 0.2, 0.002);
  EXPECT_NEAR(result.kdu, 0.2, 3.0 * result.kdu_sd);
  EXPECT_EQ(result.lines, 4);
  EXPECT_LT(result.points, 4 * 81);  // the two stray points left out
}

// The standard deviation it reports is the scatter of its estimates over the noise: what the
// lines' own shift and turn absorb of a bend tells nothing of the lens.
TEST(PlumbLine, ItsStandardDeviationIsTheEstimatesScatter) {
  constexpr int kTrials = 200;
  double sum = 0.0, sum_squares = 0.0, sd_sum = 0.0;
  for (unsigned seed = 1; seed <= kTrials; ++seed) {
    const PlumbLineResult result =
        EstimateRadialDistortion(Hash(0.2, 0.2, seed), kPx, kPx, kU0, kV0);
    sum += result.kdu;
    sum_squares += result.kdu * result.kdu;
    sd_sum += result.kdu_sd;
  }
  const double mean = sum / kTrials;
  const double scatter = std::sqrt((sum_squares - kTrials * mean * mean) / (kTrials - 1));
  const double reported = sd_sum / kTrials;
  EXPECT_NEAR(mean, 0.2, 3.0 * scatter / std::sqrt(kTrials));
  EXPECT_GT(reported, 0.8 * scatter);
  EXPECT_LT(reported, 1.25 * scatter);
}

TEST(PlumbLine, LinesThroughTheCentreCannotTell) {
  std::mt19937 random(3);
  const std::vector<std::vector<Point2d>> through = {
      BentLine(0.0, 0.0, 0.1, 0.6, 0.2, 0.2, &random),
      BentLine(0.0, 0.0, 0.6, 0.1, 0.2, 0.2, &random),
      BentLine(0.0, 0.0, 0.5, 0.5, 0.2, 0.2, &random),
      BentLine(0.0, 0.0, 0.5, -0.5, 0.2, 0.2, &random)};
  try {
    EstimateRadialDistortion(through, kPx, kPx, kU0, kV0);
    FAIL() << "lines through the centre accepted";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("too near the image's centre"), std::string::npos)
        << error.what();
  }
}

TEST(PlumbLine, TooFewLinesAreRefused) {
  std::vector<std::vector<Point2d>> lines = Hash(0.1, 0.0, 1);
  lines.resize(3);
  EXPECT_THROW(EstimateRadialDistortion(lines, kPx, kPx, kU0, kV0), std::runtime_error);
  lines = Hash(0.1, 0.0, 1);
  lines[0].resize(5);  // too few points: not used
  EXPECT_THROW(EstimateRadialDistortion(lines, kPx, kPx, kU0, kV0), std::runtime_error);
}

// The A3 sheet on the bench through lenses of kdu 0.08-0.3, tracked with a camera that knows no
// distortion: ten frames' stripes tell kdu.
TEST(PlumbLine, TheSheetsStripesTellTheLensInTenFrames) {
  const struct {
    std::uint64_t scene;
    double kdu;
  } cases[] = {{13, 0.15}, {29, 0.3}, {5, 0.08}};
  for (const auto& [scene, kdu] : cases) {
    SCOPED_TRACE("scene " + std::to_string(scene) + ", kdu " + std::to_string(kdu));
    RenderOptions render;
    render.camera = Lens::WithKdu(kPx, kPx, kU0, kV0, kdu, 640, 480);
    render.noise_sigma = 4.0;
    render.blur_sigma_px = 1.0;
    DressAsBench(&render, scene);
    const SceneRenderer renderer(FourLineA3Target(), render);
    const PoseSampling sampling = SheetSampling(renderer.target());
    Lens pinhole = Lens::Pinhole(kPx, kPx, kU0, kV0);
    PoseOptions pose;
    pose.camera = pinhole;
    pose.image_width = 640;
    pose.image_height = 480;
    TargetPoseTracker tracker(renderer.target(), pinhole, DetectorOptions(), pose);
    std::vector<std::vector<Point2d>> lines;
    std::uint64_t random = scene;
    int frames = 0;
    for (int k = 0; k < 40 && frames < 10; ++k) {
      const vpImage<unsigned char> image =
          renderer.Render(SamplePose(renderer, sampling, &random), 500 + k).image;
      tracker.Reset();
      if (tracker.Track(ViewOf(image)).status != TargetStatus::kOk) continue;
      for (std::vector<Point2d>& stripe : tracker.StripePoints(6.0)) {
        lines.push_back(std::move(stripe));
      }
      ++frames;
    }
    ASSERT_EQ(frames, 10);
    const PlumbLineResult result = EstimateRadialDistortion(lines, kPx, kPx, kU0, kV0);
    // Within 5 %, or, for a lens as weak as kdu 0.08, within three of the estimate's own
    // standard deviations (ten frames tell kdu to about 0.0015 whatever the lens: which
    // borders the frames were scanned on moves it by that much).
    const double tolerance = std::max(0.05 * kdu, 3.0 * result.kdu_sd);
    EXPECT_NEAR(result.kdu, kdu, tolerance) << "kud " << result.kud << ", sd " << result.kdu_sd;
    EXPECT_NEAR(result.kud, render.camera.kud(), tolerance / kdu * std::fabs(render.camera.kud()));
    EXPECT_LT(result.rms_after_px, result.rms_before_px);
  }
}

}  // namespace
}  // namespace oal
