#include "detector/lens.h"

namespace oal {

// Undistort() is vpPixelMeterConversion::convertPoint (distorted pixel -> metre, with kdu)
// followed by x -> u0 + px * x, folded into one expression; tests/detector/lens_test.cpp
// checks it against ViSP's own conversion.
PointUndistorter::PointUndistorter(const vpCameraParameters& camera)
    : u0_(camera.get_u0()),
      v0_(camera.get_v0()),
      inv_px2_(1.0 / (camera.get_px() * camera.get_px())),
      inv_py2_(1.0 / (camera.get_py() * camera.get_py())),
      kdu_(camera.get_projModel() == vpCameraParameters::perspectiveProjWithDistortion
               ? camera.get_kdu()
               : 0.0) {}

}  // namespace oal
