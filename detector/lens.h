// Lens distortion of feature points (the paper's main source of failures, see NOTES 5), and
// the model's other direction for those who draw or project (the renderer, the tracker's
// model check, the calibrations).
//
// Only the feature points are corrected, never the image: a distorted pixel (u, v) maps to
// the pixel (u', v') where an ideal pinhole camera with the same intrinsics would have seen
// it. ViSP's model is used: pixel -> metre with `kdu` (vpPixelMeterConversion), then metre ->
// pixel without distortion.
#pragma once

#include <visp3/core/vpCameraParameters.h>

#include <string>

#include "detector/line.h"

namespace oal {

class PointUndistorter {
 public:
  explicit PointUndistorter(const vpCameraParameters& camera);

  /// True when the camera model has distortion to correct.
  bool active() const { return kdu_ != 0.0; }
  Point2d Undistort(const Point2d& pixel) const {
    const double du = pixel.u - u0_, dv = pixel.v - v0_;
    const double factor = 1.0 + kdu_ * (du * du * inv_px2_ + dv * dv * inv_py2_);
    return Point2d{u0_ + du * factor, v0_ + dv * factor};
  }

 private:
  double u0_, v0_, inv_px2_, inv_py2_, kdu_;
};

/// ViSP's kdu of `camera`; 0 for a camera without distortion.
double Kdu(const vpCameraParameters& camera);

/// The distorted over the ideal normalised radius of a point whose ideal radius squared is
/// `rho2`, under ViSP's kdu model (ideal rho = r (1 + kdu r^2) of distorted r), to rounding;
/// NaN where kdu < 0 reaches no such radius.
double DistortedOverIdeal(double kdu, double rho2);

/// Distorted pixel of an ideal normalised point (x, y) under the kdu model (numerical
/// inverse of vpPixelMeterConversion); exact to 1e-9 px. With kdu < 0 the model cannot reach
/// points beyond a radius; they come back as NaN.
Point2d DistortedPixel(const vpCameraParameters& camera, double x, double y);

/// The kud that best inverts `kdu` over a width x height image (least squares), so a
/// camera file written with both is consistent in ViSP's two directions.
double FitKud(const vpCameraParameters& camera, int width, int height);

/// A camera with ViSP's distortion model: `kdu` and the kud that best inverts it over a
/// width x height image (FitKud), as a calibration gives both (kud = 0 when kdu = 0).
vpCameraParameters CameraWithKdu(double px, double py, double u0, double v0, double kdu, int width,
                                 int height);

/// Throws std::invalid_argument naming `field` (e.g. "PoseOptions::camera") unless `camera`
/// is a perspective projection, with or without ViSP's distortion, of finite px, py > 0 and
/// finite u0, v0.
void CheckPerspectiveCamera(const vpCameraParameters& camera, const std::string& field);

}  // namespace oal
