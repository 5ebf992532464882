// Lens distortion of feature points (the paper's main source of failures, see NOTES 5).
//
// Only the feature points are corrected, never the image: a distorted pixel (u, v) maps to
// the pixel (u', v') where an ideal pinhole camera with the same intrinsics would have seen
// it. ViSP's model is used: pixel -> metre with `kdu` (vpPixelMeterConversion), then metre ->
// pixel without distortion.
#pragma once

#include <visp3/core/vpCameraParameters.h>

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

}  // namespace oal
