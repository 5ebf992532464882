// The pose refined on the stripes' own points (servo/stripe_fit.h) and the model check
// (servo/stripe_check.h), on rendered frames of the A3 sheet through the real detector.
#include "servo/stripe_fit.h"

#include <gtest/gtest.h>
#include <visp3/core/vpMath.h>
#include <visp3/core/vpMatrix.h>
#include <visp3/core/vpThetaUVector.h>
#include <visp3/core/vpUniRand.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "base/pose_distance.h"
#include "scene/scene.h"
#include "servo/stripe_check.h"
#include "servo/target_tracker.h"
#include "tests/scene/scene_test_util.h"

namespace oal {
namespace {

using testing::FrontoParallel;

const Lens kCamera = Lens::WithKdu(600.0, 600.0, 319.5, 239.5, 0.15, 640, 480);

RenderOptions Render() {
  RenderOptions render;
  render.camera = kCamera;
  render.noise_sigma = 3.0;
  render.blur_sigma_px = 0.8;
  return render;
}

// A sheet 0.6 m away, rolled, and tilted by 25 degrees about the point the camera looks at.
vpHomogeneousMatrix Tilted() {
  const vpHomogeneousMatrix tilt = vpHomogeneousMatrix(0.0, 0.0, 0.6, 0.0, 0.0, 0.0) *
                                   vpHomogeneousMatrix(0.0, 0.0, 0.0, vpMath::rad(25.0), 0.0, 0.0) *
                                   vpHomogeneousMatrix(0.0, 0.0, -0.6, 0.0, 0.0, 0.0);
  return tilt * FrontoParallel(0.6, 0.01, -0.005, 0.4);
}

// Translation error in metres, rotation error in degrees.
std::pair<double, double> PoseError(const vpHomogeneousMatrix& cMo,
                                    const vpHomogeneousMatrix& truth) {
  const PoseDistance d = Distance(cMo, truth);
  return {d.translation_m, vpMath::deg(d.rotation_rad)};
}

// `cMo` off by half a degree about the optical axis and 2 mm: the stripes' ends a few pixels
// away, where a fit starts from.
vpHomogeneousMatrix SlightlyOff(const vpHomogeneousMatrix& cMo) {
  return vpHomogeneousMatrix(0.002, 0.0, 0.0, 0.0, 0.0, vpMath::rad(0.5)) * cMo;
}

// The tracker's feature points of `frame` (found with no prior) and its pose.
struct Tracked {
  std::vector<FramePoint> points;
  TargetFrame frame;
};
Tracked Track(const RenderedFrame& rendered, TargetTrackerOptions options = {}) {
  PoseOptions pose;
  pose.camera = kCamera;
  TargetPoseTracker tracker(FourLineA3Target(), kCamera, DetectorOptions(), pose, options);
  Tracked tracked;
  tracked.frame = tracker.Track(ViewOf(rendered.image));
  tracked.points = tracker.detector().feature_points();
  return tracked;
}

TEST(StripeFit, ConvergesToTheTruthFromAPoseADegreeOff) {
  const SceneRenderer renderer(FourLineA3Target(), Render());
  const RenderedFrame rendered = renderer.Render(Tilted(), 3);
  const Tracked tracked = Track(rendered);
  ASSERT_EQ(tracked.frame.status, TargetStatus::kOk) << tracked.frame.message;
  const TargetLayout layout = TargetLayout::Of(FourLineA3Target());
  const StripeFit fit =
      FitStripes(SlightlyOff(rendered.cMo), layout, tracked.points, kCamera, true);
  ASSERT_TRUE(fit.ok) << fit.message;
  const auto [t, r] = PoseError(fit.cMo, rendered.cMo);
  EXPECT_LT(t, 0.6e-3);
  EXPECT_LT(r, 0.05);
  for (int k = 0; k < 4; ++k) {
    EXPECT_GE(fit.points[static_cast<std::size_t>(k)], 12) << "line " << k + 1;
    EXPECT_GT(fit.extent[static_cast<std::size_t>(k)], 0.7) << "line " << k + 1;
  }
  EXPECT_LT(fit.rms_px, 0.2);
}

// Runs merged with something dark lying against one stripe (their middles a few pixels off)
// are let go: the pose stays where the other points put it.
TEST(StripeFit, LetsGoOfRunsPulledOffTheirStripe) {
  const SceneRenderer renderer(FourLineA3Target(), Render());
  const RenderedFrame rendered = renderer.Render(Tilted(), 4);
  const Tracked tracked = Track(rendered);
  ASSERT_EQ(tracked.frame.status, TargetStatus::kOk) << tracked.frame.message;
  const TargetLayout layout = TargetLayout::Of(FourLineA3Target());
  const StripeFit clean = FitStripes(tracked.frame.pose.cMo, layout, tracked.points, kCamera, true);
  ASSERT_TRUE(clean.ok) << clean.message;
  // A third of the points moved 3 px along their runs, as a run merged with a pen 6 px wide
  // lying against the stripe would.
  std::vector<FramePoint> pulled = tracked.points;
  for (std::size_t i = 0; i < pulled.size(); i += 3) {
    const double length = std::hypot(pulled[i].across_u, pulled[i].across_v);
    if (length <= 0.0) continue;
    pulled[i].p.u += 3.0 * pulled[i].across_u / length;
    pulled[i].p.v += 3.0 * pulled[i].across_v / length;
  }
  const StripeFit fit = FitStripes(tracked.frame.pose.cMo, layout, pulled, kCamera, true);
  ASSERT_TRUE(fit.ok) << fit.message;
  const auto [t, r] = PoseError(fit.cMo, rendered.cMo);
  EXPECT_LT(t, 1e-3);
  EXPECT_LT(r, 0.1);
}

// Runs with a glare's slope on one side (FramePoint::background_step) are not centred on their
// stripe: left out, however they pull.
TEST(StripeFit, LeavesOutRunsWithALighterSide) {
  const SceneRenderer renderer(FourLineA3Target(), Render());
  const RenderedFrame rendered = renderer.Render(Tilted(), 9);
  const Tracked tracked = Track(rendered);
  ASSERT_EQ(tracked.frame.status, TargetStatus::kOk) << tracked.frame.message;
  const TargetLayout layout = TargetLayout::Of(FourLineA3Target());
  // Every run in the image's lower right quarter pulled half a pixel along its run, as a
  // glare there would, and marked so.
  std::vector<FramePoint> pulled = tracked.points;
  for (FramePoint& point : pulled) {
    const double length = std::hypot(point.across_u, point.across_v);
    if (length <= 0.0 || point.p.u < 320.0 || point.p.v < 240.0) continue;
    point.p.u += 0.5 * point.across_u / length;
    point.p.v += 0.5 * point.across_v / length;
    point.background_step = 0.4f;
  }
  const StripeFit fit = FitStripes(tracked.frame.pose.cMo, layout, pulled, kCamera, true);
  ASSERT_TRUE(fit.ok) << fit.message;
  const auto [t, r] = PoseError(fit.cMo, rendered.cMo);
  EXPECT_LT(t, 1e-3);
  EXPECT_LT(r, 0.1);
  const StripeFit unmarked = [&] {
    StripeFitOptions keep_them;
    keep_them.max_background_step = 1e9;
    return FitStripes(tracked.frame.pose.cMo, layout, pulled, kCamera, true, keep_them);
  }();
  ASSERT_TRUE(unmarked.ok);
  EXPECT_GT(PoseError(unmarked.cMo, rendered.cMo).second, r);
}

// The rotation's deviation the fit gives is what the points' scatter leaves: the same frame's
// points moved by fresh noise along their runs, fit after fit, turn the pose by about as much,
// and each fit's rotation lies about sqrt(3) to 2 of its own deviations (Mahalanobis, three
// axes) from the truth. The points of the stripes' middles alone fix the tilt less well, and say
// so.
TEST(StripeFit, TheRotationsDeviationIsWhatThePointsScatterLeaves) {
  const SceneRenderer renderer(FourLineA3Target(), Render());
  const RenderedFrame rendered = renderer.Render(Tilted(), 11);
  const Tracked tracked = Track(rendered);
  ASSERT_EQ(tracked.frame.status, TargetStatus::kOk) << tracked.frame.message;
  const TargetLayout layout = TargetLayout::Of(FourLineA3Target());
  constexpr double kNoisePx = 0.4;
  vpUniRand random(12);
  const auto noisy_fit = [&](const std::vector<FramePoint>& points) {
    std::vector<FramePoint> moved = points;
    for (FramePoint& point : moved) {
      const double length = std::hypot(point.across_u, point.across_v);
      if (length <= 0.0) continue;
      // A sum of twelve uniforms: near enough a Gaussian of unit deviation.
      double gauss = -6.0;
      for (int i = 0; i < 12; ++i) gauss += random();
      point.p.u += kNoisePx * gauss * point.across_u / length;
      point.p.v += kNoisePx * gauss * point.across_v / length;
    }
    return FitStripes(rendered.cMo, layout, moved, kCamera, true);
  };
  // The spread of the fits' rotations about the truth, along its largest axis, against the
  // deviation the fits give (their median).
  const auto spread_and_deviation = [&](const std::vector<FramePoint>& points) {
    vpMatrix scatter(3, 3, 0.0);
    std::vector<double> deviations;
    double distance2 = 0.0;
    constexpr int kFits = 200;
    for (int i = 0; i < kFits; ++i) {
      const StripeFit fit = noisy_fit(points);
      EXPECT_TRUE(fit.ok) << fit.message;
      const vpThetaUVector turn((fit.cMo * rendered.cMo.inverse()).getRotationMatrix());
      for (unsigned r = 0; r < 3; ++r) {
        for (unsigned c = 0; c < 3; ++c) scatter[r][c] += turn[r] * turn[c] / kFits;
      }
      deviations.push_back(fit.RotationDeviation());
      distance2 += std::pow(fit.RotationDistance(rendered.cMo), 2) / kFits;
    }
    // Three axes: a mean square of 3 for an exact covariance; the robust scale and the weights
    // leave it a little small.
    EXPECT_GT(distance2, 2.0);
    EXPECT_LT(distance2, 6.0);
    std::sort(deviations.begin(), deviations.end());
    const double spread = std::sqrt(scatter.eigenValues().getMaxValue());
    return std::make_pair(spread, deviations[deviations.size() / 2]);
  };
  const auto [spread, deviation] = spread_and_deviation(tracked.points);
  EXPECT_GT(deviation, 0.0);
  EXPECT_NEAR(deviation / spread, 1.0, 0.3)
      << "spread " << spread << " rad, deviation " << deviation << " rad";
  // The stripes' middles only: the points within 0.15 m of the sheet's centre across it and
  // 0.11 m along it (the stripes' arms reach 0.2 and 0.14 m).
  std::vector<FramePoint> middles;
  const vpHomogeneousMatrix oMc = rendered.cMo.inverse();
  for (const FramePoint& point : tracked.points) {
    const Point2d x{(point.p.u - kCamera.u0()) / kCamera.px(),
                    (point.p.v - kCamera.v0()) / kCamera.py()};
    const vpColVector ray = oMc.getRotationMatrix() * vpColVector({x.u, x.v, 1.0});
    const vpTranslationVector centre = oMc.getTranslationVector();
    const double s = -centre[2] / ray[2];
    if (std::fabs(centre[0] + s * ray[0]) < 0.15 && std::fabs(centre[1] + s * ray[1]) < 0.11) {
      middles.push_back(point);
    }
  }
  const auto [middles_spread, middles_deviation] = spread_and_deviation(middles);
  EXPECT_GT(middles_deviation, 1.3 * deviation)
      << middles.size() << " of " << tracked.points.size() << " points: " << middles_deviation
      << " against " << deviation << " rad";
  EXPECT_NEAR(middles_deviation / middles_spread, 1.0, 0.3);
}

// Points of something dark lying along one side of a stripe beyond where the stripe is
// covered line up with its other side, a few pixels off: the line the stripe's own points
// (the more) lie on decides, and the pose stays right.
TEST(StripeFit, KeepsTheStripesOwnLineWhenAnotherLinesUpWithIt) {
  const SceneRenderer renderer(FourLineA3Target(), Render());
  const RenderedFrame rendered = renderer.Render(Tilted(), 10);
  const Tracked tracked = Track(rendered);
  ASSERT_EQ(tracked.frame.status, TargetStatus::kOk) << tracked.frame.message;
  const TargetLayout layout = TargetLayout::Of(FourLineA3Target());
  // Line 1's points on one side of its middle moved across it by a growing offset (0.3 px
  // to 1.5 px out to its end): a finger's runs lying along it, at a slant.
  const LineParams& line1 = rendered.truth[0].ideal;
  const double c = std::cos(line1.theta_rad), s = std::sin(line1.theta_rad);
  const Point2d middle{0.5 * (rendered.truth[0].end_a.u + rendered.truth[0].end_b.u),
                       0.5 * (rendered.truth[0].end_a.v + rendered.truth[0].end_b.v)};
  std::vector<FramePoint> pulled = tracked.points;
  int moved = 0;
  for (FramePoint& point : pulled) {
    if (std::fabs(line1.SignedDistance(point.p.u, point.p.v)) > 3.0) continue;
    const double t = -s * (point.p.u - middle.u) + c * (point.p.v - middle.v);  // along line 1
    if (t < 20.0) continue;
    const double offset = 0.3 + 1.2 * std::min(1.0, t / 150.0);
    point.p.u += offset * c;
    point.p.v += offset * s;
    ++moved;
  }
  ASSERT_GE(moved, 4);
  const StripeFit fit = FitStripes(tracked.frame.pose.cMo, layout, pulled, kCamera, true);
  ASSERT_TRUE(fit.ok) << fit.message;
  const auto [t, r] = PoseError(fit.cMo, rendered.cMo);
  EXPECT_LT(r, 0.1);
  EXPECT_LT(t, 1e-3);
}

// Three of every four runs of line 1 a seventh wider (both ends out, their middles where they
// were): the stripe's median excess width says so, and a band of widths about the others'
// keeps only the runs as wide as the stripe, the pose where it was.
TEST(StripeFit, ABandOfRunWidthsKeepsOnlyTheRunsItHolds) {
  const SceneRenderer renderer(FourLineA3Target(), Render());
  const RenderedFrame rendered = renderer.Render(Tilted(), 7);
  const Tracked tracked = Track(rendered);
  ASSERT_EQ(tracked.frame.status, TargetStatus::kOk) << tracked.frame.message;
  const TargetLayout layout = TargetLayout::Of(FourLineA3Target());
  const StripeFit clean = FitStripes(rendered.cMo, layout, tracked.points, kCamera, true);
  ASSERT_TRUE(clean.ok) << clean.message;
  for (int k = 0; k < 4; ++k) EXPECT_LT(std::fabs(clean.width_excess_px[k]), 1.0) << k;

  const LineParams& line1 = rendered.truth[0].ideal;
  std::vector<FramePoint> widened = tracked.points;
  int on_line1 = 0;
  for (FramePoint& point : widened) {
    if (std::fabs(line1.SignedDistance(point.p.u, point.p.v)) > 3.0) continue;
    if (on_line1++ % 4 == 0) continue;
    point.across_u *= 1.15f;
    point.across_v *= 1.15f;
  }
  ASSERT_GE(on_line1, 12);
  const StripeFit wide = FitStripes(rendered.cMo, layout, widened, kCamera, true);
  ASSERT_TRUE(wide.ok) << wide.message;
  EXPECT_GT(wide.width_excess_px[0], clean.width_excess_px[0] + 2.0);
  EXPECT_EQ(wide.points[0], clean.points[0]);

  const double half = 0.5 * (wide.width_excess_px[0] - clean.width_excess_px[0]);
  const RunWidthBand band{0, clean.width_excess_px[0] - half, clean.width_excess_px[0] + half};
  const StripeFit banded =
      FitStripes(rendered.cMo, layout, widened, kCamera, true, {}, nullptr, -1, nullptr, &band);
  ASSERT_TRUE(banded.ok) << banded.message;
  EXPECT_LE(banded.points[0], (on_line1 + 3) / 4);
  EXPECT_GE(banded.points[0], 4);
  EXPECT_LT(std::fabs(banded.width_excess_px[0] - clean.width_excess_px[0]), 1.0);
  const auto [t, r] = PoseError(banded.cMo, rendered.cMo);
  EXPECT_LT(r, 0.1);
  EXPECT_LT(t, 1e-3);
  // The band is line 1's: the others keep their runs.
  for (int k = 1; k < 4; ++k) EXPECT_NEAR(banded.points[k], clean.points[k], 2) << k;
}

TEST(StripeFit, AStripeWithoutPointsIsNamed) {
  const SceneRenderer renderer(FourLineA3Target(), Render());
  const RenderedFrame rendered = renderer.Render(Tilted(), 5);
  const Tracked tracked = Track(rendered);
  ASSERT_EQ(tracked.frame.status, TargetStatus::kOk);
  const TargetLayout layout = TargetLayout::Of(FourLineA3Target());
  const StripeFit all = FitStripes(rendered.cMo, layout, tracked.points, kCamera, true);
  ASSERT_TRUE(all.ok);
  // The points are in undistorted pixels, as the truth's ideal lines.
  std::vector<FramePoint> without;
  const std::vector<TruthLine>& truth = rendered.truth;
  for (const FramePoint& point : tracked.points) {
    if (std::fabs(truth[2].ideal.SignedDistance(point.p.u, point.p.v)) > 20.0) {
      without.push_back(point);
    }
  }
  const StripeFit fit = FitStripes(rendered.cMo, layout, without, kCamera, true);
  EXPECT_FALSE(fit.ok);
  EXPECT_NE(fit.message.find("line 3 keeps 0 of its stripe's points"), std::string::npos)
      << fit.message;
}

// Any three stripes fix the sheet's pose: each one left out in turn, the others' points still
// give the truth (within a third of the 1 degree by which the tracker lets a stripe with few
// points pull the pose: three stripes tell the tilt less well than four), the one left out
// keeping none and needing none.
TEST(StripeFit, TheOtherThreeStripesHoldThePoseWithOneLeftOut) {
  const SceneRenderer renderer(FourLineA3Target(), Render());
  const RenderedFrame rendered = renderer.Render(Tilted(), 6);
  const Tracked tracked = Track(rendered);
  ASSERT_EQ(tracked.frame.status, TargetStatus::kOk) << tracked.frame.message;
  const TargetLayout layout = TargetLayout::Of(FourLineA3Target());
  const vpHomogeneousMatrix start = SlightlyOff(rendered.cMo);
  for (int line = 0; line < 4; ++line) {
    const StripeFit fit =
        FitStripes(start, layout, tracked.points, kCamera, true, {}, nullptr, line);
    ASSERT_TRUE(fit.ok) << "line " << line + 1 << " left out: " << fit.message;
    EXPECT_EQ(fit.points[static_cast<std::size_t>(line)], 0);
    const auto [t, r] = PoseError(fit.cMo, rendered.cMo);
    EXPECT_LT(t, 2e-3) << "line " << line + 1 << " left out";
    EXPECT_LT(r, 0.3) << "line " << line + 1 << " left out";
  }
}

// What a stripe's points span counts only stretches of three points or more: a few runs
// at a hand's edge far from the rest do not make a stripe seen over its length.
TEST(StripeFit, AStripesExtentCountsOnlyStretchesOfThreePointsOrMore) {
  // Both arms of a 0.4 m stripe, a point every 5 mm: the stretch between them counts too.
  std::vector<double> arms;
  for (double a = 0.0; a <= 0.0701; a += 0.005) arms.push_back(a), arms.push_back(0.4 - a);
  EXPECT_DOUBLE_EQ(SupportedExtent(&arms, 0.4), 1.0);
  // Seven runs over 3 cm near one end, two at a hand's edge 10 cm away.
  std::vector<double> cut = {0.30, 0.305, 0.31, 0.315, 0.32, 0.325, 0.33, 0.20, 0.21};
  EXPECT_NEAR(SupportedExtent(&cut, 0.4), 0.03 / 0.4, 1e-12);
  // Two such pairs and nothing else: no stretch at all.
  std::vector<double> pairs = {0.05, 0.06, 0.30, 0.31};
  EXPECT_EQ(SupportedExtent(&pairs, 0.4), 0.0);
  std::vector<double> none;
  EXPECT_EQ(SupportedExtent(&none, 0.4), 0.0);
}

TEST(StripeFit, BadOptionsNameTheField) {
  StripeFitOptions options;
  options.corridor_px = 0.0;
  EXPECT_THROW(options.Check(), std::invalid_argument);
  options = StripeFitOptions();
  options.min_points = 1;
  try {
    options.Check();
    FAIL();
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("StripeFitOptions::min_points = 1"),
              std::string::npos);
  }
}

// ------------------------------------------------------------------------------------------
// The model check.

TEST(StripeCheck, TheTruthAgreesAlongEveryStripe) {
  const SceneRenderer renderer(FourLineA3Target(), Render());
  const RenderedFrame rendered = renderer.Render(Tilted(), 6);
  const TargetLayout layout = TargetLayout::Of(FourLineA3Target());
  const StripeAgreement agreement =
      CheckStripes(ViewOf(rendered.image), layout, rendered.cMo, kCamera);
  for (int k = 0; k < 4; ++k) {
    EXPECT_GE(agreement.samples[static_cast<std::size_t>(k)], 8) << "line " << k + 1;
    EXPECT_EQ(agreement.dark[static_cast<std::size_t>(k)],
              agreement.samples[static_cast<std::size_t>(k)])
        << "line " << k + 1;
  }
  EXPECT_EQ(agreement.Worst(), 1.0);
  EXPECT_EQ(agreement.Seen(), 1.0);
}

// Line 1 running along the image's left edge, its middle 35 px in: a stripe's width of paper
// beside it would leave the image, half of one does not. Read with the shorter profiles it
// agrees; without them it is not read at all (a pose fitted to the stripes alone is held to
// the full profiles).
TEST(StripeCheck, AStripeAlongTheImagesEdgeIsReadWithShorterProfiles) {
  const SceneRenderer renderer(FourLineA3Target(), Render());
  const vpHomogeneousMatrix cMo = FrontoParallel(0.4, 0.09967, 0.0, 0.0);
  const RenderedFrame rendered = renderer.Render(cMo, 8);
  const TargetLayout layout = TargetLayout::Of(FourLineA3Target());
  const StripeAgreement short_profiles =
      CheckStripes(ViewOf(rendered.image), layout, rendered.cMo, kCamera);
  EXPECT_GE(short_profiles.dark[0], 8);
  EXPECT_EQ(short_profiles.contradict[0], 0);
  StripeCheckOptions full_only;
  full_only.short_profiles_at_edge = false;
  const StripeAgreement full_profiles =
      CheckStripes(ViewOf(rendered.image), layout, rendered.cMo, kCamera, full_only);
  EXPECT_EQ(full_profiles.samples[0], 0);
  EXPECT_EQ(full_profiles.Worst(), 0.0);
}

// Line 1 along the image's edge read with the full profiles only: nothing of it is read, and
// the other three agree: it is the one stripe unseen. Not so when a second stripe is unseen
// too, when one of its samples contradicts, or for a pose a degree and a half off (its stripes
// contradicted).
TEST(StripeCheck, TheOneStripeNoSampleTellsOfIsUnseen) {
  const SceneRenderer renderer(FourLineA3Target(), Render());
  const RenderedFrame rendered = renderer.Render(FrontoParallel(0.4, 0.09967, 0.0, 0.0), 8);
  const TargetLayout layout = TargetLayout::Of(FourLineA3Target());
  StripeCheckOptions full_only;
  full_only.short_profiles_at_edge = false;
  const StripeAgreement agreement =
      CheckStripes(ViewOf(rendered.image), layout, rendered.cMo, kCamera, full_only);
  EXPECT_EQ(agreement.Unseen(0.75), 0);
  StripeAgreement two_unseen = agreement;
  two_unseen.dark[2] = 2;
  two_unseen.contradict[2] = 0;
  EXPECT_EQ(two_unseen.Unseen(0.75), -1);
  StripeAgreement contradicted = agreement;
  contradicted.contradict[0] = 1;
  EXPECT_EQ(contradicted.Unseen(0.75), -1);

  const RenderedFrame tilted = renderer.Render(Tilted(), 7);
  const vpHomogeneousMatrix off =
      vpHomogeneousMatrix(0.0, 0.0, 0.0, 0.0, vpMath::rad(1.5), 0.0) * tilted.cMo;
  EXPECT_EQ(CheckStripes(ViewOf(tilted.image), layout, off, kCamera).Unseen(0.75), -1);
}

// A pose a degree and a half off moves the stripes' far ends off their ink: contradicted.
TEST(StripeCheck, APoseADegreeAndAHalfOffIsContradicted) {
  const SceneRenderer renderer(FourLineA3Target(), Render());
  const RenderedFrame rendered = renderer.Render(Tilted(), 7);
  const TargetLayout layout = TargetLayout::Of(FourLineA3Target());
  const vpHomogeneousMatrix off =
      vpHomogeneousMatrix(0.0, 0.0, 0.0, 0.0, vpMath::rad(1.5), 0.0) * rendered.cMo;
  const StripeAgreement agreement = CheckStripes(ViewOf(rendered.image), layout, off, kCamera);
  EXPECT_LT(agreement.Worst(), 0.75);
}

// At 1920x1080 (a 1371 px lens) the stripes are 2.285 times as many pixels wide: profiles read
// a point every 2.285 px, with the tolerance scaled alike, judge as at 640x480. The truth
// agrees along every stripe, a pose a degree and a half off is contradicted.
TEST(StripeCheck, ProfilesReadAPointEveryScaledPixelJudgeAsAtTheReferenceSize) {
  const Lens camera = Lens::WithKdu(1371.0, 1371.0, 959.5, 539.5, 0.15, 1920, 1080);
  RenderOptions render = Render();
  render.camera = camera;
  render.width = 1920;
  render.height = 1080;
  const SceneRenderer renderer(FourLineA3Target(), render);
  const RenderedFrame rendered = renderer.Render(Tilted(), 6);
  const TargetLayout layout = TargetLayout::Of(FourLineA3Target());
  StripeCheckOptions scaled;
  scaled.profile_step_px = 2.285;
  scaled.centre_tolerance_px = 2.285;
  const StripeAgreement truth =
      CheckStripes(ViewOf(rendered.image), layout, rendered.cMo, camera, scaled);
  for (int k = 0; k < 4; ++k) {
    EXPECT_GE(truth.samples[static_cast<std::size_t>(k)], 8) << "line " << k + 1;
    EXPECT_EQ(truth.dark[static_cast<std::size_t>(k)], truth.samples[static_cast<std::size_t>(k)])
        << "line " << k + 1;
  }
  const vpHomogeneousMatrix off =
      vpHomogeneousMatrix(0.0, 0.0, 0.0, 0.0, vpMath::rad(1.5), 0.0) * rendered.cMo;
  EXPECT_LT(CheckStripes(ViewOf(rendered.image), layout, off, camera, scaled).Worst(), 0.75);
  StripeCheckOptions bad;
  bad.profile_step_px = 0.1;
  EXPECT_THROW(bad.Check(), std::invalid_argument);
}

// The shift both edges of a stripe share: about a tenth of a pixel at the truth (the image's
// noise), also where a white cable over one side of line 3 moves that edge alone; a pose a tenth
// of a degree off, which the check still agrees with everywhere, moves both edges of the
// stripes the same way, by more than half a pixel.
TEST(StripeCheck, BothEdgesShiftTheSameWayOffThePoseNotUnderACableAlongOneSide) {
  const SceneRenderer renderer(FourLineA3Target(), Render());
  const TargetLayout layout = TargetLayout::Of(FourLineA3Target());
  const RenderedFrame plain = renderer.Render(Tilted(), 6);
  const StripeAgreement truth = CheckStripes(ViewOf(plain.image), layout, plain.cMo, kCamera);
  EXPECT_LT(truth.ShiftRms(), 0.2);
  const vpHomogeneousMatrix off =
      vpHomogeneousMatrix(0.0, 0.0, 0.0, 0.0, vpMath::rad(0.1), 0.0) * plain.cMo;
  const StripeAgreement shifted = CheckStripes(ViewOf(plain.image), layout, off, kCamera);
  EXPECT_EQ(shifted.Worst(), 1.0);
  EXPECT_GT(shifted.ShiftRms(), 0.5);
  EXPECT_GT(shifted.ShiftRms(), 3.0 * truth.ShiftRms());

  FrameEffects effects;
  PlaneOccluder cable;  // line 3 is 16 mm wide at x = 0.09: the cable covers its right 2 mm
  cable.capsules.push_back({0.1, -0.14, 0.1, 0.14, 0.004});
  cable.grey = 250;
  effects.plane_occluders.push_back(cable);
  const RenderedFrame covered = renderer.Render(Tilted(), 6, effects);
  const StripeAgreement under_cable =
      CheckStripes(ViewOf(covered.image), layout, covered.cMo, kCamera);
  EXPECT_GE(under_cable.dark[2], 4);
  EXPECT_LT(under_cable.shift_rms_px[2], 0.2);
}

// A hand over part of a stripe tells nothing there; a glare saturating ink and paper neither.
TEST(StripeCheck, AHandOrAGlareHidesWithoutContradicting) {
  const SceneRenderer renderer(FourLineA3Target(), Render());
  const TargetLayout layout = TargetLayout::Of(FourLineA3Target());
  FrameEffects effects;
  PlaneOccluder palm;
  palm.ellipses.push_back({-0.09, 0.10, 0.05, 0.04, 0.3});  // over line 1's lower arm
  palm.grey = 140;
  effects.plane_occluders.push_back(palm);
  effects.glares.push_back({0.15, -0.062, 0.015, 600.0});  // on line 2's right arm
  const RenderedFrame rendered = renderer.Render(Tilted(), 8, effects);
  const StripeAgreement agreement =
      CheckStripes(ViewOf(rendered.image), layout, rendered.cMo, kCamera);
  EXPECT_LT(agreement.dark[0], agreement.samples[0]);  // the hand hides some of line 1
  EXPECT_LT(agreement.dark[1], agreement.samples[1]);  // the glare some of line 2
  EXPECT_EQ(agreement.contradict[0] + agreement.contradict[1], 0);
  EXPECT_EQ(agreement.Worst(), 1.0);
}

// Something as light as the paper (a pale hand, a sheet, a glove) over the middle of line 1
// between the crossings: its profiles there are paper where the ink should be, next to samples
// that agree to a pixel. A wrong pose could not put them there (its stripe would be a few
// pixels off its ink at the next sample, not wholly beside it): they tell nothing.
TEST(StripeCheck, SomethingAsLightAsThePaperOverAStripeHidesWithoutContradicting) {
  const SceneRenderer renderer(FourLineA3Target(), Render());
  const TargetLayout layout = TargetLayout::Of(FourLineA3Target());
  FrameEffects effects;
  PlaneOccluder pale;
  pale.capsules.push_back({-0.09, -0.035, -0.09, 0.035, 0.025});
  pale.grey = FourLineA3Target().board_grey;
  effects.plane_occluders.push_back(pale);
  const RenderedFrame rendered = renderer.Render(Tilted(), 11, effects);
  const StripeAgreement agreement =
      CheckStripes(ViewOf(rendered.image), layout, rendered.cMo, kCamera);
  EXPECT_LE(agreement.dark[0] + 3, agreement.samples[0]);  // it hides line 1's middle
  EXPECT_EQ(agreement.contradict[0], 0);
  EXPECT_EQ(agreement.Worst(), 1.0);
}

// A pose 70 mm off across lines 1 and 3 puts both on bare paper along their whole length:
// paper where the ink should be, with no sample of theirs agreeing, contradicts.
TEST(StripeCheck, StripesWhollyOnBarePaperContradictThePose) {
  const SceneRenderer renderer(FourLineA3Target(), Render());
  const RenderedFrame rendered = renderer.Render(Tilted(), 12);
  const TargetLayout layout = TargetLayout::Of(FourLineA3Target());
  const vpHomogeneousMatrix off = rendered.cMo * vpHomogeneousMatrix(0.07, 0.0, 0.0, 0.0, 0.0, 0.0);
  const StripeAgreement agreement = CheckStripes(ViewOf(rendered.image), layout, off, kCamera);
  EXPECT_GE(agreement.contradict[0], agreement.samples[0] / 2);
  EXPECT_GE(agreement.contradict[2], agreement.samples[2] / 2);
  EXPECT_LT(agreement.Worst(), 0.75);
}

// A grey pen lying along line 1 over part of its width leaves a narrower dark run there, one
// edge the stripe's: it hides that part of the stripe and contradicts nothing (samples between
// agreeing ones are not excused as an occluder's rim).
TEST(StripeCheck, APenOverPartOfAStripesWidthHidesWithoutContradicting) {
  const SceneRenderer renderer(FourLineA3Target(), Render());
  const TargetLayout layout = TargetLayout::Of(FourLineA3Target());
  FrameEffects effects;
  // Line 1: 24 mm wide at x = -0.09; the pen covers x from -0.086 to -0.074 between the
  // crossings, with the stripe's ink in full on both sides of it.
  PlaneOccluder pen;
  pen.capsules.push_back({-0.08, -0.035, -0.08, 0.035, 0.006});
  pen.grey = 170;
  effects.plane_occluders.push_back(pen);
  const RenderedFrame rendered = renderer.Render(Tilted(), 10, effects);
  const StripeAgreement agreement =
      CheckStripes(ViewOf(rendered.image), layout, rendered.cMo, kCamera);
  EXPECT_LT(agreement.dark[0], agreement.samples[0]);  // the pen hides some of line 1
  EXPECT_EQ(agreement.contradict[0], 0);
  EXPECT_EQ(agreement.Worst(), 1.0);
}

// A glare beside a stripe lights the paper on one side of it and the ink next to it: each of
// the stripe's edges is read against the paper on its own side, and where the glare washes
// the ink out its profile is brighter than the sheet's paper and tells nothing.
TEST(StripeCheck, AGlaresSlopeAcrossAStripeDoesNotContradictIt) {
  const SceneRenderer renderer(FourLineA3Target(), Render());
  const TargetLayout layout = TargetLayout::Of(FourLineA3Target());
  for (const double offset : {0.012, 0.02, 0.03}) {
    FrameEffects effects;
    const Point2d beside = layout.OnStripe(1, 0.12, offset);
    effects.glares.push_back({beside.u, beside.v, 0.02, 500.0});
    const RenderedFrame rendered = renderer.Render(Tilted(), 9, effects);
    const StripeAgreement agreement =
        CheckStripes(ViewOf(rendered.image), layout, rendered.cMo, kCamera);
    EXPECT_EQ(agreement.contradict[1], 0) << "glare " << offset << " m beside line 2";
    EXPECT_EQ(agreement.Worst(), 1.0) << "glare " << offset << " m beside line 2";
  }
}

}  // namespace
}  // namespace oal
