#include "servo/target_tracker.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <sstream>
#include <stdexcept>

#include "base/angles.h"
#include "base/clock.h"
#include "base/pose_distance.h"
#include "base/statistics.h"
#include "detector/lens.h"  // DistortedPixel
#include "detector/options.h"

namespace oal {
namespace {

// A fit from an expected pose that may be turned by 180 degrees: the other way round must fit
// the runs' widths worse by this (FitExpected's score).
constexpr double kWaysRoundMargin = 0.1;
// A detected line guides a stripe's first fit when within this fraction of the spacing of the
// stripe and its parallel partner of where the expected pose puts the stripe (over the
// stripe's ends and middle), and this close in angle.
constexpr double kGuideReach = 0.3;
constexpr double kGuideMaxAngleRad = 8.0 * kPi / 180.0;
// A pose fitted to the stripes: each stripe's runs within this log ratio of its width (0.22:
// 0.8 to 1.25 times; a stripe taken for its partner is 1.5 or 0.67 times), beside the widening
// its parallel stripe shares (RunsAsWideAsStripe); without four lines
// also its points spanning this fraction of it at least (a stripe seen over less, its other
// stretches under a hand or beyond the image, leaves the pose's tilt about it poorly told).
constexpr double kMaxFittedWidthLog = 0.22;
constexpr double kMinFittedExtent = 0.12;
// ... and its fits take points in corridors these many times the fit's, in turn.
constexpr std::array<double, 3> kExpectedCorridorScales = {6.0, 2.5, 1.0};
// Borders across each pair of stripes between the crossings, when a candidate's concentric
// borders gave no pose.
constexpr int kMiddleBordersPerPair = 4;
// ... and, after a pose, when a stripe's points span less than this fraction of it.
constexpr double kWeakStripeExtent = 0.3;
// Points along a stripe's centre line tested for being in view.
constexpr int kInViewSamples = 32;
// A whole image's pose whose stripe fit finds too few runs as wide as a stripe lying at least
// this much in view is not taken (a pale cable along the wide stripe of a sheet running out of
// view merged with all its runs, and the lines' pose was 2 degrees off); the 2 m board seen
// from near shows at most 0.72 of such a stripe.
constexpr double kStarvedInViewFraction = 0.9;
// A stripe keeping fewer than this fraction of the median of the others' points is checked
// against the pose the other three hold. Its points are not its stripe's when they move the pose
// by more than kMaxPullRad or kMaxPullFraction of the distance at a cost to the others: their RMS
// over kMaxOthersRmsGrowth times theirs without it, and kOthersRmsMarginPx more (a finger's
// shadow where a hidden stripe should be tilted a sheet by 2.3 degrees, the others' RMS 0.38 px
// against 0.09). Three stripes alone tell the tilt loosely (their pose may lie degrees away, the
// RMS the same): a move alone says nothing.
constexpr double kFewPointsRatio = 0.5;
// ... and every stripe so when the four's fit is poor, its RMS over this (a cable along a stripe
// of a dim, smeared frame left it as many points as the others, every stripe 0.3-0.5 px off the
// fit and the pose 2.6 degrees off; leaving it out, the others' RMS fell to 0.10 px).
constexpr double kPoorFitRmsPx = 0.2;
constexpr double kMaxPullRad = 1.0 * kRadPerDeg;
constexpr double kMaxPullFraction = 0.01;
// A stripe the model check cannot see (under a hand, out of view: fewer than 3 of its samples
// agree, none contradicts), or one line with too few feature points, is excused when the pose
// does not rest on it: the other three stripes alone fix the rotation to this (one standard
// deviation) and put the pose within these of it.
constexpr double kHeldByThreeMaxDeviationRad = 0.25 * kRadPerDeg;
constexpr double kHeldByThreeMaxMoveRad = 0.5 * kRadPerDeg;
constexpr double kHeldByThreeMaxMoveFraction = 0.005;
constexpr double kMaxOthersRmsGrowth = 2.0;
constexpr double kOthersRmsMarginPx = 0.05;
// A fit whose rotation its points fix to more than this about some axis (one standard
// deviation) has each stripe checked against the pose the other three hold: with stripes seen
// over short stretches, a few runs biased alike (merged with a cable along a stripe) turn it by
// degrees and fit as well as the truth. A stripe that moves the pose by more than kMaxPullRad
// and more than kMaxPullDeviations standard deviations of the three's own rotation
// (Mahalanobis, StripeFit::RotationDistance) disagrees with them, and neither pose is sure: no
// pose is taken (a cable along a stripe under motion blur: its 6-7 runs turned the pose by 2-3
// degrees from the three's, 1.9-3 of their deviations, and the four's was 2-3.5 degrees off).
// A tidy frame's fit fixes its rotation to 0.02-0.1 degrees: nothing is checked there.
constexpr double kLooseRotationRad = 0.15 * kRadPerDeg;
constexpr double kMaxPullDeviations = 1.8;
// ... when the three's rotation deviation is under this (a far sheet's three stripes, one of
// them seen over an eighth of its length, fixed it to 14 degrees and their fit settled 38
// degrees away).
constexpr double kMaxThreesDeviationRad = 3.0 * kRadPerDeg;
// Before that, a stripe seen over less than kHeldExtent of its length, or keeping fewer than
// kFewPointsRatio of the others' median points, is not taken when it holds the pose's rotation:
// the other three alone fix it more than kHeldDeviationRatio times as loosely (one standard
// deviation about its loosest axis: the stripe gives nine tenths of what is known there) and
// looser than kMinHeldDeviationRad. The four's deviation counts its points' scatter only; a
// few points along a short stretch, shifted alike by a fraction of a pixel (a cable lying along
// the rest of the stripe, a blur), turn such a pose by degrees (a sheet at 0.85-0.9 m under
// motion blur, a cable along a stripe: its 6 points over a third of it, the four fixed to
// 0.25-0.5 degrees, the three to 1.1-6, the pose 2-3.3 degrees off, in 12 of 33 poses).
constexpr double kHeldExtent = 0.4;
constexpr double kHeldDeviationRatio = 3.0;
constexpr double kMinHeldDeviationRad = 1.0 * kRadPerDeg;
// Once the stripes of this many readings of one frame (the scans of its borders its attempts
// make) have disagreed, no later reading's pose is taken: the image's stripes are what an
// occluder or a blur corrupted, and one reading of them passing after others failed is chance
// (a grey sheet's edge blurred across a stripe: 15 readings refused, the 16th, 2.9 degrees off,
// passed; a corner cell's pose 5 degrees off, fixed to 0.09 degrees, after nine refused).
constexpr int kMaxDisagreeingReadings = 3;
// A stripe whose runs' median width over its own differs from the others' median by more than
// this (log of the ratio: 8 %) is lopsided: something light or dark lies along one side of it
// (a white cable over an edge narrows its runs), their middles off its centre line all the same
// way. When it pulls the pose as above, the image's stripes decide: its points are not taken
// when the model check finds the stripes' edges, both shifted the same way, at most
// kLopsidedShiftRatio as far off at the three's pose as at the four's (a cable along a stripe of
// an over-exposed far sheet: 0.05 px against 0.46; right poses on the lived-in scenes: 0.47
// of it at least). Otherwise, when its runs' excess width over the stripe's (pixels) is off its
// parallel stripe's by more than 8 % of its width, the fit is made again with only its runs as
// wide as the parallel stripe's: blur and the threshold widen both by about as many pixels (a
// motion blur across one pair of stripes widens that pair alone), and a run merged with
// something along one side is wider (or, under something light, narrower) by its width. The
// band keeps the runs nearer the parallel stripe's excess than its own median excess; the fit
// starts from the four's pose (the three's may lie degrees off: a near board's, 14); at least
// min_points of them, or the frame is not taken (a dark cable crossing a stripe at a shallow
// angle under motion blur: its wide runs turned the pose by 2 degrees, and the image's edges
// told the two poses apart by 0.48 against 1/3).
constexpr double kLopsidedWidthLog = 0.08;
// ... when fewer than this fraction of its runs lie in the band, and too few for a fit, they are
// all off alike (its predicted width off: a strong lens near the image's edge; a clean board's
// stripe there was 18 % wider than its parallel one), and the pose stands as the image decided.
constexpr double kMixedWidthsFraction = 1.0 / 3.0;
constexpr double kLopsidedShiftRatio = 1.0 / 3.0;

// Candidates closed in on two sides set aside as corner cells, at most.
constexpr std::size_t kMaxCornerGuesses = 3;

}  // namespace

std::string ToString(ScanMode mode) {
  return mode == ScanMode::kImage ? "image" : "target";
}

std::string ToString(ScanSource source) {
  switch (source) {
    case ScanSource::kNone:
      return "none";
    case ScanSource::kPrior:
      return "prior";
    case ScanSource::kMiddleCell:
      return "middle-cell";
    case ScanSource::kEdgeCell:
      return "edge-cell";
    case ScanSource::kCornerCell:
      return "corner-cell";
    case ScanSource::kImage:
      return "image";
  }
  return "unknown";
}

std::string ToString(TargetStatus status) {
  switch (status) {
    case TargetStatus::kOk:
      return "ok";
    case TargetStatus::kNotFound:
      return "not-found";
    case TargetStatus::kModelMismatch:
      return "model-mismatch";
    case TargetStatus::kJump:
      return "jump";
  }
  return "unknown";
}

ScanMode ScanModeFromString(const std::string& text) {
  if (text == "target") return ScanMode::kTarget;
  if (text == "image") return ScanMode::kImage;
  throw std::invalid_argument("scan mode '" + text + "' is not one of: target, image");
}

void TargetTrackerOptions::Check() const {
  RequireOption(
      reference_focal_px == 0.0 || (reference_focal_px >= 1.0 && reference_focal_px <= 1e5),
      "TargetTrackerOptions::reference_focal_px", reference_focal_px,
      "0 or 1 <= reference_focal_px <= 1e5");
  finder.Check();
  RequireOption(borders >= 2 && borders <= 64, "TargetTrackerOptions::borders", borders,
                "2 <= borders <= 64");
  RequireOption(tracked_borders >= 2 && tracked_borders <= 64,
                "TargetTrackerOptions::tracked_borders", tracked_borders,
                "2 <= tracked_borders <= 64");
  RequireOption(quick_max_identification_cost >= 0.0 && quick_max_identification_cost <= 1e9,
                "TargetTrackerOptions::quick_max_identification_cost",
                quick_max_identification_cost, "0 <= quick_max_identification_cost <= 1e9");
  RequireOption(max_candidates >= 1 && max_candidates <= 16, "TargetTrackerOptions::max_candidates",
                max_candidates, "1 <= max_candidates <= 16");
  RequireOption(min_line_support >= 0 && min_line_support <= 1000,
                "TargetTrackerOptions::min_line_support", min_line_support,
                "0 <= min_line_support <= 1000");
  RequireOption(min_stripe_agreement >= 0.0 && min_stripe_agreement <= 1.0,
                "TargetTrackerOptions::min_stripe_agreement", min_stripe_agreement,
                "0 <= min_stripe_agreement <= 1");
  RequireOption(min_stripe_seen >= 0.0 && min_stripe_seen <= 1.0,
                "TargetTrackerOptions::min_stripe_seen", min_stripe_seen,
                "0 <= min_stripe_seen <= 1");
  RequireOption(min_stripe_contrast >= 1 && min_stripe_contrast <= 255,
                "TargetTrackerOptions::min_stripe_contrast", min_stripe_contrast,
                "1 <= min_stripe_contrast <= 255");
  RequireOption(max_jump_m >= 0.0 && max_jump_m <= 100.0, "TargetTrackerOptions::max_jump_m",
                max_jump_m, "0 <= max_jump_m <= 100");
  RequireOption(max_jump_deg >= 0.0 && max_jump_deg <= 180.0, "TargetTrackerOptions::max_jump_deg",
                max_jump_deg, "0 <= max_jump_deg <= 180");
  RequireOption(stripe_tolerance_px > 0.0 && stripe_tolerance_px <= 100.0,
                "TargetTrackerOptions::stripe_tolerance_px", stripe_tolerance_px,
                "0 < stripe_tolerance_px <= 100");
  RequireOption(stripe_tolerance_fraction >= 0.0 && stripe_tolerance_fraction <= 1.0,
                "TargetTrackerOptions::stripe_tolerance_fraction", stripe_tolerance_fraction,
                "0 <= stripe_tolerance_fraction <= 1");
  RequireOption(stripe_width_tolerance > 0.0 && stripe_width_tolerance <= 10.0,
                "TargetTrackerOptions::stripe_width_tolerance", stripe_width_tolerance,
                "0 < stripe_width_tolerance <= 10");
  RequireOption(stripe_profile_step_px >= 0.25 && stripe_profile_step_px <= 16.0,
                "TargetTrackerOptions::stripe_profile_step_px", stripe_profile_step_px,
                "0.25 <= stripe_profile_step_px <= 16");
  stripe_fit.Check();
}

double TargetTrackerOptions::PixelScale(const Lens& camera) const {
  if (reference_focal_px == 0.0) return 1.0;
  return std::clamp(std::sqrt(camera.px() * camera.py()) / reference_focal_px, 0.01, 100.0);
}

TargetTrackerOptions TargetTrackerOptions::ScaledBy(double scale) const {
  RequireOption(scale > 0.0 && scale <= 100.0, "TargetTrackerOptions::ScaledBy scale", scale,
                "0 < scale <= 100");
  TargetTrackerOptions scaled = *this;
  scaled.finder = finder.ScaledBy(scale);
  scaled.stripe_tolerance_px = stripe_tolerance_px * scale;
  // A smaller image's profile is read a pixel apart still: closer points repeat its pixels.
  scaled.stripe_profile_step_px = std::min(16.0, stripe_profile_step_px * std::max(1.0, scale));
  scaled.stripe_fit.corridor_px = stripe_fit.corridor_px * scale;
  scaled.stripe_fit.guide_tolerance_px = stripe_fit.guide_tolerance_px * scale;
  return scaled;
}

StripeCheckOptions TargetTrackerOptions::StripeCheck() const {
  StripeCheckOptions check;
  check.min_contrast = min_stripe_contrast;
  check.centre_tolerance_px = stripe_tolerance_px;
  check.centre_tolerance_fraction = stripe_tolerance_fraction;
  check.width_tolerance = stripe_width_tolerance;
  check.profile_step_px = stripe_profile_step_px;
  return check;
}

namespace {

// A target-plane point through a plane-to-image homography: normalised image coordinates, and
// the third homogeneous coordinate before the division (positive in front of the camera).
struct PlaneImage {
  double x = 0.0, y = 0.0, w = 0.0;
};
PlaneImage ThroughHomography(const vpHomography& h, const Point2d& plane) {
  const double w = h[2][0] * plane.u + h[2][1] * plane.v + h[2][2];
  return {(h[0][0] * plane.u + h[0][1] * plane.v + h[0][2]) / w,
          (h[1][0] * plane.u + h[1][1] * plane.v + h[1][2]) / w, w};
}

// A stripe's two edges and centre line in the image of a view, as lines n . p = c in the
// detector's pixels, and where a run across the stripe has its middle on them.
struct StripeOutline {
  std::array<std::array<double, 3>, 3> lines{};  // the edge at -half, the centre, +half

