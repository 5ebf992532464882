// ViSP's radial distortion (kdu, kud) from points that must lie on straight lines (the
// plumb-line method): the stripes of the printed target, seen through a lens nobody measured.
//
// The lens is fitted as the detector will correct it: kdu, ViSP's distorted-to-ideal term
// x_u = x_d (1 + kdu r_d^2), is the one that makes the lines straightest. kud, the other
// direction (for drawing and projecting), is the single term that best undoes it over the
// whole image, as a calibrated camera file pairs them. (Fitting kud to the lines and deriving
// kdu instead measured the lens only where the stripes are: on a sheet 0.6 m away, in the
// middle of the image, kdu came out 11 % high.)
//
// For a fixed kdu each line is a total-least-squares fit of its ideal points; for fixed lines
// the residuals are linear in kdu, one least-squares step. The two alternate until kdu
// settles; points far from their line (a stray mark, the other stripe at a crossing) are left
// out by a robust cut on the median residual. Lines through the principal point do not bend
// and tell nothing; the solution says when the lines together do not determine the lens.
#pragma once

#include <string>
#include <vector>

#include "detector/line.h"

namespace oal {

struct PlumbLineOptions {
  int min_lines = 4;             ///< Range [1, 100000].
  int min_points_per_line = 10;  ///< fewer: the line is not used. Range [3, 1000000].
  /// kdu must come out inside this range, else the lines are refused as not telling it.
  double kdu_min = -0.5, kdu_max = 1.5;
  /// The image the lines are seen in, pixels: kud is fitted over it. > 0.
  int width = 640, height = 480;

  /// Throws std::invalid_argument naming the field, its value and the violated constraint.
  void Check() const;
};

struct PlumbLineResult {
  double kdu = 0.0;     ///< distorted to ideal: the straightest lines
  double kdu_sd = 0.0;  ///< its standard deviation from the residuals
  double kud = 0.0;     ///< ideal to distorted: the single term that best undoes kdu
  /// RMS distance of the points from their lines, pixels: straight (kdu = 0) and corrected.
  double rms_before_px = 0.0, rms_after_px = 0.0;
  int lines = 0, points = 0;  ///< used
};

/// kdu and kud from `lines`, each the distorted pixels of one straight line, seen by a camera
/// with focal lengths px, py and principal point u0, v0 (pixels). Throws std::invalid_argument
/// for options failing Check(), and std::runtime_error saying why when the lines cannot
/// determine the lens: too few lines with enough points, or lines that pass too near the
/// principal point to bend.
PlumbLineResult EstimateRadialDistortion(const std::vector<std::vector<Point2d>>& lines, double px,
                                         double py, double u0, double v0,
                                         const PlumbLineOptions& options = PlumbLineOptions());

}  // namespace oal
