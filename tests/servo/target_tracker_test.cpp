// The target tracker (servo/target_tracker.h) on rendered scenes of a printed sheet lying on a
// bench: found with no prior at many rolls (A3 and A4), followed from frame to frame, lost
// when the sheet leaves the view and found again when it comes back, and never a pose from a
// scene that holds clutter but no target.
#include "servo/target_tracker.h"

#include <gtest/gtest.h>
#include <visp3/core/vpMath.h>
#include <visp3/core/vpThetaUVector.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>

#include "scene/bench_scene.h"
#include "scene/scene.h"
#include "servo/pbvs.h"  // Se3Exp, Se3Log
#include "servo/target_layout.h"
#include "tests/scene/scene_image_util.h"

namespace oal {
namespace {

// A pose counted as right: within 2 % of the distance and 2 degrees (as pose-accuracy).
constexpr double kMaxTranslationFraction = 0.02;
constexpr double kMaxRotationDeg = 2.0;

// A photograph of Debian's visp-images-data as the bench, or a uniform grey without it.
std::shared_ptr<const vpImage<unsigned char>> Bench() {
  return testing::ReadPgm("/usr/share/visp-images-data/ViSP-images/Klimt/Klimt.pgm");
}

// 640x480, px = 600, a lens the camera file corrects (kdu 0.15), noise, blur, fall-off, the
// sheet's shadow and printed marks, other sheets and tools around it.
RenderOptions BenchRender(std::uint64_t scene_seed) {
  RenderOptions render;
  render.camera = Lens::WithKdu(600.0, 600.0, 319.5, 239.5, 0.15, 640, 480);
  render.noise_sigma = 4.0;
  render.blur_sigma_px = 1.0;
  render.background = Bench();
  DressAsBench(&render, scene_seed);
  return render;
}

TargetPoseTracker TrackerFor(const SceneRenderer& renderer) {
  PoseOptions pose;
  pose.camera = renderer.options().camera;
  pose.image_width = renderer.options().width;
  pose.image_height = renderer.options().height;
  return TargetPoseTracker(renderer.target(), renderer.options().camera, DetectorOptions(), pose);
}

// Something lying on the sheet: one capsule (a segment and its radius, metres on the plane).
PlaneOccluder Capsule(const PlaneOccluder::Capsule& capsule, int grey, double texture_grey = 0.0) {
  PlaneOccluder occluder;
  occluder.capsules.push_back(capsule);
  occluder.grey = grey;
  occluder.texture_grey = texture_grey;
  return occluder;
}

// Translation error over the distance, and rotation error in degrees.
std::pair<double, double> PoseError(const vpHomogeneousMatrix& cMo,
                                    const vpHomogeneousMatrix& cMo_true) {
  const vpTranslationVector t_true = cMo_true.getTranslationVector();
  const double t = (cMo.getTranslationVector() - t_true).frobeniusNorm() / t_true.frobeniusNorm();
  const double r =
      vpMath::deg(vpThetaUVector((cMo * cMo_true.inverse()).getRotationMatrix()).getTheta());
  return {t, r};
}

void ExpectRightPose(const TargetFrame& frame, const vpHomogeneousMatrix& cMo_true,
                     const std::string& what) {
  ASSERT_EQ(frame.status, TargetStatus::kOk) << what << ": " << frame.message;
  const auto [t, r] = PoseError(frame.pose.cMo, cMo_true);
  EXPECT_LT(t, kMaxTranslationFraction) << what;
  EXPECT_LT(r, kMaxRotationDeg) << what;
}

// Each frame on its own (no prior): the sheet's middle cell is found and the pose is right,
// whatever the roll, on A3 and A4 sheets.
TEST(TargetPoseTracker, FindsA3AndA4SheetsAtEveryRollWithoutAPrior) {
  // Each sheet over its range (A3 0.3-0.85 m, A4 0.25-0.6 m), as the evaluations view it.
  for (const LineTarget& target : {FourLineA3Target(), FourLineA4Target()}) {
    const SceneRenderer renderer(target, BenchRender(3));
    TargetPoseTracker tracker = TrackerFor(renderer);
    const PoseSampling sampling = SheetSampling(target);
    std::uint64_t state = 11;
    for (int frame = 0; frame < 12; ++frame) {
      // Rolls spread over the whole turn, 30 degrees apart, on top of the sampled pose.
      const vpHomogeneousMatrix roll(0, 0, 0, 0, 0, vpMath::rad(30.0 * frame));
      const vpHomogeneousMatrix sampled = SamplePose(renderer, sampling, &state);
      const vpHomogeneousMatrix cMo =
          CrossingsInView(renderer, roll * sampled, 10.0) ? roll * sampled : sampled;
      const RenderedFrame rendered = renderer.Render(cMo, 100 + frame);
      tracker.Reset();
      const TargetFrame& result = tracker.Track(ViewOf(rendered.image));
      ExpectRightPose(result, cMo, target.name + " frame " + std::to_string(frame));
      EXPECT_NE(result.source, ScanSource::kPrior);
      EXPECT_FALSE(result.region.empty()) << "the region scanned is reported";
    }
  }
}

// A candidate is scanned first on as few borders as a tracked frame; with the quick scan off
// (as the lens is told), on all of them at once, and the pose is right either way.
TEST(TargetPoseTracker, ACandidateIsScannedOnFewBordersFirstUnlessTheQuickScanIsOff) {
  const SceneRenderer renderer(FourLineA3Target(), BenchRender(7));
  TargetPoseTracker tracker = TrackerFor(renderer);
  const vpHomogeneousMatrix cMo(0.02, -0.01, 0.55, vpMath::rad(12), vpMath::rad(-9), 0.7);
  const RenderedFrame rendered = renderer.Render(cMo, 31);
  ASSERT_TRUE(tracker.quick_scan());
  const TargetFrame quick = tracker.Track(ViewOf(rendered.image));
  ExpectRightPose(quick, cMo, "quick scan");
  EXPECT_EQ(quick.source, ScanSource::kMiddleCell);
  EXPECT_LE(quick.borders, tracker.options().tracked_borders);
  EXPECT_LT(quick.pose.identification_cost, tracker.options().quick_max_identification_cost);

  tracker.Reset();
  tracker.set_quick_scan(false);
  const TargetFrame full = tracker.Track(ViewOf(rendered.image));
  ExpectRightPose(full, cMo, "full scan");
  EXPECT_GT(full.borders, tracker.options().tracked_borders);
  EXPECT_EQ(full.candidates, quick.candidates);

  // A cost bound of 0 could keep no quick scan: the configuration's way to turn it off.
  TargetTrackerOptions no_quick;
  no_quick.quick_max_identification_cost = 0.0;
  PoseOptions pose;
  pose.camera = renderer.options().camera;
  pose.image_width = renderer.options().width;
  pose.image_height = renderer.options().height;
  TargetPoseTracker configured(renderer.target(), renderer.options().camera, DetectorOptions(),
                               pose, no_quick);
  const TargetFrame by_options = configured.Track(ViewOf(rendered.image));
  ExpectRightPose(by_options, cMo, "quick scan off by the options");
  EXPECT_EQ(by_options.borders, full.borders);
}

// Without a middle cell (a sheet finder that can find none), the whole image's scan places the
// sheet, and the borders on the target's plane seen from its pose are scanned again: their
// pose is taken when it fits the target's corners better. Every accepted pose is right.
TEST(TargetPoseTracker, AWholeImagePoseIsScannedAgainOnTheTargetsPlane) {
  const SceneRenderer renderer(FourLineA3Target(), BenchRender(4));
  TargetTrackerOptions blind;
  blind.finder.min_area_fraction = 1.0;  // no light region covers the whole image
  PoseOptions pose;
  pose.camera = renderer.options().camera;
  pose.image_width = renderer.options().width;
  pose.image_height = renderer.options().height;
  TargetPoseTracker tracker(renderer.target(), renderer.options().camera, DetectorOptions(), pose,
                            blind);
  PoseSampling sampling = SheetSampling(renderer.target());
  sampling.max_distance_m = 0.45;  // near: the sheet's stripes cross the image's borders
  std::uint64_t state = 5;
  int accepted = 0, rescanned = 0;
  for (int frame = 0; frame < 12; ++frame) {
    const vpHomogeneousMatrix cMo = SamplePose(renderer, sampling, &state);
    tracker.Reset();
    const TargetFrame& result = tracker.Track(ViewOf(renderer.Render(cMo, 70 + frame).image));
    const std::string what = "frame " + std::to_string(frame);
    EXPECT_EQ(result.candidates, 0) << what;
    if (result.status != TargetStatus::kOk) continue;
    ++accepted;
    EXPECT_EQ(result.source, ScanSource::kImage) << what;
    if (result.borders > 0) {
      ++rescanned;
      EXPECT_FALSE(result.region.empty()) << what;
    }
    ExpectRightPose(result, cMo, what);
  }
  EXPECT_GT(accepted, 0) << "the whole image's scan never placed the sheet";
  EXPECT_GT(rescanned, 0) << "no pose came from the target's plane seen from the whole image's";
}

// A camera sliding over the sheet: every frame after the first is tracked from the last pose.
TEST(TargetPoseTracker, FollowsAMovingSheetFromItsLastPose) {
  const SceneRenderer renderer(FourLineA3Target(), BenchRender(5));
  TargetPoseTracker tracker = TrackerFor(renderer);
  const vpHomogeneousMatrix from(0.0, 0.0, 0.55, vpMath::rad(10), vpMath::rad(-8), 0.4);
  const vpHomogeneousMatrix to = vpHomogeneousMatrix(0.05, -0.03, 0.05, 0.05, -0.05, 0.2) * from;
  const vpColVector xi = Se3Log(to * from.inverse());
  constexpr int kFrames = 15;
  for (int frame = 0; frame < kFrames; ++frame) {
    const vpHomogeneousMatrix cMo = Se3Exp(xi * (frame / (kFrames - 1.0))) * from;
    const TargetFrame& result = tracker.Track(ViewOf(renderer.Render(cMo, frame).image));
    ExpectRightPose(result, cMo, "frame " + std::to_string(frame));
    if (frame > 0) {
      EXPECT_EQ(result.source, ScanSource::kPrior) << "frame " << frame;
    }
  }
}

// The straightness of lines 1-4 after the lens correction tells a camera file that matches
// the lens (kdu 0.15) from ones whose distortion is off by 0.1 or missing: on each frame (no
// right one contradicts its file, at most one wrong one fails to) and over every run of five.
TEST(TargetPoseTracker, StraightnessTellsARightCameraFileFromAWrongOne) {
  const SceneRenderer renderer(FourLineA3Target(), BenchRender(13));
  const PoseSampling sampling = SheetSampling(renderer.target());
  std::uint64_t random = 21;
  std::vector<vpImage<unsigned char>> frames;
  for (int k = 0; k < 40; ++k) {
    frames.push_back(renderer.Render(SamplePose(renderer, sampling, &random), 300 + k).image);
  }
  for (const double kdu : {0.15, 0.05, 0.25, 0.0}) {
    const bool right = kdu == 0.15;
    const Lens camera = Lens::WithKdu(600.0, 600.0, 319.5, 239.5, kdu, 640, 480);
    PoseOptions pose;
    pose.camera = camera;
    pose.image_width = 640;
    pose.image_height = 480;
    TargetPoseTracker tracker(renderer.target(), camera, DetectorOptions(), pose);
    tracker.set_measure_lens(true);
    std::vector<RadialBend> values;
    for (const vpImage<unsigned char>& frame : frames) {
      tracker.Reset();
      const TargetFrame& result = tracker.Track(ViewOf(frame));
      if (result.status == TargetStatus::kOk) values.push_back(result.lens);
    }
    ASSERT_GE(values.size(), 35u) << "kdu " << kdu;
    int contradicting = 0;
    for (const RadialBend& value : values) {
      if (right) {  // no single frame of the right file bends: no stray point, no run-end effect
        EXPECT_FALSE(ContradictsLens(value)) << value.kdu_error << " +- " << value.kdu_error_sd;
        EXPECT_LT(value.bend_px, 0.1);
      }
      contradicting += ContradictsLens(value);
    }
    if (!right) {
      EXPECT_GE(contradicting, static_cast<int>(values.size()) - 1) << "kdu " << kdu;
    }
    for (std::size_t first = 0; first + 5 <= values.size(); first += 5) {
      const LensCheck check =
          CheckLens(std::vector<RadialBend>(values.begin() + first, values.begin() + first + 5));
      EXPECT_EQ(check.mismatch, !right)
          << "kdu " << kdu << ", frames from " << first << ": median " << check.median_px << " px";
      // The camera's kdu less the lens's, as the lines tell it.
      EXPECT_NEAR(check.median_kdu_error, kdu - 0.15, 0.03) << "kdu " << kdu;
    }
  }
  RadialBend bent;
  bent.kdu_error = 0.1;
  bent.kdu_error_sd = 0.01;
  EXPECT_FALSE(CheckLens({bent, bent}).mismatch) << "two frames are too few to judge";
  EXPECT_TRUE(CheckLens({bent, bent, RadialBend{}}).mismatch);
  EXPECT_FALSE(CheckLens({bent, RadialBend{}, RadialBend{}}).mismatch) << "one frame of three";
  EXPECT_EQ(CheckLens({}).frames, 0);
}

// The lens is measured on every pose only when asked (the pose command's lens check); by
// default only a pose the model check refuses is, to say whether the lens is why.
TEST(TargetPoseTracker, MeasuresEachPosesLensOnlyWhenAsked) {
  const SceneRenderer renderer(FourLineA3Target(), BenchRender(13));
  std::uint64_t random = 5;
  const vpImage<unsigned char> image =
      renderer.Render(SamplePose(renderer, SheetSampling(renderer.target()), &random), 7).image;
  const Lens camera = Lens::WithKdu(600.0, 600.0, 319.5, 239.5, 0.15, 640, 480);
  PoseOptions pose;
  pose.camera = camera;
  TargetPoseTracker tracker(renderer.target(), camera, DetectorOptions(), pose);
  ASSERT_EQ(tracker.Track(ViewOf(image)).status, TargetStatus::kOk);
  const TargetFrame& unasked = tracker.Track(ViewOf(image));
  EXPECT_EQ(unasked.lens.lines, 0);
  EXPECT_FALSE(MeasuresLens(unasked));
  tracker.set_measure_lens(true);
  const TargetFrame& frame = tracker.Track(ViewOf(image));
  ASSERT_EQ(frame.status, TargetStatus::kOk);
  EXPECT_TRUE(MeasuresLens(frame));
  EXPECT_GE(frame.lens.lines, 3);
  EXPECT_TRUE(std::isfinite(frame.lens.kdu_error_sd));
}

// The stripes' points lie on their centre lines' images: on a sheet tilted 45 degrees, a run's
// middle between the two converging edges is off the centre line's image by a shift that
// changes with the border's direction (enough to bend a stripe as a lens would); moved back
// along the run, the points stay on it.
TEST(TargetPoseTracker, TheStripesPointsLieOnTheirCentreLines) {
  RenderOptions render;
  render.camera = Lens::WithKdu(600.0, 600.0, 319.5, 239.5, 0.0, 640, 480);
  render.blur_sigma_px = 1.0;
  const SceneRenderer renderer(FourLineA3Target(), render);
  TargetPoseTracker tracker = TrackerFor(renderer);
  tracker.set_quick_scan(false);  // every border, as the lens is told
  const TargetLayout layout = TargetLayout::Of(renderer.target());
  double worst_mean = 0.0;  // px, the largest mean distance of a stripe's points from its line
  for (const double tilt_deg : {-45.0, 45.0}) {
    const vpHomogeneousMatrix cMo(0.0, 0.0, 0.5, vpMath::rad(tilt_deg), 0.0, vpMath::rad(20.0));
    tracker.Reset();
    ASSERT_EQ(tracker.Track(ViewOf(renderer.Render(cMo, 1).image)).status, TargetStatus::kOk);
    const vpHomography plane_to_image = PlaneToImage(cMo);
    const std::array<std::vector<Point2d>, 4> stripes = tracker.StripePoints(6.0);
    for (int k = 0; k < 4; ++k) {
      // The true centre line, in pixels: through the images of its printed ends.
      const StripeSpan& span = layout.stripes[static_cast<std::size_t>(k)];
      Point2d ends[2];
      for (int e = 0; e < 2; ++e) {
        const Point2d plane = layout.OnStripe(k, e == 0 ? span.along.lo : span.along.hi, 0.0);
        const vpColVector x = plane_to_image * vpColVector({plane.u, plane.v, 1.0});
        ends[e] = {319.5 + 600.0 * x[0] / x[2], 239.5 + 600.0 * x[1] / x[2]};
      }
      const double nu = ends[0].v - ends[1].v, nv = ends[1].u - ends[0].u;
      const double norm = std::hypot(nu, nv);
      const std::vector<Point2d>& points = stripes[static_cast<std::size_t>(k)];
      ASSERT_GE(points.size(), 12u);
      double sum = 0.0;
      for (const Point2d& p : points) {
        sum += (nu * (p.u - ends[0].u) + nv * (p.v - ends[0].v)) / norm;
      }
      worst_mean = std::max(worst_mean, std::fabs(sum / points.size()));
    }
  }
  // The run middles themselves are off by up to 0.07 px on average over a stripe here.
  EXPECT_LT(worst_mean, 0.04);
}

// The sheet slides out of view (no pose, never a wrong one) and comes back (found again).
// A hand lying over one side of a stripe, from its crossing to its end: every border meets
// that stripe there, so no border pairs its points into a line; its points on the other side
// still fit the pose, the target held rigid, from where the middle cell puts it. Right, and
// the hand's samples excused by the model check.
TEST(TargetPoseTracker, AStripeHiddenOnOneSideIsFittedFromTheOther) {
  const LineTarget target = FourLineA3Target();
  const SceneRenderer renderer(target, BenchRender(5));
  TargetPoseTracker tracker = TrackerFor(renderer);
  FrameEffects effects;
  // An arm over line 4 (y = +0.062) from x = 0.101 to beyond the sheet's edge.
  effects.plane_occluders.push_back(Capsule({0.126, 0.062, 0.30, 0.062, 0.025}, 120, 10.0));
  const vpHomogeneousMatrix cMo(0.01, -0.02, 0.55, 0.2, -0.15, 0.3);
  const RenderedFrame frame = renderer.Render(cMo, 4, effects);
  ASSERT_GT(frame.truth[3].occluded_fraction, 0.2);  // all of it right of the crossing
  const TargetFrame& found = tracker.Track(ViewOf(frame.image));
  ExpectRightPose(found, cMo, "line 4 half hidden");
  EXPECT_TRUE(found.fit.ok);  // the pose the stripes' points hold
  EXPECT_GT(found.fit.points[3], 0);
  // Only the stretch the arm leaves: x from -0.2 to 0.101 of the stripe's 0.4 m (0.75). The
  // concentric borders give line 4's left arm only (a quarter of it): the pose is scanned
  // again with borders across the stripes' middles, which give the rest of that stretch.
  EXPECT_LT(found.fit.extent[3], 0.76);
  EXPECT_GT(found.fit.extent[3], 0.5);
}

// Line 4 hidden on both sides beyond the crossings (an arm over one side, a tool over the
// other): the concentric borders meet it only there and give it no points. The borders across
// the stripes' middles do: right, line 4 fitted on its stretch between the crossings.
TEST(TargetPoseTracker, AStripeSeenOnlyBetweenTheCrossingsIsFittedThere) {
  const LineTarget target = FourLineA3Target();
  const SceneRenderer renderer(target, BenchRender(5));
  FrameEffects effects;
  PlaneOccluder arm, tool;  // over line 4 (y = +0.062) beyond x = +-0.1
  arm.capsules.push_back({0.127, 0.062, 0.30, 0.062, 0.025});
  arm.grey = 120;
  arm.texture_grey = 10.0;
  tool.capsules.push_back({-0.127, 0.062, -0.30, 0.062, 0.025});
  tool.grey = 90;
  effects.plane_occluders = {arm, tool};
  for (const double roll : {0.3, 1.9}) {
    const vpHomogeneousMatrix cMo(0.01, -0.02, 0.55, 0.2, -0.15, roll);
    const RenderedFrame frame = renderer.Render(cMo, 4, effects);
    ASSERT_GT(frame.truth[3].occluded_fraction, 0.4);
    TargetPoseTracker tracker = TrackerFor(renderer);
    const TargetFrame& found = tracker.Track(ViewOf(frame.image));
    ExpectRightPose(found, cMo, "line 4 seen between the crossings, roll " + std::to_string(roll));
    EXPECT_EQ(found.pose.method, PoseMethod::kStripes);
    EXPECT_GT(found.fit.points[3], 0);
    EXPECT_LT(found.fit.extent[3], 0.5);  // x from -0.1 to 0.1 of the stripe's 0.4 m
  }
}

// An A4 sheet turned upside down, smeared by 10 px of motion across lines 2 and 4, a lamp's
// glare washing out line 4's arm beyond line 1: the concentric borders leave line 4 a few
// points on its other arm, a fifth of it, and their pose tilts about it by two degrees. Scanned
// again from that pose with the borders across the stripes' middles, it is right.
TEST(TargetPoseTracker, AStripeSeenOverAShortStretchIsScannedAgainAcrossItsMiddle) {
  const LineTarget target = FourLineA4Target();
  const SceneRenderer renderer(target, BenchRender(16));
  FrameEffects effects;
  effects.glares.push_back({-0.110, 0.047, 0.0237, 249.0});
  effects.motion_blur_px = 10.1;
  effects.motion_blur_angle_rad = 1.306;
  vpHomogeneousMatrix cMo;
  const double m[3][4] = {{-0.9978, 0.0619, 0.0225, -0.0987},
                          {-0.062, -0.9981, -0.0025, -0.0056},
                          {0.0223, -0.0039, 0.9997, 0.547}};
  vpRotationMatrix rotation;
  for (unsigned r = 0; r < 3; ++r) {
    for (unsigned c = 0; c < 3; ++c) rotation[r][c] = m[r][c];
  }
  cMo.buildFrom(vpTranslationVector(m[0][3], m[1][3], m[2][3]),
                vpRotationMatrix(vpThetaUVector(rotation)));
  TargetPoseTracker tracker = TrackerFor(renderer);
  const TargetFrame& found = tracker.Track(ViewOf(renderer.Render(cMo, 17, effects).image));
  ExpectRightPose(found, cMo, "line 4 washed out on one arm");
  // The borders across the stripes' middles were scanned.
  EXPECT_GT(found.borders, TargetTrackerOptions().borders);
}

// A lamp's glare across a stripe between two crossings joins the middle cell to the paper
// beyond it: no cell is closed in on four sides, and the cells closed in on three are taken
// for the cells beyond a stripe, out to the sheet's edge.
TEST(TargetPoseTracker, AGlareAcrossTheMiddleCellsSideFindsTheSheetFromAnEdgeCell) {
  const LineTarget target = FourLineA3Target();
  const SceneRenderer renderer(target, BenchRender(6));
  TargetPoseTracker tracker = TrackerFor(renderer);
  FrameEffects effects;
  effects.glares.push_back({0.0, -0.062, 0.02, 900.0});  // on line 2 between lines 1 and 3
  const vpHomogeneousMatrix cMo(0.0, 0.01, 0.6, -0.15, 0.2, 1.1);
  const RenderedFrame frame = renderer.Render(cMo, 5, effects);
  const TargetFrame& found = tracker.Track(ViewOf(frame.image));
  ExpectRightPose(found, cMo, "glare across line 2");
  EXPECT_EQ(found.source, ScanSource::kEdgeCell);
}

// A lamp's broad glare over the middle of the sheet, at 1280x720 (a 720p webcam, 70 degrees
// across): the stripes washed out between the crossings join the middle cell to the four cells
// beyond the stripes. A corner's paper, closed in by two stripes alone (the margin beyond the
// stripes' ends is narrower than the finder's cells), is taken for each of the sheet's corner
// cells in turn: the right pose, from a corner cell. At another roll the cells beyond the
// stripes meet the middle one through necks the finder splits them at (SheetFinder::
// FindSplitAtNecks), and a cell beyond a stripe gives the right pose first.
TEST(TargetPoseTracker, ABroadGlareOverTheMiddleAt720pFindsTheSheetFromACornerCell) {
  const LineTarget target = FourLineA3Target();
  RenderOptions render = BenchRender(4);
  render.camera = Lens::WithKdu(914.0, 914.0, 639.5, 359.5, 0.15, 1280, 720);
  render.width = 1280;
  render.height = 720;
  const SceneRenderer renderer(target, render);
  FrameEffects effects;
  effects.glares.push_back({0.0, 0.0, 0.05, 700.0});
  effects.motion_blur_px = 5.0;
  effects.motion_blur_angle_rad = 2.3;
  effects.jpeg_quality = 62;
  for (const double roll : {2.95, 1.0}) {
    const vpHomogeneousMatrix cMo(0.02, -0.05, 0.45, 0.09, -0.28, roll);
    const RenderedFrame frame = renderer.Render(cMo, 9, effects);
    TargetPoseTracker tracker = TrackerFor(renderer);
    const TargetFrame& found = tracker.Track(ViewOf(frame.image));
    const std::string what = "a broad glare at 720p, roll " + std::to_string(roll);
    ExpectRightPose(found, cMo, what);
    if (roll == 2.95) {
      EXPECT_EQ(found.source, ScanSource::kEdgeCell) << what;
      continue;
    }
    EXPECT_EQ(found.source, ScanSource::kCornerCell) << what;
    // Without the corner cells, nothing else finds it.
    TargetTrackerOptions options;
    options.corner_cells = false;
    PoseOptions pose;
    pose.camera = render.camera;
    TargetPoseTracker without(target, render.camera, DetectorOptions(), pose, options);
    EXPECT_NE(without.Track(ViewOf(frame.image)).status, TargetStatus::kOk) << what;
  }
}

// A dark cable lying against line 3 along its length: its runs there are half as wide again
// as the stripe and their middles off its centre line. No pose, or a right one, at any roll.
TEST(TargetPoseTracker, ACableAgainstAStripeGivesNoWrongPose) {
  const LineTarget target = FourLineA3Target();
  const SceneRenderer renderer(target, BenchRender(8));
  FrameEffects effects;
  // Line 3 is 16 mm wide at x = 0.09: the cable touches its right edge.
  effects.plane_occluders.push_back(Capsule({0.102, -0.14, 0.102, 0.14, 0.004}, 25));
  for (const double roll : {0.3, 1.4, 2.6}) {
    const vpHomogeneousMatrix cMo(0.01, -0.02, 0.55, 0.15, -0.1, roll);
    TargetPoseTracker tracker = TrackerFor(renderer);
    const TargetFrame& found = tracker.Track(ViewOf(renderer.Render(cMo, 6, effects).image));
    if (found.status != TargetStatus::kOk) continue;
    const auto [t, r] = PoseError(found.pose.cMo, cMo);
    EXPECT_LT(t, kMaxTranslationFraction) << "roll " << roll;
    EXPECT_LT(r, kMaxRotationDeg) << "roll " << roll;
  }
}

// A white cable lying over one side of line 3 along its length, at 640x480 and 1920x1080: the
// stripe's runs are a quarter narrower and their middles off its centre line, all the same way;
// fitted with the others, they tilt the pose. No pose, or a right one, at any roll and distance.
TEST(TargetPoseTracker, AWhiteCableOverOneSideOfAStripeGivesNoWrongPose) {
  const LineTarget target = FourLineA3Target();
  FrameEffects effects;
  // Line 3 is 16 mm wide at x = 0.09: the cable covers its right 4 mm.
  effects.plane_occluders.push_back(Capsule({0.098, -0.14, 0.103, 0.14, 0.004}, 250));
  for (const bool full_hd : {false, true}) {
    RenderOptions render = BenchRender(8);
    if (full_hd) {
      render.camera = Lens::WithKdu(1371.0, 1371.0, 959.5, 539.5, 0.15, 1920, 1080);
      render.width = 1920;
      render.height = 1080;
    }
    const SceneRenderer renderer(target, render);
    int posed = 0;
    for (const double distance : {0.55, 0.8, 1.0}) {
      for (const double roll : {0.3, 1.4, 2.6, 4.0}) {
        const vpHomogeneousMatrix cMo(0.01, -0.02, distance, 0.2, -0.15, roll);
        TargetPoseTracker tracker = TrackerFor(renderer);
        const TargetFrame& found = tracker.Track(ViewOf(renderer.Render(cMo, 6, effects).image));
        if (found.status != TargetStatus::kOk) continue;
        ++posed;
        const auto [t, r] = PoseError(found.pose.cMo, cMo);
        const std::string what = std::string(full_hd ? "1080p" : "640x480") + ", distance " +
                                 std::to_string(distance) + ", roll " + std::to_string(roll);
        EXPECT_LT(t, kMaxTranslationFraction) << what;
        EXPECT_LT(r, kMaxRotationDeg) << what;
      }
    }
    EXPECT_GT(posed, 0) << (full_hd ? "1080p" : "640x480");
  }
}

// A dark grey cable lying along line 2 and crossing it at a shallow angle, smeared into the
// stripe by a vertical motion blur, at 640x480 and 1920x1080: below the stripe at one end, over
// its middle, above it at the other. Many of the stripe's runs are wider and their middles off
// its centre line, one way at one end and the other way at the other: fitted with the others,
// they turn the pose by two to three degrees (at 0.75 m at 640x480, most noise seeds). The
// stripe, seen over a third of its length where the cable leaves it, then holds the pose's tilt
// alone, and the other three put it degrees away. No pose, or a right one, and some poses at
// each size, over rolls and distances about those (at 640x480, 7 of 70 poses were wrong before
// the stripes were checked against each other). Farther, 0.85-0.9 m, its few runs hold the
// tilt with the other three fixing it far more loosely, and the four's deviation, from their
// scatter, is a tenth of their error (12 of 33 poses there were wrong before that was checked).
TEST(TargetPoseTracker, ADarkCableAlongAStripeUnderMotionBlurGivesNoWrongPose) {
  const LineTarget target = FourLineA3Target();
  const std::array<std::array<double, 2>, 8> cable_bends = {{{-0.29, -0.026},
                                                             {-0.195, -0.047},
                                                             {-0.099, -0.057},
                                                             {0.0, -0.065},
                                                             {0.094, -0.069},
                                                             {0.19, -0.073},
                                                             {0.286, -0.083},
                                                             {0.48, -0.108}}};
  PlaneOccluder cable;
  cable.grey = 65;
  cable.texture_grey = 12.0;
  for (std::size_t k = 0; k + 1 < cable_bends.size(); ++k) {
    cable.capsules.push_back({cable_bends[k][0], cable_bends[k][1], cable_bends[k + 1][0],
                              cable_bends[k + 1][1], 0.0035});
  }
  FrameEffects effects;
  effects.plane_occluders.push_back(cable);
  effects.motion_blur_angle_rad = 1.55;
  effects.jpeg_quality = 84;
  for (const bool full_hd : {false, true}) {
    RenderOptions render = BenchRender(3);
    render.noise_sigma = 7.8;
    render.blur_sigma_px = 1.2;
    effects.motion_blur_px = 4.5;
    if (full_hd) {
      render.camera = Lens::WithKdu(1371.0, 1371.0, 959.5, 539.5, 0.15, 1920, 1080);
      render.width = 1920;
      render.height = 1080;
      effects.motion_blur_px = 10.0;
    }
    const SceneRenderer renderer(target, render);
    int posed = 0;
    const std::vector<double> rolls = full_hd ? std::vector<double>{-2.76, -2.2}
                                              : std::vector<double>{-2.9, -2.76, -2.5, -2.2, -2.0};
    const std::vector<double> distances = full_hd
                                              ? std::vector<double>{0.6, 0.75}
                                              : std::vector<double>{0.6, 0.7, 0.75, 0.8, 0.85, 0.9};
    for (const double roll : rolls) {
      for (const double distance : distances) {
        for (const std::uint64_t noise_seed : {1, 2, 3, 4}) {
          const vpHomogeneousMatrix cMo(0.029, -0.051, distance, 0.018, 0.176, roll);
          TargetPoseTracker tracker = TrackerFor(renderer);
          const TargetFrame& found =
              tracker.Track(ViewOf(renderer.Render(cMo, noise_seed, effects).image));
          if (found.status != TargetStatus::kOk) continue;
          ++posed;
          const auto [t, r] = PoseError(found.pose.cMo, cMo);
          const std::string what = std::string(full_hd ? "1080p" : "640x480") + ", distance " +
                                   std::to_string(distance) + ", roll " + std::to_string(roll) +
                                   ", noise seed " + std::to_string(noise_seed);
          EXPECT_LT(t, kMaxTranslationFraction) << what;
          EXPECT_LT(r, kMaxRotationDeg) << what;
        }
      }
    }
    EXPECT_GT(posed, 8) << (full_hd ? "1080p" : "640x480");
  }
}

// A tool lying across the middle cell, parallel to line 4 and clear of it: the light cell the
// sheet finder sees ends at the tool's edge, a quadrilateral closed in on four sides that is not
// the middle cell's shape. Taken as cut by something lying across it, it is lengthened back.
TEST(TargetPoseTracker, AToolAcrossTheMiddleCellIsSeenPast) {
  const LineTarget target = FourLineA3Target();
  const SceneRenderer renderer(target, BenchRender(11));
  FrameEffects effects;
  effects.plane_occluders.push_back(Capsule({-0.25, 0.028, 0.25, 0.028, 0.014}, 110, 6.0));
  for (const double roll : {0.2, 2.0}) {
    const vpHomogeneousMatrix cMo(0.0, 0.0, 0.5, 0.1, -0.12, roll);
    TargetPoseTracker tracker = TrackerFor(renderer);
    const TargetFrame& found = tracker.Track(ViewOf(renderer.Render(cMo, 12, effects).image));
    ExpectRightPose(found, cMo, "a tool across the middle cell, roll " + std::to_string(roll));
    // Read as the middle cell it is (not as a cell beyond a stripe, which it is not).
    EXPECT_EQ(found.source, ScanSource::kMiddleCell);
  }
}

// A forearm lying across the sheet over half the middle cell and beyond both sides of it:
// the light cell left is closed in on three sides by stripes and on the fourth by the arm,
// which nothing light follows within reach. The sheet is found past it (the cell lengthened
// back to the middle cell's shape, or a cell beyond a stripe), at either roll.
TEST(TargetPoseTracker, AnArmAcrossHalfTheMiddleCellIsSeenPast) {
  const LineTarget target = FourLineA3Target();
  const SceneRenderer renderer(target, BenchRender(12));
  FrameEffects effects;
  effects.plane_occluders.push_back(Capsule({-0.35, 0.01, 0.35, 0.01, 0.03}, 120, 8.0));
  for (const double roll : {0.4, 2.2}) {
    const vpHomogeneousMatrix cMo(0.0, 0.0, 0.5, 0.1, -0.12, roll);
    TargetPoseTracker tracker = TrackerFor(renderer);
    const TargetFrame& found = tracker.Track(ViewOf(renderer.Render(cMo, 13, effects).image));
    ExpectRightPose(found, cMo, "an arm across the middle cell, roll " + std::to_string(roll));
  }
}

// A pale forearm, a tenth darker than the paper, from the middle cell across line 2 and off the
// sheet: the middle cell, joined to the arm and the cell beyond, is found again with the arm
// taken as dark (the finder's last pass), at either roll.
TEST(TargetPoseTracker, APaleArmAcrossTheMiddleCellIsSeenPast) {
  const LineTarget target = FourLineA3Target();
  const SceneRenderer renderer(target, BenchRender(14));
  FrameEffects effects;
  effects.plane_occluders.push_back(
      Capsule({0.0, -0.02, 0.04, -0.3, 0.022}, static_cast<int>(0.9 * target.board_grey), 5.0));
  for (const double roll : {0.5, 2.5}) {
    const vpHomogeneousMatrix cMo(0.01, 0.0, 0.5, 0.12, -0.1, roll);
    TargetPoseTracker tracker = TrackerFor(renderer);
    const TargetFrame& found = tracker.Track(ViewOf(renderer.Render(cMo, 15, effects).image));
    ExpectRightPose(found, cMo, "a pale arm across the middle cell, roll " + std::to_string(roll));
  }
}

// The settings in pixels follow the camera: a 1920x1080 webcam 70 degrees across (1371 px)
// gets the detector's and the sheet finder's settings of a 600 px camera 2.285 times; with
// reference_focal_px 0 they are used as given.
TEST(TargetPoseTracker, ItsSettingsInPixelsFollowTheCamerasFocalLength) {
  const Lens camera = Lens::WithKdu(1371.0, 1371.0, 959.5, 539.5, 0.15, 1920, 1080);
  PoseOptions pose;
  pose.camera = camera;
  const TargetPoseTracker scaled(FourLineA3Target(), camera, DetectorOptions(), pose);
  EXPECT_EQ(scaled.detector().options().step_px, DetectorOptions().ScaledBy(2.285).step_px);
  EXPECT_DOUBLE_EQ(scaled.detector().options().max_width_px, 80.0 * 2.285);
  EXPECT_EQ(scaled.detector().options().region_sample_step, 2);
  TargetTrackerOptions as_given;
  as_given.reference_focal_px = 0.0;
  const TargetPoseTracker unscaled(FourLineA3Target(), camera, DetectorOptions(), pose, as_given);
  EXPECT_EQ(unscaled.detector().options().step_px, DetectorOptions().step_px);
  EXPECT_DOUBLE_EQ(as_given.PixelScale(camera), 1.0);
  EXPECT_DOUBLE_EQ(TargetTrackerOptions().ScaledBy(2.0).finder.cell_px, 16);
  // The model check's profiles: a point every 2 px at twice the focal length, every pixel
  // still at half of it.
  EXPECT_DOUBLE_EQ(TargetTrackerOptions().ScaledBy(2.0).stripe_profile_step_px, 2.0);
  EXPECT_DOUBLE_EQ(TargetTrackerOptions().ScaledBy(0.5).stripe_profile_step_px, 1.0);
  TargetTrackerOptions bad_step;
  bad_step.stripe_profile_step_px = 0.1;
  EXPECT_THROW(bad_step.Check(), std::invalid_argument);
  TargetTrackerOptions bad;
  bad.reference_focal_px = 0.5;
  EXPECT_THROW(bad.Check(), std::invalid_argument);
}

// A lens about 100 degrees across (OpenCV's model, strong barrel), the sheet in the image's
// bottom-right corner and running out of it: there a run across a stripe is a third shorter in
// the image than on the ideal one, and the runs' widths are held against the stripes' in ideal
// pixels.
TEST(TargetPoseTracker, FindsTheSheetInTheCornerOfAWideLens) {
  Distortion barrel;
  barrel.k1 = -0.28, barrel.k2 = 0.08, barrel.p1 = 0.0006, barrel.p2 = -0.0004, barrel.k3 = -0.01;
  RenderOptions render;
  render.camera = Lens::WithDistortion(730.0, 730.0, 642.5, 357.5, barrel);
  render.width = 1280;
  render.height = 720;
  render.noise_sigma = 3.0;
  render.blur_sigma_px = 0.8;
  const SceneRenderer renderer(FourLineA3Target(), render);
  const vpHomogeneousMatrix cMo(0.199, 0.117, 0.408, 0.527, -0.272, 2.945);
  TargetPoseTracker tracker = TrackerFor(renderer);
  ExpectRightPose(tracker.Track(ViewOf(renderer.Render(cMo, 1).image)), cMo, "in the corner");
}

TEST(TargetPoseTracker, LosesTheSheetOutOfViewAndFindsItAgain) {
  const SceneRenderer renderer(FourLineA3Target(), BenchRender(7));
  TargetPoseTracker tracker = TrackerFor(renderer);
  const vpHomogeneousMatrix centred(0.0, 0.0, 0.5, 0.0, 0.0, 0.3);
  // The camera slides sideways by up to 0.6 m (the sheet is 0.42 m wide) and back.
  const double shifts_m[] = {0.0, 0.0, 0.3, 0.6, 0.6, 0.3, 0.05, 0.0, 0.0};
  bool lost = false, found_again = false;
  for (std::size_t frame = 0; frame < std::size(shifts_m); ++frame) {
    const vpHomogeneousMatrix cMo = vpHomogeneousMatrix(-shifts_m[frame], 0, 0, 0, 0, 0) * centred;
    const RenderedFrame rendered = renderer.Render(cMo, 40 + frame);
    const TargetFrame& result = tracker.Track(ViewOf(rendered.image));
    const std::string what = "frame " + std::to_string(frame);
    if (CrossingsInView(renderer, cMo, 10.0)) {
      if (lost && result.status == TargetStatus::kOk) found_again = true;
      if (frame + 1 == std::size(shifts_m)) ExpectRightPose(result, cMo, what);
    } else {
      lost = true;
    }
    if (result.status == TargetStatus::kOk) {
      const auto [t, r] = PoseError(result.pose.cMo, cMo);
      EXPECT_LT(t, kMaxTranslationFraction) << what << ": a wrong pose was passed on";
      EXPECT_LT(r, kMaxRotationDeg) << what << ": a wrong pose was passed on";
    }
  }
  EXPECT_TRUE(lost) << "the sheet never left the view";
  EXPECT_TRUE(found_again);
}

// A bench with sheets of text and tools but no target: no pose, from any of the scans.
// A lines' pose that the stripes' own points do not hold (here: no stripe can keep the
// thousand points the fit is told to need) is not taken, and the frame says why.
TEST(TargetPoseTracker, ALinesPoseTheStripesPointsDoNotHoldIsNotTaken) {
  const SceneRenderer renderer(FourLineA3Target(), BenchRender(9));
  PoseOptions pose;
  pose.camera = renderer.options().camera;
  TargetTrackerOptions options;
  options.stripe_fit.min_points = 1000;
  options.image_fallback = false;
  TargetPoseTracker tracker(renderer.target(), renderer.options().camera, DetectorOptions(), pose,
                            options);
  const vpHomogeneousMatrix cMo(0.01, -0.02, 0.55, 0.1, -0.05, 0.3);
  const TargetFrame& found = tracker.Track(ViewOf(renderer.Render(cMo, 3).image));
  EXPECT_NE(found.status, TargetStatus::kOk);
  EXPECT_NE(found.message.find("keeps"), std::string::npos) << found.message;
  options.stripe_fit.min_points = 4;
  TargetPoseTracker holding(renderer.target(), renderer.options().camera, DetectorOptions(), pose,
                            options);
  ExpectRightPose(holding.Track(ViewOf(renderer.Render(cMo, 3).image)), cMo, "min_points 4");
}

TEST(TargetPoseTracker, NoPoseFromClutterWithoutATarget) {
  RenderOptions render = BenchRender(9);
  render.clutter_sheets = 6;
  render.clutter_objects = 12;
  render.clutter_reach_m = 0.4;
  const SceneRenderer renderer(FourLineA3Target(), render);
  TargetPoseTracker tracker = TrackerFor(renderer);
  // The camera looks at the bench 0.72-0.86 m from the sheet's centre (its view reaches about
  // 0.4 m around the axis at 0.6 m; the sheet, 0.26 m to its corners, stays out of it), where
  // the clutter lies (up to 0.4 m from the sheet's edges).
  for (int frame = 0; frame < 8; ++frame) {
    const double beside_m = 0.72 + 0.02 * frame;
    const vpHomogeneousMatrix cMo(-beside_m, 0.1 * (frame % 3), 0.6, 0.1, -0.1,
                                  vpMath::rad(40.0 * frame));
    ASSERT_FALSE(CrossingsInView(renderer, cMo, 0.0));
    tracker.Reset();
    const TargetFrame& result = tracker.Track(ViewOf(renderer.Render(cMo, 60 + frame).image));
    EXPECT_NE(result.status, TargetStatus::kOk) << "frame " << frame << ": a pose from clutter";
  }
}

// A pose the image does not support is refused with a status: a blank sheet (the stripes
// missing) where the prior puts the target.
TEST(TargetPoseTracker, APriorOnABlankPageGivesNoPose) {
  const SceneRenderer renderer(FourLineA3Target(), BenchRender(3));
  TargetPoseTracker tracker = TrackerFor(renderer);
  const vpHomogeneousMatrix cMo(0.0, 0.0, 0.5, 0.1, 0.0, 0.2);
  vpImage<unsigned char> blank(480, 640, 200);
  const TargetFrame& result = tracker.Track(ViewOf(blank), cMo);
  EXPECT_NE(result.status, TargetStatus::kOk);
  EXPECT_FALSE(result.message.empty());
}

}  // namespace
}  // namespace oal
