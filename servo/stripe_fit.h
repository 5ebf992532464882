// The pose refined on the stripes' own feature points, the target held rigid.
//
// The intersections' pose (pose.h) rests on four lines, each fitted on its own to the feature
// points near it; on a far sheet a line pulled by a pixel tilts the pose by degrees, and a run
// merged with a finger, a pen or a shadow beside a stripe pulls its line that much. Here every
// run middle the detector found on a stripe's printed stretch pulls that stripe's projected
// centre line towards it, and the pose's six parameters move the four lines together: the
// points of one stripe that the other three stripes, and the rest of its own, do not agree
// with are let go (Tukey's biweight on a robust scale), however many borders they came from.
// The same points tell how much of each stripe the image shows where the pose puts it.
//
// Points: the detector's feature points (detector/line_fit.h FramePoint) in its pixels
// (undistorted when it corrects the lens, else the image's, then converted with the camera's
// kdu). Only runs along one side of a border (a run round a border's corner gives the middle of
// its ends, off the stripe) whose width across the stripe is within a factor of the stripe's
// width where the pose puts it, between the stripe's printed ends and off the crossings, and
// with paper as light on both sides (beside a glare's slope a run's middle is pulled off its
// stripe: a few such runs at one end of a far sheet's stripe tilt its pose by degrees). Each
// run's middle is moved onto the image of the centre line's locus first: under perspective
// the middle between converging edges is off it (a few hundredths of a pixel, up to half a
// pixel for a wide stripe seen at a slant), as the corners are in pose.h. A stripe whose
// points are not all within a pixel of one straight line (something dark lying along it lines
// up runs of its own a pixel or two off) keeps those on the line most of them lie on (least
// median of distances), before the fit weighs them.
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "detector/lens.h"
#include "detector/line_fit.h"
#include "servo/target_layout.h"

namespace oal {

struct StripeFitOptions {
  /// Feature points farther than this from a stripe's projected centre line (where the
  /// starting pose puts it) are not the stripe's, pixels. Range (0, 1000].
  double corridor_px = 4.0;
  /// The residuals' robust scale never goes below this, pixels: a clean frame's points lie
  /// within a tenth of a pixel of the line, and the biweight's cut (4.685 scales) must not
  /// let the stripe's own points go. Range (0, 100].
  double min_scale_px = 0.1;
  /// A run is the stripe's only when its width across the stripe is within this factor of
  /// the stripe's width where the pose puts it (blur and the threshold change a width a
  /// little; a run merged with a finger, a pen or a cable lying against the stripe changes it
  /// by their width, and its middle by half that). Range [1, 100].
  double max_width_ratio = 1.35;
  /// A run one side of which is lighter than the other by more than this fraction of its
  /// depth (FramePoint::background_step: a glare's slope, a shadow's edge beside the stripe)
  /// is not centred on its stripe and is left out. Range (0, 1e9].
  double max_background_step = 0.2;
  /// Gauss-Newton steps at most. Range [1, 100].
  int max_iterations = 12;
  /// Each stripe needs at least this many points kept. Range [2, 1000].
  int min_points = 4;
  /// A feature point this close to a stripe's guide line (FitStripes' `guides`) is the
  /// stripe's, wherever the starting pose puts the stripe, pixels. Range (0, 100].
  double guide_tolerance_px = 2.0;

