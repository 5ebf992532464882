// Camera pose from the four-line target (../shared/paper/ordered-list-hough.md, section 4).
//
//   step 1  identify the detected lines as target lines 1-4          IdentifyTargetLines()
//   step 2  roll from the orientation of line 1, over 0-360 deg      PoseResult::line1_roll_deg
//   step 3  the four intersections -> a pose: the previous one, or   EstimatePose()
//           the corners' homography's, refined and kept alone when it
//           fits; else vpPose (Dementhon, Lagrange, lower residual
//           kept); corners corrected for the perspective shift of wide
//           stripes' middles; refined by Gauss-Newton on the corners,
//           virtual visual servoing's model and update on fixed-size
//           matrices (vpPose's where that fails), also from the
//           previous pose if given)
//   step 4  the position; the paper's plane angles (Eq. 5) reported  PoseResult::plane_angle_deg
//
// Target. A LineTarget (target/line_target.h) whose lines 1 and 3 are parallel, lines 2 and 4 are
// parallel and lines 1 and 2 cross: a '#'. Its four corners are
//     corner k = line k ∩ line k+1   (k = 1..4, line 5 = line 1),
// i.e. in 0-based arrays corner[k] = lines[k] ∩ lines[(k + 1) % 4]. FourLineTarget() is one.
//
// Identification rule (step 1, IdentifyTargetLines()):
//   1. Four lines are taken: the first four detected (best first); if they fail the rule
//      below, every other 4-subset of the first `max_candidate_lines` is tried and the one
//      with the lowest cost that passes is kept.
//   2. The four are split into two groups of two (3 possible splits): the split with the
//      largest smallest angle between lines of different groups. That angle must reach
//      min_group_angle_deg, else kDegenerate (e.g. two target lines replaced by lines parallel
//      to the others). The four intersections of the groups must lie near the image
//      (max_intersection_radius, max_outside_px), form a convex quadrilateral with sides of at
//      least min_side_px, else kDegenerate.
//   3. Of the 8 ways to map the image groups onto the target's two pairs of parallel lines
//      (the symmetries of a square), the 4 that preserve orientation are kept (a reflection
//      would put the camera behind the board). For each, the homography H (board plane ->
//      pixels) through the four corners is formed, and scored by
//        cost = [log²(|g1|/|g2|) + cos²(g1, g2)] / ortho_sigma²
//             + Σ_k (r_k - mean r)² / width_sigma²,      r_k = log(measured / predicted width)
//      where g1, g2 are the first two columns of K⁻¹H (a rotation's columns, up to scale, for
//      the right assignment: this term rejects the two 90° turns, which map the target's
//      rectangle onto one of the wrong aspect), and the predicted width of line k is H's image
//      of its printed width at the middle of its visible part (this term separates the two
//      180° turns: lines 1 and 3 are 30 and 20 mm wide, lines 2 and 4 15 and 17.5 mm). The
//      width term is left out when a width is unknown (width_px = 0, edge polarity).
//   4. The lowest cost wins if it is at most max_identification_cost and the runner-up's cost
//      exceeds it by at least min_identification_margin; otherwise kNotIdentifiable.
//   Nothing in the rule depends on the roll, so it holds over the full 0-360 deg.
//
// Pixels: the lines are in undistorted pixels when the detector corrects distortion
// (OalDetector::Undistorts(), then x = (u - u0)/px exactly), otherwise in image pixels (the
// intersections are then converted with vpPixelMeterConversion, i.e. with kdu; the lines
// themselves are then only approximately the images of the target's lines, see
// feature_line.h). See PoseOptions::lines_undistorted. The residual is always in undistorted pixels
// (px times the normalised reprojection error).
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/core/vpMatrix.h>

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "detector/detector.h"
#include "detector/lens.h"
#include "detector/line.h"
#include "target/line_target.h"

namespace oal {

enum class PoseStatus {
  kOk,
  kNotEnoughLines,   ///< fewer than 4 lines
  kNotIdentifiable,  ///< no assignment of lines 1-4 clearly better than the others
  kDegenerate,       ///< nearly parallel groups, far or non-convex corners, pose behind the
                     ///< camera, vpPose failure, or residual too large
};

/// Which pose was refined into the result: a linear method's (vpPose::DEMENTHON or LAGRANGE),
/// the previous pose alone (PoseOptions::previous_accept_px), or, without one, the pose of the
/// four corners' homography alone (PoseOptions::homography_accept_px); kStripes: no four lines
/// to intersect, the pose fitted to the stripes' points from where the target was expected
/// (servo/target_tracker.h).
enum class PoseMethod { kNone, kDementhon, kLagrange, kPrevious, kHomography, kStripes };

/// The one place where these enums meet strings ("ok", "not-enough-lines",
/// "not-identifiable", "degenerate"; "none", "dementhon", "lagrange", "previous", "homography",
/// "stripes").
std::string ToString(PoseStatus status);
std::string ToString(PoseMethod method);

struct PoseOptions {
  /// Intrinsics (and kdu when the model has distortion) of the camera that took the frame.
  Lens camera = Lens::Pinhole(600.0, 600.0, 319.5, 239.5);
  /// true: the lines are in undistorted pixels (OalDetector::Undistorts()), converted to
  /// metres by x = (u - u0)/px; false: in image pixels, converted with kdu
  /// (vpPixelMeterConversion).
  bool lines_undistorted = true;