  // `plane_to_image` maps the target plane to normalised coordinates; `camera`'s px, py, u0,
  // v0 take them to pixels (the detector's undistorted pixels, or those of a pinhole camera).
  static StripeOutline Of(const TargetLayout& layout, int k, const vpHomography& plane_to_image,
                          const Lens& camera) {
    const StripeSpan& span = layout.stripes[static_cast<std::size_t>(k)];
    const auto to_pixel = [&](const Point2d& plane) {
      const PlaneImage image = ThroughHomography(plane_to_image, plane);
      return Point2d{camera.u0() + camera.px() * image.x, camera.v0() + camera.py() * image.y};
    };
    StripeOutline view;
    const double across[3] = {-span.half, 0.0, span.half};
    for (std::size_t i = 0; i < 3; ++i) {
      const Point2d a = to_pixel(layout.OnStripe(k, span.along.lo, across[i]));
      const Point2d b = to_pixel(layout.OnStripe(k, span.along.hi, across[i]));
      const double nu = a.v - b.v, nv = b.u - a.u;
      view.lines[i] = {nu, nv, nu * a.u + nv * a.v};
    }
    return view;
  }

  // A run's middle moved onto the image of the stripe's centre line, along the run. Under
  // perspective the two edges converge, so the middle of a run between them is off the centre
  // line's image, by an amount that changes with the run's direction from border to border:
  // enough to bend the points of a stripe as a lens would (told kdu up to 3 % off). The
  // shift is the model's (a few hundredths of a pixel), so a pose a few pixels off, or a
  // pinhole camera on a lens, still gives it closely. Runs of unknown width stay.
  Point2d CentreOfRun(const FramePoint& point) const {
    const double length = std::hypot(point.across_u, point.across_v);
    if (!(length > 0.0)) return point.p;
    const double du = point.across_u / length, dv = point.across_v / length;
    double s[3];
    for (std::size_t i = 0; i < 3; ++i) {
      const double towards = lines[i][0] * du + lines[i][1] * dv;
      if (std::fabs(towards) < 1e-12) return point.p;
      s[i] = (lines[i][2] - lines[i][0] * point.p.u - lines[i][1] * point.p.v) / towards;
    }
    const double shift = s[1] - 0.5 * (s[0] + s[2]);
    if (!(std::fabs(shift) < 1.0)) return point.p;  // a pose too far off to say
    return {point.p.u + shift * du, point.p.v + shift * dv};
  }
};

}  // namespace

std::array<std::vector<Point2d>, 4> TargetPoseTracker::StripePoints(double tolerance_px) const {
  std::array<std::vector<Point2d>, 4> stripes;
  if (frame_.status != TargetStatus::kOk) return stripes;
  const vpHomography plane_to_image = PlaneToImage(frame_.pose.cMo);
  const std::array<std::vector<FramePoint>, 4> runs = StripeRuns(tolerance_px);
  for (std::size_t k = 0; k < 4; ++k) {
    const StripeOutline stripe =
        StripeOutline::Of(layout_, static_cast<int>(k), plane_to_image, camera_);
    for (const FramePoint& point : runs[k]) stripes[k].push_back(stripe.CentreOfRun(point));
  }
  return stripes;
}

std::array<std::vector<FramePoint>, 4> TargetPoseTracker::StripeRuns(double tolerance_px) const {
  std::array<std::vector<FramePoint>, 4> stripes;
  if (frame_.status != TargetStatus::kOk) return stripes;
  const std::array<std::optional<LineExtent>, 4> ends = StripeEnds(PlaneToImage(frame_.pose.cMo));
  for (std::size_t k = 0; k < 4; ++k) {
    const LineParams& line = lines_[static_cast<std::size_t>(frame_.pose.line_index[k])].line;
    ForEachPointOnStretch(
        line, detector_.feature_points(), tolerance_px, ends[k],
        [&](const FramePoint& point, double, double) { stripes[k].push_back(point); });
  }
  return stripes;
}

namespace {

// The median of the values of the three lines other than `line`.
template <typename T>
T MedianOfOthers(const std::array<T, 4>& values, int line) {
  std::array<T, 3> others{};
  for (int k = 0, i = 0; k < 4; ++k) {
    if (k != line) others[static_cast<std::size_t>(i++)] = values[static_cast<std::size_t>(k)];
  }
  std::sort(others.begin(), others.end());
  return others[1];
}

// The stripe (0-3) parallel to stripe k; k itself when it has none.
std::size_t ParallelStripe(const TargetLayout& layout, std::size_t k) {
  for (std::size_t other = 0; other < layout.stripes.size(); ++other) {
    if (other != k && layout.stripes[other].along_b == layout.stripes[k].along_b) return other;
  }
  return k;
}

// Whether stripe k's runs are widened by about as many pixels as those of its parallel stripe
// `parallel`: their median excess widths within kLopsidedWidthLog of its width. Blur and the
// threshold widen both alike (a motion blur across one pair of stripes widens that pair alone);
// something along one side of one of them widens or narrows it by its own width.
bool WidenedAlike(const StripeFit& fit, std::size_t k, std::size_t parallel) {
  return !(std::fabs(fit.width_excess_px[k] - fit.width_excess_px[parallel]) >
           kLopsidedWidthLog * fit.width_px[k]);
}

// The runs of `line` nearer the median excess width of its parallel stripe's runs than its
// own: the band about the parallel stripe's excess reaching half way to it. None when the two
// are widened alike.
std::optional<RunWidthBand> AsWideAsItsParallel(const StripeFit& fit, const TargetLayout& layout,
                                                int line) {
  const auto k = static_cast<std::size_t>(line);
  const std::size_t parallel = ParallelStripe(layout, k);
  if (parallel == k || WidenedAlike(fit, k, parallel)) return std::nullopt;
  const double reference = fit.width_excess_px[parallel];
  const double apart = std::fabs(fit.width_excess_px[k] - reference);
  return RunWidthBand{line, reference - 0.5 * apart, reference + 0.5 * apart};
}

// Whether stripe k's kept runs are, at their median, as wide as it, beside the widening its
// parallel stripe's runs show as well: a motion blur across a pair of stripes widens both by as
// many pixels (a thin stripe's runs 1.3 times its width under a blur of a few pixels), while a
// stripe taken for its partner leaves the pair's excesses twice their widths' difference apart.
bool RunsAsWideAsStripe(const StripeFit& fit, const TargetLayout& layout, std::size_t k) {
  const std::size_t parallel = ParallelStripe(layout, k);
  const double width = fit.width_px[k];
  double shared_px = 0.0;
  if (parallel != k && width > 0.0 && WidenedAlike(fit, k, parallel)) {
    shared_px = std::max(0.0, std::min(fit.width_excess_px[k], fit.width_excess_px[parallel]));
  }
  const double ratio =
      shared_px > 0.0 ? fit.width_ratio[k] * width / (width + shared_px) : fit.width_ratio[k];
  return !(std::fabs(std::log(ratio)) > kMaxFittedWidthLog);
}

// The first stripe (0-3) whose kept runs are not as wide as it; -1 when none.
int MergedStripe(const StripeFit& fit, const TargetLayout& layout) {
  for (std::size_t k = 0; k < 4; ++k) {
    if (!RunsAsWideAsStripe(fit, layout, k)) return static_cast<int>(k);
  }
  return -1;
}

// The corner where a quadrilateral's only two closed sides meet (side k runs from corner k to
// corner k + 1); -1 unless exactly two sides that meet are closed.
int ClosedCorner(const LightQuad& quad) {
  if (quad.ClosedSideCount() != 2) return -1;
  for (int k = 0; k < 4; ++k) {
    const int next = (k + 1) % 4;
    if (((quad.closed_sides >> k) & 1) && ((quad.closed_sides >> next) & 1)) return next;
  }
  return -1;
}

}  // namespace

LensCheck CheckLens(const std::vector<RadialBend>& frames, int min_frames) {
  LensCheck check;
  check.frames = static_cast<int>(frames.size());
  std::vector<double> bends, errors;
  for (const RadialBend& frame : frames) {
    bends.push_back(frame.bend_px);
    if (std::isfinite(frame.kdu_error_sd)) errors.push_back(frame.kdu_error);
    check.contradicting += ContradictsLens(frame);
  }
  check.median_px = MedianInPlace(&bends);
  check.median_kdu_error = MedianInPlace(&errors);
  check.mismatch = check.frames >= min_frames && 2 * check.contradicting > check.frames;
  return check;
}

TargetPoseTracker::TargetPoseTracker(const LineTarget& target, const Lens& camera,
                                     const DetectorOptions& detector, const PoseOptions& pose,
                                     const TargetTrackerOptions& options)
    : target_(target),
      camera_(camera),
      layout_(TargetLayout::Of(target)),
      pixel_scale_((options.Check(), options.PixelScale(camera))),
      pose_options_(pose.ScaledBy(pixel_scale_)),
      options_(options.ScaledBy(pixel_scale_)),
      detector_(detector.ScaledBy(pixel_scale_), camera),
      finder_(options_.finder) {
  pose_options_.camera = camera;
  pose_options_.lines_undistorted = detector_.Undistorts();
  pose_options_.Check();
}

void TargetPoseTracker::Reset() {
  last_cMo_.reset();
  held_cMo_.reset();
  frames_since_ok_ = 0;
}

std::array<std::optional<LineExtent>, 4> TargetPoseTracker::StripeEnds(
    const vpHomography& plane_to_image) const {
  std::array<std::optional<LineExtent>, 4> extents;
  for (int k = 0; k < 4; ++k) {
    const StripeSpan& stripe = layout_.stripes[static_cast<std::size_t>(k)];
    Point2d ends[2];
    bool ok = true;
    for (int e = 0; e < 2 && ok; ++e) {
      const Point2d plane = layout_.OnStripe(k, e == 0 ? stripe.along.lo : stripe.along.hi, 0.0);
      const PlaneImage image = ThroughHomography(plane_to_image, plane);
      ok = image.w > 1e-9;
      if (!ok) break;
      // The detector's coordinates: undistorted pixels when it undistorts.
      ends[e] = detector_.Undistorts() ? Point2d{camera_.u0() + camera_.px() * image.x,
                                                 camera_.v0() + camera_.py() * image.y}
                                       : camera_.Pixel(image.x, image.y);
      ok = std::isfinite(ends[e].u) && std::isfinite(ends[e].v);
    }
    if (ok) extents[static_cast<std::size_t>(k)] = LineExtent{ends[0], ends[1]};
  }
  return extents;
}

StripeGuides TargetPoseTracker::GuidesFrom(const vpHomography& plane_to_image) const {
  StripeGuides guides;
  const std::array<std::optional<LineExtent>, 4> ends = StripeEnds(plane_to_image);
  std::array<bool, 4> have{};
  for (std::size_t k = 0; k < 4; ++k) have[k] = ends[k].has_value();
  if (!(have[0] && have[1] && have[2] && have[3])) return guides;
  std::vector<bool> taken(lines_.size(), false);
  for (std::size_t k = 0; k < 4; ++k) {
    const LineExtent& end = *ends[k];
    const LineParams predicted = LineThrough(end.a, end.b);
    const Point2d middle{0.5 * (end.a.u + end.b.u), 0.5 * (end.a.v + end.b.v)};
    // Less than a third of the way to the parallel stripe: no other stripe is nearer.
    const LineExtent& partner = *ends[(k + 2) % 4];
    const double spacing = std::fabs(predicted.SignedDistance(0.5 * (partner.a.u + partner.b.u),
                                                              0.5 * (partner.a.v + partner.b.v)));
    double best = kGuideReach * spacing;
    int best_line = -1;
    for (std::size_t i = 0; i < lines_.size(); ++i) {
      const DetectedLine& line = lines_[i];
      if (taken[i] || !(line.width_px > 0.0) ||
          AngleBetween(line.line, predicted) > kGuideMaxAngleRad) {
        continue;
      }
      const double distance = std::max({std::fabs(line.line.SignedDistance(end.a.u, end.a.v)),
                                        std::fabs(line.line.SignedDistance(end.b.u, end.b.v)),
                                        std::fabs(line.line.SignedDistance(middle.u, middle.v))});
      if (distance < best) {
        best = distance;
        best_line = static_cast<int>(i);
      }
    }
    if (best_line >= 0) {
      guides[k] = lines_[static_cast<std::size_t>(best_line)].line;
      taken[static_cast<std::size_t>(best_line)] = true;
    }
  }
  return guides;
}

std::vector<LineSeed> TargetPoseTracker::SeedsFrom(const vpHomography& plane_to_image) const {
  std::vector<LineSeed> seeds;
  const std::array<std::optional<LineExtent>, 4> ends = StripeEnds(plane_to_image);
  for (int k = 0; k < 4; ++k) {
    const std::optional<LineExtent>& end = ends[static_cast<std::size_t>(k)];
    if (end && std::hypot(end->b.u - end->a.u, end->b.v - end->a.v) > 1.0) {
      seeds.push_back(LineSeed{k, LineThrough(end->a, end->b)});
    }
  }
  return seeds;
}

bool TargetPoseTracker::Attempt(const GrayImageView& image, const ScanBorders& borders,
                                const std::vector<LineSeed>& seeds,
                                const std::optional<vpHomogeneousMatrix>& prior, ScanSource source,
                                const std::optional<Expected>& expected) {
  auto start = std::chrono::steady_clock::now();
  const std::vector<DetectedLine>& lines = detector_.Detect(image, seeds, borders);
  frame_.detect_us += MicrosecondsSince(start);
  lines_ = lines;
  frame_.source = source;
  frame_.borders = detector_.region_borders().count();
  frame_.region =
      frame_.borders > 0 ? detector_.region_borders().Polygon(0) : std::vector<Point2d>{};
  start = std::chrono::steady_clock::now();
  frame_.pose = EstimatePose(lines_, target_, pose_options_, prior);
  frame_.pose_us += MicrosecondsSince(start);
  frame_.agreement = StripeAgreement{};
  frame_.lens = RadialBend{};
  frame_.lens_measured = false;
  frame_.fit = StripeFit{};
  if (frame_.pose.status == PoseStatus::kOk && options_.fit_stripes) {
    frame_.fit = FitStripes(frame_.pose.cMo, layout_, detector_.feature_points(), camera_,
                            detector_.Undistorts(), options_.stripe_fit);
    if (frame_.fit.ok && !prior) frame_.fit = OtherTiltIfBetter(frame_.fit);
    const int merged = frame_.fit.ok ? MergedStripe(frame_.fit, layout_) : -1;
    if (merged >= 0 && source != ScanSource::kImage) {
      // A stripe whose runs are not as wide as it: most of them merged with something beside
      // it (a cable along it, a glare's slope), their middles off its centre line.
      frame_.pose.status = PoseStatus::kDegenerate;
      std::ostringstream message;
      message << "the stripes' points do not hold the lines' pose: line " << merged + 1
              << "'s runs are " << frame_.fit.width_ratio[static_cast<std::size_t>(merged)]
              << " times its width";
      frame_.pose.message = message.str();
    } else if (frame_.fit.ok) {
      ReplacePose(frame_.fit.cMo, target_, &frame_.pose);
    } else if (source != ScanSource::kImage || StarvedStripeInView()) {
      // The lines' pose puts a stripe where too few runs as wide as it lie, or where its runs
      // cannot hold the pose (a line drawn through runs merged with fingers or a pen beside
      // the stripe): not taken. (A whole image's pose is scanned again on the target's plane,
      // where this applies; its stripes' runs tell against it only for a stripe in view: a
      // board seen from near shows too little of a stripe to fit.)
      frame_.pose.status = PoseStatus::kDegenerate;
      frame_.pose.message =
          "the stripes' points do not hold the lines' pose: " + frame_.fit.message;
    }
  }
  if (frame_.pose.status != PoseStatus::kOk &&
      !(options_.fit_stripes && expected && FitExpected(*expected))) {
    frame_.status = TargetStatus::kNotFound;
    frame_.message = frame_.pose.message;
    return false;
  }
  return Verify(image);
}

StripeFit TargetPoseTracker::FitNarrowing(const vpHomogeneousMatrix& start,
                                          const StripeGuides* guides,
                                          const vpHomogeneousMatrix* known) const {
  StripeFit fit;
  fit.cMo = start;
  for (const double scale : kExpectedCorridorScales) {
    StripeFitOptions corridor = options_.stripe_fit;
    corridor.corridor_px *= scale;
    fit = FitStripes(fit.cMo, layout_, detector_.feature_points(), camera_, detector_.Undistorts(),
                     corridor, scale == kExpectedCorridorScales[0] ? guides : nullptr, -1, known);
    if (!fit.ok) break;
  }
  return fit;
}

StripeFit TargetPoseTracker::OtherTiltIfBetter(const StripeFit& fit) const {
  // Tried wherever the other tilt puts the stripes: from tens of pixels off, its fit in the
  // narrowing corridors still settles where it explains the points best.
  const vpHomogeneousMatrix mirrored = MirroredTilt(fit.cMo);
  StripeFit other = FitNarrowing(mirrored, nullptr, &fit.cMo);
  if (!other.ok) return fit;
  const int kept = fit.TotalPoints(), other_kept = other.TotalPoints();
  return other_kept > kept || (other_kept == kept && other.rms_px < fit.rms_px) ? other : fit;
}

bool TargetPoseTracker::FitExpected(const Expected& expected) {
  // The target turned by 180 degrees about the '#''s middle.
  const vpHomogeneousMatrix to_middle(layout_.origin.u, layout_.origin.v, 0.0, 0.0, 0.0, 0.0);
  const vpHomogeneousMatrix turned = expected.cMo * to_middle *
                                     vpHomogeneousMatrix(0.0, 0.0, 0.0, 0.0, 0.0, kPi) *
                                     to_middle.inverse();
  std::optional<StripeFit> best;
  double best_score = HUGE_VAL, other_score = HUGE_VAL;
  std::string failure;
  for (const vpHomogeneousMatrix& start : {expected.cMo, turned}) {
    if (!expected.either_way && best) break;
    // The lines the scan found near where `start` puts each stripe guide the first fit.
    const StripeGuides guides = GuidesFrom(PlaneToImage(start));
    StripeFit fit = FitNarrowing(start, &guides);
    if (!fit.ok) {
      if (failure.empty()) failure = fit.message;
      continue;
    }
    // How far the runs' widths are from their stripes' (log ratios: a stripe taken for one
    // 1.5 times as wide scores 0.16).
    double score = 0.0;
    for (const double ratio : fit.width_ratio) score += std::pow(std::log(ratio), 2);
    if (score < best_score) {
      other_score = best_score;
      best_score = score;
      best = std::move(fit);
    } else {
      other_score = std::min(other_score, score);
    }
    if (!expected.either_way) break;
  }
  const std::string why = frame_.pose.message;
  if (!best) {
    frame_.pose.message = why +
                          "; fitted to the stripes' points from where the target was "
                          "expected: " +
                          failure;
    return false;
  }
  // The widths must tell the way round (each ratio of the other is 1.5 or 1.17 for the
  // built-in targets: a score of 0.37 against about 0).
  if (expected.either_way && other_score < best_score + kWaysRoundMargin) {
    std::ostringstream message;
    message << why << "; fitted to the stripes' points, their widths do not tell which way round "
            << "the target lies (scores " << best_score << " and " << other_score << ")";
    frame_.pose.message = message.str();
    return false;
  }
  // Its runs as wide as their stripes (a stripe taken for one half as wide again is not), and
  // each stripe seen over a good part of it: the lines' identification and support, for a pose
  // that has no four lines.
  for (std::size_t k = 0; k < 4; ++k) {
    if (!RunsAsWideAsStripe(*best, layout_, k) || best->extent[k] < kMinFittedExtent) {
      std::ostringstream message;
      message << why << "; fitted to the stripes' points, line " << k + 1 << "'s runs are "
              << best->width_ratio[k] << " times its width and span " << best->extent[k]
              << " of it";
      frame_.pose.message = message.str();
      return false;
    }
  }
  if (best->rms_px > pose_options_.max_residual_px) {
    std::ostringstream message;
    message << why << "; fitted to the stripes' points, their residual " << best->rms_px
            << " px > max_residual_px = " << pose_options_.max_residual_px;
    frame_.pose.message = message.str();
    return false;
  }
  if (expected.either_way) best = OtherTiltIfBetter(*best);
  frame_.fit = *best;
  if (const int behind = SetLinesFromFit(); behind >= 0) {
    frame_.pose.message =
        why + "; the fitted pose puts line " + std::to_string(behind + 1) + " behind the camera";
    return false;
  }
  PoseResult& pose = frame_.pose;
  pose.residual_px = best->rms_px;
  pose.method = PoseMethod::kStripes;
  pose.identification_cost = best_score;
  pose.identification_margin = other_score - best_score;
  ReplacePose(best->cMo, target_, &pose);
  pose.status = PoseStatus::kOk;
  pose.message.clear();
  return true;
}

int TargetPoseTracker::SetLinesFromFit() {
  // The four lines are the stripes' centre lines where the fit puts them.
  const StripeFit& fit = frame_.fit;
  const std::array<std::optional<LineExtent>, 4> ends = StripeEnds(PlaneToImage(fit.cMo));
  std::vector<DetectedLine> lines;
  for (std::size_t k = 0; k < 4; ++k) {
    if (!ends[k]) return static_cast<int>(k);
    DetectedLine line;
    line.line = LineThrough(ends[k]->a, ends[k]->b);
    line.end_a = line.support_a = ends[k]->a;
    line.end_b = line.support_b = ends[k]->b;
    line.support = fit.points[k];
    line.seed_id = static_cast<int>(k);
    lines.push_back(line);
  }
  lines_ = std::move(lines);
  PoseResult& pose = frame_.pose;
  pose.line_index = {0, 1, 2, 3};
  for (std::size_t k = 0; k < 4; ++k) {
    Point2d& corner = pose.corners_px[k];
    Intersect(lines_[k].line, lines_[(k + 1) % 4].line, &corner);
    double x = 0.0, y = 0.0;
    if (detector_.Undistorts()) {
      x = (corner.u - camera_.u0()) / camera_.px();
      y = (corner.v - camera_.v0()) / camera_.py();
    } else {
      const Point2d ideal = camera_.Normalised(corner.u, corner.v);
      x = ideal.u;
      y = ideal.v;
    }
    pose.corners_m[k] = vpColVector(2);
    pose.corners_m[k][0] = x;
    pose.corners_m[k][1] = y;
  }
  return -1;
}

void TargetPoseTracker::MeasureLens() {
  std::array<LineParams, 4> identified;
  for (std::size_t k = 0; k < identified.size(); ++k) {
    identified[k] = lines_[static_cast<std::size_t>(frame_.pose.line_index[k])].line;
  }
  // Only the points on the printed stripes: beyond their ends the lines run over the bench.
  frame_.lens = RadialBendOfFour(
      identified, detector_.feature_points(), 2.0 * detector_.options().support_tolerance_px,
      StripeEnds(PlaneToImage(frame_.pose.cMo)), Point2d{camera_.u0(), camera_.v0()},
      std::sqrt(camera_.px() * camera_.py()));
  frame_.lens_measured = true;
}

TargetPoseTracker::Pull TargetPoseTracker::PullOf(int line) const {
  const StripeFit& fit = frame_.fit;
  Pull pull;
  pull.without = FitStripes(fit.cMo, layout_, detector_.feature_points(), camera_,
                            detector_.Undistorts(), options_.stripe_fit, nullptr, line);
  const PoseDistance moved = Distance(fit.cMo, pull.without.cMo);
  const double distance = std::max(fit.cMo.getTranslationVector().frobeniusNorm(), 1e-6);
  pull.angle_rad = moved.rotation_rad;
  pull.shift = moved.translation_m / distance;
  return pull;
}

bool TargetPoseTracker::Pull::Matters() const {
  return without.ok && (angle_rad > kMaxPullRad || shift > kMaxPullFraction);
}

std::string TargetPoseTracker::Pull::Describe() const {
  std::ostringstream text;
  text << "pull the pose " << angle_rad * kDegPerRad << " deg and " << 100.0 * shift
       << " % of the distance from where the other three stripes put it";
  return text.str();
}

std::optional<std::string> TargetPoseTracker::WeakStripePull() const {
  const StripeFit& fit = frame_.fit;
  if (!fit.ok) return std::nullopt;
  const int weakest =
      static_cast<int>(std::min_element(fit.points.begin(), fit.points.end()) - fit.points.begin());
  if (fit.points[static_cast<std::size_t>(weakest)] <
      kFewPointsRatio * MedianOfOthers(fit.points, weakest)) {
    return PullAgainstTheOthers(weakest, PullOf(weakest));
  }
  if (!(fit.rms_px > kPoorFitRmsPx) || !options_.check_stripes_on_poor_fit) return std::nullopt;
  for (int line = 0; line < 4; ++line) {
    if (std::optional<std::string> why = PullAgainstTheOthers(line, PullOf(line))) return why;
  }
  return std::nullopt;
}

std::optional<std::string> TargetPoseTracker::RotationHeldByFew(int line, double four,
                                                                double three) const {
  const StripeFit& fit = frame_.fit;
  const auto k = static_cast<std::size_t>(line);
  if (!(fit.extent[k] < kHeldExtent) &&
      !(fit.points[k] < kFewPointsRatio * MedianOfOthers(fit.points, line))) {
    return std::nullopt;
  }
  if (!(three > kHeldDeviationRatio * four) || !(three > kMinHeldDeviationRad)) {
    return std::nullopt;
  }
  std::ostringstream message;
  message << "line " << line + 1 << "'s " << fit.points[k] << " points (the others keep "
          << MedianOfOthers(fit.points, line) << ") along " << 100.0 * fit.extent[k]
          << " % of its stripe hold the pose's rotation: ";
  if (std::isfinite(three)) {
    message << "the other three stripes fix it to " << three * kDegPerRad << " deg, with them "
            << four * kDegPerRad << " deg";
  } else {
    message << "the other three stripes do not fix it";
  }
  message << " (at most " << kHeldDeviationRatio
          << " times as loosely): too few to trust, a fraction of a pixel turns it by degrees";
  return message.str();
}

std::optional<std::string> TargetPoseTracker::PullAgainstTheOthers(int line,
                                                                   const Pull& pull) const {
  const StripeFit& fit = frame_.fit;
  if (!pull.Matters()) return std::nullopt;  // Matters: the other three fix the pose
  double others_sum2 = 0.0;
  int others_points = 0;
  for (std::size_t k = 0; k < 4; ++k) {
    if (static_cast<int>(k) == line) continue;
    others_sum2 += fit.points[k] * fit.line_rms_px[k] * fit.line_rms_px[k];
    others_points += fit.points[k];
  }
  const double others_rms = others_points > 0 ? std::sqrt(others_sum2 / others_points) : 0.0;
  if (others_rms <= kMaxOthersRmsGrowth * pull.without.rms_px + kOthersRmsMarginPx) {
    return std::nullopt;
  }
  std::ostringstream message;
  message << "line " << line + 1 << "'s " << fit.points[static_cast<std::size_t>(line)]
          << " points (the others keep " << MedianOfOthers(fit.points, line) << ") "
          << pull.Describe() << ", their RMS from " << pull.without.rms_px << " to " << others_rms
          << " px: they are not all its stripe's";
  return message.str();
}

std::string TargetPoseTracker::LensNote() {
  if (!measure_lens_) MeasureLens();
  if (!ContradictsLens(frame_.lens)) return "";
  std::ostringstream note;
  note << "; the stripes bend as a lens the camera model misses would (its kdu off by "
       << -frame_.lens.kdu_error << ")";
  return note.str();
}

bool TargetPoseTracker::HeldByTheOtherThree(int line) const {
  if (line < 0 || !frame_.fit.ok) return false;
  const Pull pull = PullOf(line);
  return pull.without.ok && pull.without.RotationDeviation() < kHeldByThreeMaxDeviationRad &&
         pull.angle_rad < kHeldByThreeMaxMoveRad && pull.shift < kHeldByThreeMaxMoveFraction;
}

std::optional<std::string> TargetPoseTracker::DisagreeingStripe() const {
  const StripeFit& fit = frame_.fit;
  if (!fit.ok) return std::nullopt;
  if (disagreeing_readings_ >= kMaxDisagreeingReadings) {
    return "the stripes disagreed in " + std::to_string(disagreeing_readings_) +
           " readings of this frame: a later reading's pose is not taken (at most " +
           std::to_string(kMaxDisagreeingReadings - 1) + ")";
  }
  const double four = fit.RotationDeviation();
  if (!(four > kLooseRotationRad)) return std::nullopt;
  for (int line = 0; line < 4; ++line) {
    const Pull pull = PullOf(line);
    const double three = pull.without.ok ? pull.without.RotationDeviation() : HUGE_VAL;
    if (std::optional<std::string> why = RotationHeldByFew(line, four, three)) return why;
    // Three stripes that fix the rotation to degrees only (their fit may settle tens of
    // degrees away) say nothing against the fourth.
    if (!pull.without.ok || !(pull.angle_rad > kMaxPullRad) || !(three < kMaxThreesDeviationRad)) {
      continue;
    }
    const double deviations = pull.without.RotationDistance(fit.cMo);
    if (!(deviations > kMaxPullDeviations)) continue;
    std::ostringstream message;
    message << "line " << line + 1 << "'s points " << pull.Describe() << ", " << deviations
            << " standard deviations of those three's rotation (at most " << kMaxPullDeviations
            << "): the stripes disagree";
    return message.str();
  }
  return std::nullopt;
}

std::optional<std::string> TargetPoseTracker::LopsidedStripePull(const GrayImageView& image) {
  const StripeFit& fit = frame_.fit;
  if (!fit.ok) return std::nullopt;
  int line = -1;
  double most = 0.0, relative = 1.0;
  for (int k = 0; k < 4; ++k) {
    const double ratio =
        fit.width_ratio[static_cast<std::size_t>(k)] / MedianOfOthers(fit.width_ratio, k);
    const double apart = std::fabs(std::log(ratio));
    if (apart > most) {
      most = apart;
      line = k;
      relative = ratio;
    }
  }
  if (!(most > kLopsidedWidthLog)) return std::nullopt;
  const Pull pull = PullOf(line);
  if (!pull.Matters()) return std::nullopt;
  const StripeCheckOptions check = options_.StripeCheck();
  const StripeAgreement all = CheckStripes(image, layout_, fit.cMo, camera_, check);
  const StripeAgreement three = CheckStripes(image, layout_, pull.without.cMo, camera_, check);
  std::ostringstream message;
  message << "line " << line + 1 << "'s runs are " << relative
          << " times as wide as the others' (something lying along one side of its stripe) and "
          << pull.Describe();
  if (three.Worst() >= options_.min_stripe_agreement && three.Seen() >= options_.min_stripe_seen &&
      three.ShiftRms() < kLopsidedShiftRatio * all.ShiftRms()) {
    message << ", where the image's stripes lie: their edges are " << three.ShiftRms()
            << " px off (both edges the same way) there, " << all.ShiftRms() << " px with it";
    return message.str();
  }
  const std::optional<RunWidthBand> parallel_band = AsWideAsItsParallel(fit, layout_, line);
  if (!parallel_band) return std::nullopt;
  const RunWidthBand& band = *parallel_band;
  const StripeFit banded =
      FitStripes(fit.cMo, layout_, detector_.feature_points(), camera_, detector_.Undistorts(),
                 options_.stripe_fit, nullptr, -1, nullptr, &band);
  const int in_band = banded.points[static_cast<std::size_t>(line)];
  if (!banded.ok && banded.starved_line == line &&
      in_band < kMixedWidthsFraction * fit.points[static_cast<std::size_t>(line)]) {
    // Nearly all its runs are as far off: the widths it is predicted (a strong lens at the
    // image's edge, a slanted view) or a blur along it, not something along part of it.
    return std::nullopt;
  }
  if (!banded.ok) {
    message << "; fitted again with only those of its runs as wide as its parallel stripe's ("
            << band.min_excess_px << " to " << band.max_excess_px
            << " px wider than the stripe): " << banded.message;
    return message.str();
  }
  if (const int behind = AdoptFit(banded); behind >= 0) {
    message << "; fitted again from its runs as wide as its parallel stripe's, the pose puts line "
            << behind + 1 << " behind the camera";
    return message.str();
  }
  return std::nullopt;
}

int TargetPoseTracker::AdoptFit(const StripeFit& fit) {
  frame_.fit = fit;
  ReplacePose(fit.cMo, target_, &frame_.pose);
  if (frame_.pose.method != PoseMethod::kStripes) return -1;
  frame_.pose.residual_px = fit.rms_px;
  return SetLinesFromFit();
}

bool TargetPoseTracker::Verify(const GrayImageView& image) {
  if (measure_lens_) MeasureLens();
  if (const std::optional<std::string> pull = WeakStripePull()) {
    frame_.status = TargetStatus::kNotFound;
    frame_.message = *pull;
    return false;
  }
  if (const std::optional<std::string> pull = LopsidedStripePull(image)) {
    frame_.status = TargetStatus::kNotFound;
    frame_.message = *pull;
    return false;
  }
  if (const std::optional<std::string> pull = DisagreeingStripe()) {
    ++disagreeing_readings_;
    // Stripes bent by a lens the camera file misses disagree too: said when they bend so.
    const std::string lens = LensNote();
    frame_.status = lens.empty() ? TargetStatus::kNotFound : TargetStatus::kModelMismatch;
    frame_.message = *pull + lens;
    return false;
  }
  if (frame_.pose.method == PoseMethod::kStripes) {
    // The four stripes held together: their points in all (each stripe has its fit's minimum).
    const int points = frame_.fit.TotalPoints();
    if (points < 2 * options_.min_line_support) {
      frame_.status = TargetStatus::kNotFound;
      frame_.message = "the stripes keep " + std::to_string(points) +
                       " feature points in all (2 min_line_support = " +
                       std::to_string(2 * options_.min_line_support) +
                       "): too few to trust the pose fitted to them";
      return false;
    }
  } else {
    // One line with too few points (its stripe mostly hidden) may stand when the other three
    // hold the pose; two may not.
    int weak = -1, weak_support = 0, weak_lines = 0;
    for (int k = 0; k < 4; ++k) {
      const DetectedLine& line =
          lines_[static_cast<std::size_t>(frame_.pose.line_index[static_cast<std::size_t>(k)])];
      if (line.support >= options_.min_line_support) continue;
      if (weak < 0) weak = k, weak_support = line.support;
      ++weak_lines;
    }
    if (weak >= 0 && (weak_lines > 1 || !HeldByTheOtherThree(weak))) {
      frame_.status = TargetStatus::kNotFound;
      frame_.message =
          "line " + std::to_string(weak + 1) + " has " + std::to_string(weak_support) +
          " feature points on it (min_line_support = " + std::to_string(options_.min_line_support) +
          "): too few to trust the pose";
      return false;
    }
  }
  StripeCheckOptions check = options_.StripeCheck();
  check.short_profiles_at_edge = frame_.pose.method != PoseMethod::kStripes;
  frame_.agreement = CheckStripes(image, layout_, frame_.pose.cMo, camera_, check);
  const bool stripes_agree =
      frame_.agreement.Worst() >= options_.min_stripe_agreement ||
      HeldByTheOtherThree(frame_.agreement.Unseen(options_.min_stripe_agreement));
  if (!stripes_agree || frame_.agreement.Seen() < options_.min_stripe_seen) {
    std::ostringstream message;
    message << "the image does not show the target where the pose puts it: ";
    for (int k = 0; k < 4; ++k) {
      message << (k > 0 ? ", " : "") << "line " << k + 1 << " seen in "
              << frame_.agreement.dark[static_cast<std::size_t>(k)] << " and contradicted in "
              << frame_.agreement.contradict[static_cast<std::size_t>(k)] << " of "
              << frame_.agreement.samples[static_cast<std::size_t>(k)] << " samples";
    }
    message << " (min_stripe_agreement = " << options_.min_stripe_agreement
            << ", min_stripe_seen = " << options_.min_stripe_seen << ")";
    message << LensNote();
    frame_.status = TargetStatus::kModelMismatch;
    frame_.message = message.str();
    return false;
  }
  frame_.status = TargetStatus::kOk;
  frame_.message.clear();
  return true;
}

bool TargetPoseTracker::AttemptCandidate(const GrayImageView& image,
                                         const vpHomography& plane_to_image, ScanSource source) {
  const std::vector<LineSeed> seeds = SeedsFrom(plane_to_image);
  // Where the candidate puts the target, should its lines give no pose: a middle cell either
  // way round, the whole image's pose as it is.
  std::optional<Expected> expected;
  if (const std::optional<vpHomogeneousMatrix> cMo = PlanePose(plane_to_image)) {
    expected = Expected{*cMo, source != ScanSource::kImage};
  }
  // quick_max_identification_cost 0 could never keep a quick scan: none is made.
  const bool quick = quick_scan_ && options_.quick_max_identification_cost > 0.0 &&
                     options_.tracked_borders < options_.borders;
  const std::array<int, 2> scans{quick ? options_.tracked_borders : options_.borders,
                                 options_.borders};
  for (std::size_t scan = 0; scan < scans.size(); ++scan) {
    const int count = scans[scan];
    TargetBorders(layout_, plane_to_image, camera_, count, &borders_);
    if (borders_.empty()) return false;
    if (scan == 0 && source == ScanSource::kMiddleCell) ++frame_.candidates;
    // Each candidate on its own: a prior that failed above says nothing about it.
    const bool accepted = Attempt(image, borders_, seeds, std::nullopt, source, expected);
    if (count >= options_.borders) {
      if (accepted && RescanWeakStripe(image, source)) return true;
      // A stripe seen only between the crossings (its arms under a hand or out of view)
      // gives the concentric borders no points: scanned again with borders across the
      // stripes' middles.
      AddMiddleBorders(layout_, plane_to_image, camera_, kMiddleBordersPerPair, &borders_);
      return Attempt(image, borders_, seeds, std::nullopt, source, expected) &&
             EachStripeSeenOverEnough(true, "");
    }
    if (accepted && frame_.pose.identification_cost < options_.quick_max_identification_cost &&
        RescanWeakStripe(image, source)) {
      return true;
    }
  }
  return false;
}

bool TargetPoseTracker::RescanWeakStripe(const GrayImageView& image, ScanSource source) {
  const double weakest =
      frame_.fit.ok ? *std::min_element(frame_.fit.extent.begin(), frame_.fit.extent.end()) : 1.0;
  if (weakest >= kWeakStripeExtent) return true;
  // A stripe whose points span a short stretch of it leaves the pose's tilt about it loosely
  // told (a glare's slope, a blur across it, tilts it by degrees): its middle between the
  // crossings, scanned from the pose found, tells more. When that gives no pose, the first
  // stands if its stripes are seen over kMinFittedExtent each at least (as a pose fitted
  // without four lines must be); one seen over less leaves the tilt about it to a few runs
  // (a hand's edge across a stripe tilted a sheet by 10 degrees so).
  const vpHomogeneousMatrix first = frame_.pose.cMo;
  const vpHomography plane_to_image = PlaneToImage(first);
  TargetBorders(layout_, plane_to_image, camera_, options_.borders, &borders_);
  AddMiddleBorders(layout_, plane_to_image, camera_, kMiddleBordersPerPair, &borders_);
  if (AsGuesses([&] {
        return !borders_.empty() && Attempt(image, borders_, SeedsFrom(plane_to_image),
                                            std::nullopt, source, Expected{first, false});
      })) {
    return true;
  }
  return EachStripeSeenOverEnough(false, ", and its middle scanned again gave no pose");
}

bool TargetPoseTracker::StarvedStripeInView() const {
  return frame_.fit.starved_line >= 0 &&
         InViewFraction(frame_.fit.starved_line) >= kStarvedInViewFraction;
}

double TargetPoseTracker::InViewFraction(int line) const {
  const StripeSpan& span = layout_.stripes[static_cast<std::size_t>(line)];
  const vpHomography plane_to_image = PlaneToImage(frame_.pose.cMo);
  int inside = 0;
  for (int i = 0; i < kInViewSamples; ++i) {
    const double along =
        span.along.lo + (i + 0.5) / kInViewSamples * (span.along.hi - span.along.lo);
    const PlaneImage at = ThroughHomography(plane_to_image, layout_.OnStripe(line, along, 0.0));
    if (!(at.w > 1e-9)) continue;
    const Point2d pixel = camera_.Pixel(at.x, at.y);
    inside += pixel.u >= 0.0 && pixel.v >= 0.0 && pixel.u <= pose_options_.image_width - 1.0 &&
              pixel.v <= pose_options_.image_height - 1.0;
  }
  return static_cast<double>(inside) / kInViewSamples;
}

bool TargetPoseTracker::EachStripeSeenOverEnough(bool of_its_view, const std::string& tried) {
  if (!frame_.fit.ok) return true;
  double weakest = HUGE_VAL;
  for (int k = 0; k < 4; ++k) {
    const double extent = frame_.fit.extent[static_cast<std::size_t>(k)];
    // A stripe seen over enough of its whole length is seen over enough of its view.
    const bool short_of_view = of_its_view && extent < kMinFittedExtent;
    weakest =
        std::min(weakest, short_of_view ? extent / std::max(InViewFraction(k), 1.0 / kInViewSamples)
                                        : extent);
  }
  if (weakest >= kMinFittedExtent) return true;
  std::ostringstream message;
  message << "a stripe's points span " << weakest << " of it" << (of_its_view ? " in view" : "")
          << " (at least " << kMinFittedExtent << " needed): too little to tell the pose's tilt"
          << tried;
  frame_.status = TargetStatus::kNotFound;
  frame_.message = message.str();
  return false;
}

bool TargetPoseTracker::AttemptCells(const GrayImageView& image,
                                     const std::vector<LightQuad>& cells, bool as_middle_only) {
  int tried = 0;
  bool uncut_tried = false;
  for (LightQuad cell : cells) {
    if (ClosedCorner(cell) >= 0 && corner_guesses_.size() < kMaxCornerGuesses) {
      corner_guesses_.push_back(cell);
    }
    if (cell.ClosedSideCount() < 3 || tried >= options_.max_candidates) continue;
    ++tried;
    const auto refine_start = std::chrono::steady_clock::now();
    finder_.Refine(image, &cell);
    frame_.find_us += MicrosecondsSince(refine_start);
    const std::optional<vpHomography> plane_to_image = PlaneToImageFromCell(layout_, cell, camera_);
    if (plane_to_image && AttemptCandidate(image, *plane_to_image, ScanSource::kMiddleCell)) {
      return true;
    }
    if (as_middle_only) continue;
    // Closed in on three sides: the middle cell broken open (a hand, a glare), or a cell
    // beyond a stripe whose fourth side is the sheet's edge.
    for (const TargetLayout::EdgeCell& edge : layout_.edge_cells) {
      const std::optional<vpHomography> beyond = PlaneToImageFromEdgeCell(edge, cell, camera_);
      if (beyond && AttemptCandidate(image, *beyond, ScanSource::kEdgeCell)) return true;
    }
    // Closed in on four sides, yet not the middle cell: a cell beyond a stripe, the sheet's
    // edge among its sides (something dark and light again beyond it).
    if (cell.ClosedSideCount() == 4 && AttemptEdgeCellGuesses(image, cell)) return true;
    // Not the target's middle cell as it is: one side may be the edge of a hand, a tool or a
    // cable lying across the cell (the first such cell only).
    if (!uncut_tried) {
      uncut_tried = true;
      if (AttemptUncut(image, cell)) return true;
    }
  }
  return false;
}

bool TargetPoseTracker::AsGuesses(const std::function<bool()>& attempts) {
  const TargetFrame as_found = frame_;
  const std::vector<DetectedLine> lines_as_found = lines_;
  if (attempts()) return true;
  RestoreFrame(as_found, lines_as_found);
  return false;
}

bool TargetPoseTracker::AttemptEdgeCellGuesses(const GrayImageView& image, const LightQuad& cell) {
  // When none gives a pose, the frame says what the cell as the middle one gave.
  return AsGuesses([&] {
    for (int outer = 0; outer < 4; ++outer) {
      for (const TargetLayout::EdgeCell& edge : layout_.edge_cells) {
        const std::optional<vpHomography> beyond =
            PlaneToImageFromEdgeCell(edge, cell, camera_, outer);
        if (beyond && AttemptCandidate(image, *beyond, ScanSource::kEdgeCell)) return true;
      }
    }
    return false;
  });
}

bool TargetPoseTracker::AttemptUncut(const GrayImageView& image, const LightQuad& cell) {
  // When none gives a pose, the frame says what the cell as found gave.
  return AsGuesses([&] {
    for (int cut = 0; cut < 4; ++cut) {
      for (const LightQuad& uncut : UncutCells(layout_, cell, cut)) {
        const std::optional<vpHomography> h = PlaneToImageFromCell(layout_, uncut, camera_);
        if (h && AttemptCandidate(image, *h, ScanSource::kMiddleCell)) return true;
      }
    }
    return false;
  });
}

bool TargetPoseTracker::AttemptCornerCells(const GrayImageView& image) {
  return AsGuesses([&] {
    for (LightQuad quad : corner_guesses_) {
      const int inner = ClosedCorner(quad);
      const auto refine_start = std::chrono::steady_clock::now();
      finder_.Refine(image, &quad);
      frame_.find_us += MicrosecondsSince(refine_start);
      for (const TargetLayout::CornerCell& cell : layout_.corner_cells) {
        const std::optional<vpHomography> h =
            PlaneToImageFromCorners(cell.corners, cell.inner, quad, inner, camera_);
        if (h && AttemptCandidate(image, *h, ScanSource::kCornerCell)) return true;
      }
    }
    return false;
  });
}

void TargetPoseTracker::RestoreFrame(const TargetFrame& saved,
                                     const std::vector<DetectedLine>& saved_lines) {
  // The work done since stays counted: its time and the candidates it scanned.
  const double detect_us = frame_.detect_us, pose_us = frame_.pose_us;
  const int candidates = frame_.candidates;
  frame_ = saved;
  frame_.detect_us = detect_us;
  frame_.pose_us = pose_us;
  frame_.candidates = candidates;
  lines_ = saved_lines;
}

const TargetFrame& TargetPoseTracker::Track(
    const GrayImageView& image, const std::optional<vpHomogeneousMatrix>& predicted_cMo) {
  frame_ = TargetFrame{};
  corner_guesses_.clear();
  disagreeing_readings_ = 0;
  pose_options_.image_width = image.width;
  pose_options_.image_height = image.height;
  const std::optional<vpHomogeneousMatrix> prior = predicted_cMo ? predicted_cMo : last_cMo_;
  bool found = false;
  if (options_.scan == ScanMode::kImage) {
    found = Attempt(image, ScanBorders{}, {}, prior, ScanSource::kImage);
  } else {
    if (prior) {
      const vpHomography plane_to_image = PlaneToImage(*prior);
      TargetBorders(layout_, plane_to_image, camera_, options_.tracked_borders, &borders_);
      if (!borders_.empty()) {
        found = Attempt(image, borders_, SeedsFrom(plane_to_image), prior, ScanSource::kPrior,
                        Expected{*prior, false});
      }
    }
    // The finder's looks in turn, each only when none of the one before was the target's:
    // its candidates; the cells again, those much darker than the paper near them taken as
    // dark (a hand or a glare joining the middle cell to its neighbour); those a little darker
    // (a pale hand across it); the light cells narrowed by one (a stripe washed out over a
    // short stretch); split at necks (a crossing washed out over several cells); the cells and
    // their split again with clipped cells as paper, not a glare's core (paper over-exposed
    // beside a light bench).
    using Look = const std::vector<LightQuad>& (SheetFinder::*)(const GrayImageView&);
    for (const Look look : {&SheetFinder::Find, &SheetFinder::FindLocallyLight,
                            &SheetFinder::FindFaintlyDark, &SheetFinder::FindNarrowed,
                            &SheetFinder::FindSplitAtNecks, &SheetFinder::FindClippedAsPaper}) {
      if (found) break;
      const auto start = std::chrono::steady_clock::now();
      const std::vector<LightQuad>& cells = (finder_.*look)(image);
      frame_.find_us += MicrosecondsSince(start);
      // Clipped paper's cells beside a hand or a glare's slope are as often bounded by their
      // edges as by the stripes': such a cell is taken as the middle cell only (as a cell
      // beyond a stripe it gave a pose 2.5 degrees off from a sheet seen over a fifth of two
      // stripes).
      found = AttemptCells(image, cells, look == &SheetFinder::FindClippedAsPaper);
    }
    if (!found && options_.corner_cells) found = AttemptCornerCells(image);
    if (!found && options_.image_fallback) {
      found = Attempt(image, ScanBorders{}, {}, std::nullopt, ScanSource::kImage) &&
              ConfirmOnTarget(image);
    }
  }
  if (!found) {
    if (frame_.source == ScanSource::kNone) frame_.message = "no border could be scanned";
    frames_since_ok_ = frames_since_ok_ > 0 ? frames_since_ok_ + 1 : 0;
    return frame_;
  }
  Accept(predicted_cMo.has_value());
  return frame_;
}

bool TargetPoseTracker::ConfirmOnTarget(const GrayImageView& image) {
  const TargetFrame whole_image = frame_;
  const std::vector<DetectedLine> whole_image_lines = lines_;
  auto keep_whole_image = [&] {
    RestoreFrame(whole_image, whole_image_lines);
    return true;
  };
  if (!AttemptCandidate(image, PlaneToImage(whole_image.pose.cMo), ScanSource::kImage)) {
    // The target's plane gave a pose of its own that the image contradicts, and the whole
    // image's pose puts a stripe where too few of its points lie (a hand's edge along a
    // blurred stripe tilted it by degrees, yet its samples agreed just enough): the stripes
    // are there and neither pose is sure where. (A board seen from near leaves too few stripe
    // points to fit a pose at all: nothing said against its pose.)
    const bool stripe_without_points = whole_image.fit.starved_line >= 0;
    if (frame_.status == TargetStatus::kModelMismatch && stripe_without_points) {
      frame_.message =
          "the whole image's pose is not confirmed on the target's plane seen from it: " +
          frame_.message;
      return false;
    }
    // The target's plane gave nothing (a board seen from near fills the view, its borders'
    // lines too short): the whole image's pose stands as the paper's scan gives it.
    return keep_whole_image();
  }
  double metres = 0.0, degrees = 0.0;
  if (!WithinJump(whole_image.pose.cMo, frame_.pose.cMo, &metres, &degrees)) {
    std::ostringstream message;
    message << "the whole image's pose and the one on the target's plane seen from it are "
            << 1000.0 * metres << " mm and " << degrees
            << " deg apart (max_jump_m = " << options_.max_jump_m
            << ", max_jump_deg = " << options_.max_jump_deg << ")";
    frame_.status = TargetStatus::kModelMismatch;
    frame_.message = message.str();
    return false;
  }
  // Both passed the checks: the one whose four corners a rigid target fits better. (The whole
  // image's lines, when kept, go with the feature points of the plane's scan, the detector's
  // last: the same stripes' points, close to those lines.)
  return frame_.pose.residual_px <= whole_image.pose.residual_px || keep_whole_image();
}

bool TargetPoseTracker::WithinJump(const vpHomogeneousMatrix& a, const vpHomogeneousMatrix& b,
                                   double* metres, double* degrees) const {
  const PoseDistance d = Distance(a, b);
  *metres = d.translation_m;
  *degrees = d.rotation_rad * kDegPerRad;
  return (options_.max_jump_m <= 0.0 || *metres <= options_.max_jump_m) &&
         (options_.max_jump_deg <= 0.0 || *degrees <= options_.max_jump_deg);
}

void TargetPoseTracker::Accept(bool predicted) {
  const vpHomogeneousMatrix& cMo = frame_.pose.cMo;
  // Only a pose found on the borders of the last one is held to it: one found afresh, after
  // those borders showed no target, says the target has moved.
  const bool consecutive =
      frames_since_ok_ == 1 && last_cMo_.has_value() && frame_.source == ScanSource::kPrior;
  const bool checked =
      !predicted && consecutive && (options_.max_jump_m > 0.0 || options_.max_jump_deg > 0.0);
  double metres = 0.0, degrees = 0.0;
  if (checked && !WithinJump(cMo, *last_cMo_, &metres, &degrees)) {
    double held_m = 0.0, held_deg = 0.0;
    if (!(held_cMo_ && WithinJump(cMo, *held_cMo_, &held_m, &held_deg))) {
      held_cMo_ = cMo;
      std::ostringstream message;
      message << "the pose moved " << metres << " m and " << degrees
              << " deg since the last frame (max_jump_m = " << options_.max_jump_m
              << ", max_jump_deg = " << options_.max_jump_deg
              << "): held until the next frame agrees";
      frame_.status = TargetStatus::kJump;
      frame_.message = message.str();
      return;  // the last accepted pose stays the prior; frames_since_ok_ unchanged
    }
  }
  held_cMo_.reset();
  last_cMo_ = cMo;
  frames_since_ok_ = 1;
}

}  // namespace oal
