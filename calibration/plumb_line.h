// ViSP's distortion coefficient kdu from points that must lie on straight lines (the plumb-line
// method): the stripes of the printed target, seen through a lens nobody measured yet.
//
// ViSP's model maps a distorted normalised point x_d to the ideal one as
// x_u = x_d (1 + kdu r_d^2). For a fixed kdu each line is a total-least-squares fit of its
// undistorted points; for fixed lines the residuals are linear in kdu, which is then a
// one-unknown least-squares solution. The two steps alternate until kdu settles; points far
// from their line (a stray mark, the other stripe at a crossing) are left out by a robust
// cut on the median residual. Lines through the principal point do not bend and tell nothing;
// the solution says when the lines together do not determine kdu.
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

  /// Throws std::invalid_argument naming the field, its value and the violated constraint.
  void Check() const;
};

struct PlumbLineResult {
  double kdu = 0.0;
  /// Standard deviation of kdu from the residuals.
  double kdu_sd = 0.0;
  /// RMS distance of the points from their lines, pixels: straight (kdu = 0) and corrected.
  double rms_before_px = 0.0, rms_after_px = 0.0;
  int lines = 0, points = 0;  ///< used
};

/// kdu from `lines`, each the distorted pixels of one straight line, seen by a camera with
/// focal lengths px, py and principal point u0, v0 (pixels). Throws std::invalid_argument for
/// options failing Check(), and std::runtime_error saying why when the lines cannot determine
/// kdu: too few lines with enough points, or lines that pass too near the principal point to
/// bend.
PlumbLineResult EstimateKdu(const std::vector<std::vector<Point2d>>& lines, double px, double py,
                            double u0, double v0,
                            const PlumbLineOptions& options = PlumbLineOptions());

}  // namespace oal