  // --- Step 1: identification ----------------------------------------------------------
  /// Lines considered, best first. Range [4, 12].
  int max_candidate_lines = 6;
  /// Smallest angle between lines of different groups, degrees. Range (0, 90).
  double min_group_angle_deg = 15.0;
  /// Image size in pixels for max_outside_px; 0 x 0: unknown (only the radius check).
  int image_width = 0, image_height = 0;  ///< Range [0, 100000], both 0 or both > 0.
  /// Corners may lie at most this far outside the image, pixels. Range [0, 1e6].
  double max_outside_px = 200.0;
  /// Corners may lie at most this far from the optical axis, normalised units (tan of the
  /// angle off the axis). Range (0, 100].
  double max_intersection_radius = 2.0;
  /// Shortest side of the corners' quadrilateral, pixels. Range [0, 1e6].
  double min_side_px = 4.0;
  /// Spread of the orthonormality terms of K⁻¹H for the right assignment. Range (0, 10].
  double ortho_sigma = 0.05;
  /// Spread of log(measured / predicted width) for the right assignment. Range (0, 10].
  double width_sigma = 0.07;
  /// The winner's cost must not exceed this. Range (0, 1e9].
  double max_identification_cost = 50.0;
  /// The runner-up's cost must exceed the winner's by at least this. Range [0, 1e9].
  double min_identification_margin = 9.0;
  /// Continuity of lines 1-4 with a previous pose (tracking, servo): when the frame's best
  /// assignment is turned by more than this from the previous pose and another assignment is
  /// within it with a cost under max_identification_cost, that one is taken (one badly
  /// measured stripe width must not turn the target by 90 or 180 deg between frames); the
  /// four assignments differ by 90 or 180 deg. 0: the frame alone decides. Degrees,
  /// range [0, 180].
  double previous_max_deg = 45.0;

  // --- Steps 3-4: pose -----------------------------------------------------------------
  /// Largest acceptable reprojection RMS, undistorted pixels. Range (0, 1000].
  double max_residual_px = 2.0;
  /// The refinement seeded by the previous pose is kept when its residual is at most the
  /// other's plus this, undistorted pixels. Range [0, 1000].
  double previous_tolerance_px = 0.1;
  /// Every corner must lie at least this far in front of the camera, metres. Range (0, 1e3].
  double min_depth_m = 0.01;
  /// The detector reports the middle of a stripe's image, which under perspective is not the
  /// image of the stripe's centre line (off by up to ~0.5 px for a 30 mm stripe at 0.3 m
  /// tilted by 40 deg). true: the corners are moved by the difference between the images of
  /// the centre lines and of the stripe middles (lines with width_px > 0) seen from the
  /// linear pose, before the refinement.
  bool correct_stripe_centres = true;
  /// Dementhon runs besides Lagrange (the lower residual is refined) only when Lagrange's
  /// residual is at least this, undistorted pixels: below it both end in the same minimum
  /// after the refinement, and Dementhon costs ~15 us. 0 always runs both. Range [0, 1000].
  double dementhon_above_px = 0.5;
  /// With a previous pose (a loop): the refinement seeded by it is kept without running the
  /// linear methods when its residual is below this, undistorted pixels (the usual case in a
  /// servo loop: ~3x faster). 0 always runs the linear methods too. Range [0, 1000].
  double previous_accept_px = 0.5;
  /// Without a previous pose (a first frame): the pose of the four corners' homography,
  /// refined, is kept without running vpPose's linear methods when its residual is below
  /// this, undistorted pixels (~4x faster). 0 always runs the linear methods. Range [0, 1000].
  double homography_accept_px = 0.5;
  /// Compute PoseResult::covariance (vpPose's virtual visual servoing once more, with ViSP's
  /// dynamic matrices: ~170 us a frame on the CI machine, three times the rest of the pose;
  /// the servo loop and the benchmarks run without it). Range: bool.
  bool compute_covariance = true;
  /// Iterations of vpPose's virtual visual servoing (the covariance's, and the refinement's
  /// where the fixed-size one fails). Range [1, 1000].
  int vvs_max_iterations = 200;