  /// Throws std::invalid_argument naming the field, its value and the violated constraint.
  void Check() const;
};

struct StripeFit {
  bool ok = false;
  std::string message;  ///< why not, when not ok
  vpHomogeneousMatrix cMo;
  std::array<int, 4> points{};  ///< points kept on lines 1-4 (within 2.5 robust scales)
  int TotalPoints() const { return points[0] + points[1] + points[2] + points[3]; }
  /// The fraction of each stripe's printed length (between the crossings and its ends, both
  /// arms) that its kept points span: a stripe half hidden under a hand shows about 0.5. Only
  /// stretches of three points or more count (SupportedExtent): two runs cut by a hand's
  /// edge far from the rest do not make a stripe seen over its length.
  std::array<double, 4> extent{};
  /// The median, over each stripe's kept points, of its run's width across over the stripe's
  /// width there where the pose puts it: about 1 for the right pose, the ratio of two stripes'
  /// widths for one that takes a stripe for another (turned by 180 degrees).
  std::array<double, 4> width_ratio{};
  /// The same as a difference, pixels: the median of the kept runs' widths across less the
  /// stripe's there. Blur and the threshold widen every stripe's runs by about as many pixels.
  std::array<double, 4> width_excess_px{};
  /// The median, over each stripe's kept points, of the stripe's width across where the pose
  /// puts it, pixels.
  std::array<double, 4> width_px{};
  double rms_px = 0.0;                  ///< of the kept points' distances to their lines, pixels
  std::array<double, 4> line_rms_px{};  ///< the same for each line's kept points
  double scale_px = 0.0;                ///< the residuals' robust scale at the end, pixels
  /// The last step's weighted normal matrix of the motion (v, w) in the camera's frame,
  /// row-major, per pixel squared: with scale_px, the pose's covariance. Where the points lie
  /// and how they scatter fix the rotation: a far or face-on sheet seen on short stretches of
  /// its stripes has its tilt poorly fixed.
  std::array<double, 36> normal{};
  /// The rotation's standard deviation about its worst-fixed axis, radians.
  double RotationDeviation() const;
  /// How many standard deviations (Mahalanobis, under the rotation's covariance) the rotation of
  /// `other_cMo` lies from this fit's.
  double RotationDistance(const vpHomogeneousMatrix& other_cMo) const;
  /// The line (0-3) that kept fewer than min_points, when that is why the fit is not ok; -1
  /// otherwise.
  int starved_line = -1;
  int iterations = 0;
};

/// Lines known to be lines 1-4 (a detected line identified with a stripe), in the points'
/// pixels; a stripe without one is found by the corridor alone.
using StripeGuides = std::array<std::optional<LineParams>, 4>;

/// The runs of one stripe a fit keeps by their width: those whose width across less the
/// stripe's, pixels, lies in [min_excess_px, max_excess_px].
struct RunWidthBand {
  int line = -1;  ///< 0-3
  double min_excess_px = 0.0, max_excess_px = 0.0;
};

/// The fraction of a stripe `length` long (its ends in `along`'s units) that the points at
/// `along` (sorted in place) span, counting only stretches of three points or more, each
/// within 5 % of the length of the next; 0 when there is none.
double SupportedExtent(std::vector<double>* along, double length);

/// The other pose a plane's view is nearly as well explained by (the planar ambiguity: the
/// plane tilted the other way about the line of sight to its origin, its origin where it is):
/// where a fit from `cMo` may have settled instead of the right one when the tilt is small or
/// the target far. `cMo` itself when the plane faces the camera.
vpHomogeneousMatrix MirroredTilt(const vpHomogeneousMatrix& cMo);

/// The pose that best puts lines 1-4 of `layout` through their stripes' feature points in
/// `points`, from `start` (near enough for its projected stripes to lie within corridor_px of
/// their points). `points_undistorted`: the points are in undistorted pixels (the detector
/// corrects the lens). Not ok when a stripe keeps fewer than min_points, the points cannot
/// fix the pose, or the steps diverge (the message says which).
/// `guides`, when given, take each stripe's points near its guide line (guide_tolerance_px,
/// between its printed ends as `start` puts them, wide enough) however far `start` puts the
/// stripe: a start tens of pixels off still converges when the stripes' lines were told.
/// `left_out_line` (0-3), when given, keeps none of that stripe's points: the pose the other
/// three hold (three lines fix a plane's pose), that line needing no min_points.
/// `known`, when given, is a pose already fitted: the fit stops, not ok, as soon as its steps
/// bring it back there (SameFitPose), as a fit from the other tilt mostly does.
/// `band`, when given, keeps only those of its stripe's runs whose width it holds.
StripeFit FitStripes(const vpHomogeneousMatrix& start, const TargetLayout& layout,
                     const std::vector<FramePoint>& points, const Lens& camera,
                     bool points_undistorted, const StripeFitOptions& options = {},
                     const StripeGuides* guides = nullptr, int left_out_line = -1,
                     const vpHomogeneousMatrix* known = nullptr,
                     const RunWidthBand* band = nullptr);

/// Whether two fitted poses are one: within 2e-3 rad, and 2e-3 of `b`'s depth apart. A fit
/// from the other tilt that comes back lands within 3e-3 rad of the first fit on the bench
/// frames, however wide its corridor; one settling on the other tilt, 0.5 rad or more away.
bool SameFitPose(const vpHomogeneousMatrix& a, const vpHomogeneousMatrix& b);

}  // namespace oal
