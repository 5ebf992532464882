// The camera's intrinsics (px, py, u0, v0) and its lens in OpenCV's model (k1, k2, p1, p2, k3,
// and the rational k4-k6 when asked) from views of a planar target whose points are known on
// its plane, each parameter with its standard deviation.
//
// The solver is OpenCV's calibrateCamera (Zhang's initialisation, then Levenberg-Marquardt on
// the reprojection error, with each parameter's standard deviation and each view's RMS, which
// vpCalibration does not give). Points seen along lines are paired with points of their lines;
// each round's solution is then polished on their distances across the lines, each point
// sliding along its line (Levenberg-Marquardt, its own deviations), before the views and points
// that disagree are left out, round after round until none changes. Every term the views
// determine is kept: one whose value lies within `min_term_significance` standard deviations
// of zero is fixed at zero, with the reason, and the camera solved again (k3 first, then the
// tangential pair). ViSP's one-term model (kud, kdu), for ViSP's own camera XML, is the lens's
// best approximation over the image (Lens::ViSPCamera); its reprojection RMS on the same
// points is given beside the full model's.
#pragma once

#include <string>
#include <vector>

#include "detector/lens.h"
#include "detector/line.h"

namespace oal {

/// A point of the target seen in one view.
struct CalibrationPoint {
  double u = 0.0, v = 0.0;  ///< where it is seen: distorted pixels
  double x = 0.0, y = 0.0;  ///< where it is on the target's plane, metres (z = 0)
};

/// A straight line of the target seen in one view: points seen along it, and the line on the
/// target's plane they lie on. Where along the line each point is, is not known: the line
/// constrains the camera across itself only (a plumb line that also has a known place).
struct CalibrationLine {
  double x = 0.0, y = 0.0;    ///< a point of the line on the target's plane, metres
  double dx = 1.0, dy = 0.0;  ///< its direction on the plane (any length > 0)
  std::vector<Point2d> seen;  ///< distorted pixels of points on it (e.g. a stripe's middle)
  /// When `seen` are the middles of dark runs across a stripe printed along the line: the
  /// stripe's width (metres, > 0) and each point's run (its length times its direction,
  /// distorted pixels; (0, 0) when unknown). Under perspective and a lens a run's middle is
  /// off the image of the centre line; Calibrate moves each along its run to where the camera
  /// it solves puts the centre line, and leaves out a run that does not cross the stripe
  /// from edge to edge; the stripe's printed ends are then (x, y) and (x + dx, y + dy).
  /// Empty: the points lie on the line itself.
  double width_m = 0.0;
  std::vector<Point2d> runs;
};

struct CalibrationView {
  std::string name;  ///< for messages: a file name, "video.mp4#12"
  std::vector<CalibrationPoint> points;
  /// Lines of the target (e.g. the four-line sheet's stripes). A view of lines alone needs
  /// four of them crossing in at least four points on the plane.
  std::vector<CalibrationLine> lines;
};

struct CalibrationOptions {
  int width = 0, height = 0;  ///< the views' image size, pixels; > 0
  int min_views = 3;          ///< usable views needed. Range [3, 1000].
  /// Fewer known points and points on lines together: the view is not used. Range [6, 100000].
  int min_points_per_view = 12;
  /// A view tilted less than this from facing the camera constrains the focal length poorly;
  /// at least min_tilted_views views must tilt more. Degrees, range [0, 80].
  double min_tilt_deg = 10.0;
  int min_tilted_views = 2;         ///< Range [0, 1000].
  bool estimate_distortion = true;  ///< false: the pinhole
  /// Fit OpenCV's rational model too (k4, k5, k6: lenses wider than ~100 degrees).
  bool rational = false;
  /// A term within this many standard deviations of zero is fixed at zero. Range [0, 10].
  double min_term_significance = 2.0;

  /// Throws std::invalid_argument naming the field, its value and the violated constraint.
  void Check() const;
};

struct CalibrationViewReport {
  std::string name;
  bool used = false;
  std::string rejected;  ///< why it was not used (empty when used)
  int points = 0;
  double rms_px = 0.0;    ///< reprojection RMS of its points (used views)
  double tilt_deg = 0.0;  ///< the target plane's angle to the image plane (used views)
};

struct CalibrationResult {
  /// OpenCV's model with the terms the views determine; the pinhole when
  /// estimate_distortion is false.
  Lens camera;
  double rms_px = 0.0;  ///< reprojection RMS over every point of the views used
  /// The reprojection RMS of ViSP's one-term approximation of `camera` over the image (what
  /// a ViSP camera XML holds) on the same points and view poses.
  double visp_rms_px = 0.0;
  /// Standard deviations of px, py, u0, v0 (pixels) and of each distortion term, from the
  /// solver's covariance; 0 for a term fixed at zero.
  double px_sd = 0.0, py_sd = 0.0, u0_sd = 0.0, v0_sd = 0.0;
  Distortion distortion_sd;
  /// The terms fixed at zero, each with the reason ("k3 fixed at 0: ...").
  std::vector<std::string> fixed_terms;
  std::vector<CalibrationViewReport> views;  ///< one per view given, in order
  /// What the user can do about poorly determined parameters ("tilt the target more").
  std::vector<std::string> advice;
};

/// Calibrates from `views`. Throws std::invalid_argument for options failing Check(), and
/// std::runtime_error saying why when the views cannot determine the camera: too few usable
/// views (each rejected view with its reason), or all of them nearly facing the camera.
CalibrationResult Calibrate(const std::vector<CalibrationView>& views,
                            const CalibrationOptions& options);

}  // namespace oal