  /// Throws std::invalid_argument naming the field, its value and the violated constraint.
  void Check() const;
  /// These options for an image `scale` times as many pixels across (a camera of `scale`
  /// times the focal length): the corners' bounds in pixels (max_outside_px, min_side_px) and
  /// the largest residual (max_residual_px: blur and a stripe's edges spread with the pixels)
  /// times `scale`. `scale` in (0, 100].
  PoseOptions ScaledBy(double scale) const;
};

struct PoseResult {
  PoseStatus status = PoseStatus::kNotEnoughLines;
  std::string message;  ///< empty when kOk; the reason otherwise

  /// Target (object) frame to camera frame; identity unless kOk.
  vpHomogeneousMatrix cMo;
  /// line_index[k] = index in the detected lines of target line k + 1; -1 when unknown.
  /// Set from step 1 on (also for kDegenerate found after step 1).
  std::array<int, 4> line_index{{-1, -1, -1, -1}};
  /// corner k = line k+1 ∩ line k+2 (0-based: lines[k] ∩ lines[(k+1) % 4]), in the lines'
  /// pixels (undistorted if lines_undistorted) and in normalised metres; after the
  /// stripe-centre correction (PoseOptions::correct_stripe_centres) when kOk.
  std::array<Point2d, 4> corners_px{};
  std::array<vpColVector, 4> corners_m{};  ///< each (x, y)
  /// Reprojection RMS of the corners, undistorted pixels.
  double residual_px = 0.0;
  /// 6x6 covariance of the pose (vpPose::getCovarianceMatrix after VIRTUAL_VS), in ViSP's
  /// velocity-twist order (v, ω).
  vpMatrix covariance;

  /// cRo = Rz(roll) Ry(yaw) Rx(pitch) (vpRzyxVector): roll about the optical axis in [0, 360),
  /// yaw and pitch in (-180, 180]; all 0 when the camera faces the board with the target's x
  /// and y along the image's u and v.
  double roll_deg = 0.0, pitch_deg = 0.0, yaw_deg = 0.0;
  /// Paper step 2: the direction of line 1 in the image, from its corner with line 2 to its
  /// corner with line 4 (the target's +y for FourLineTarget()), measured from the image's +v
  /// axis towards -u, in [0, 360). Equals roll_deg for a camera facing the board.
  double line1_roll_deg = 0.0;
  /// Paper Eq. 5: for lines 1 and 2, the angle by which the board plane is turned about the
  /// line (atan2 of the board normal's component across the line in the image plane, over
  /// its component along the optical axis), degrees. To first order in the tilt,
  /// plane_angle_deg[0] = yaw_deg and plane_angle_deg[1] = pitch_deg for FourLineTarget().
  std::array<double, 2> plane_angle_deg{{0.0, 0.0}};

  PoseMethod method = PoseMethod::kNone;  ///< the pose whose refinement won
  bool from_previous = false;          ///< true when the refinement seeded by previous_cMo was kept
  double identification_cost = 0.0;    ///< the winner's cost (step 1)
  double identification_margin = 0.0;  ///< runner-up's cost minus the winner's
};

/// `result`'s pose replaced by `cMo` (a refinement of it, e.g. servo/stripe_fit.h's), with the
/// angles that follow from it (roll, yaw, pitch, plane angles); the rest is kept.
void ReplacePose(const vpHomogeneousMatrix& cMo, const LineTarget& target, PoseResult* result);

/// Step 1 only, with the corners (status kOk when identified; never kOk with fewer than 4
/// lines). Fills status, message, line_index, corners_px, identification_cost and
/// identification_margin. Throws std::invalid_argument if the options fail Check() or
/// `target` is not a '#' (see the file comment).
PoseResult IdentifyTargetLines(const std::vector<DetectedLine>& lines, const LineTarget& target,
                               const PoseOptions& options);

/// Steps 1-4. `previous_cMo`, the pose of the previous frame of a sequence, seeds a second
/// refinement that is kept when its residual is comparable, so the planar pose ambiguity does
/// not flip between frames. Never throws for a frame; throws std::invalid_argument if the
/// options fail Check() or `target` is not a '#'.
PoseResult EstimatePose(const std::vector<DetectedLine>& lines, const LineTarget& target,
                        const PoseOptions& options,
                        const std::optional<vpHomogeneousMatrix>& previous_cMo = std::nullopt);

}  // namespace oal
