// The camera's intrinsics (px, py, u0, v0) and ViSP's radial distortion (kud, kdu) from views
// of a planar target whose points are known on its plane.
//
// The solver is OpenCV's calibrateCamera (Zhang's initialisation, then Levenberg-Marquardt on
// the reprojection error, with each parameter's standard deviation and each view's RMS, which
// vpCalibration does not give) with two radial terms, x_d = x (1 + k1 r^2 + k2 r^4)
// on ideal normalised coordinates. ViSP's model has one term in each direction, kud (ideal to
// distorted) and kdu (distorted to ideal), and the inverse of one term is a series: a single
// term would bend px and u0 to absorb what it misses. So the lens is fitted with two, and
// ViSP's kud and kdu are then each the least-squares best single term over the part of the
// image the views cover.
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
  bool estimate_distortion = true;  ///< false: kud = kdu = 0

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

/// OpenCV's radial distortion, ideal to distorted: x_d = x (1 + k1 r^2 + k2 r^4 + k3 r^6)
/// (k3 = 0 from Calibrate).
struct RadialDistortion {
  double k1 = 0.0, k2 = 0.0, k3 = 0.0;
};

struct CalibrationResult {
  /// perspectiveProjWithDistortion (px, py, u0, v0, kud, kdu), or without distortion when
  /// estimate_distortion is false.
  Lens camera;
  double rms_px = 0.0;  ///< reprojection RMS over every point of the views used
  /// The solver's lens: OpenCV's radial coefficients.
  RadialDistortion lens;
  /// Standard deviations of px, py, u0, v0 (pixels) and k1, from the solver's covariance.
  double px_sd = 0.0, py_sd = 0.0, u0_sd = 0.0, v0_sd = 0.0, k1_sd = 0.0;
  std::vector<CalibrationViewReport> views;  ///< one per view given, in order
  /// What the user can do about poorly determined parameters ("tilt the target more").
  std::vector<std::string> advice;
};

/// Calibrates from `views`. Throws std::invalid_argument for options failing Check(), and
/// std::runtime_error saying why when the views cannot determine the camera: too few usable
/// views (each rejected view with its reason), or all of them nearly facing the camera.
CalibrationResult Calibrate(const std::vector<CalibrationView>& views,
                            const CalibrationOptions& options);

/// ViSP's one-term coefficients in both directions.
struct RadialFit {
  double kud = 0.0, kdu = 0.0;
};

/// The kud and the kdu that best describe `lens` over a width x height image (least squares
/// on a grid of its pixels), within `max_radius` (distorted normalised coordinates) of the
/// principal point.
RadialFit FitViSPDistortion(const RadialDistortion& lens, double px, double py, double u0,
                            double v0, int width, int height, double max_radius = 1e9);

}  // namespace oal
