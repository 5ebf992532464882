// vpFeatureLine from our lines, with lens distortion handled.
//
// ViSP's line feature lives in the normalised image plane (x = X/Z, y = Y/Z, "metres"):
//     x·cos(theta) + y·sin(theta) = rho                              (vpFeatureLine, vpLine)
// Our lines live in pixels, u·cos(theta) + v·sin(theta) = rho with u = column, v = row
// (detector/line.h). Two pixel frames matter:
//
//  * undistorted pixels, u' = u0 + px·x, v' = v0 + py·y: what OalDetector reports when it was
//    given the camera (it undistorts its feature points with ViSP's kdu model, lens.h). A
//    3-D line is a straight line there, and the map to metres is affine, so the conversion
//    is EXACT: MetricLineFromUndistorted(), BuildFeatureLineFromUndistorted().
//  * image (distorted) pixels: what a detector without the camera, vpMeLine, or OpenCV
//    report. With kdu != 0 the image of a 3-D line is a CURVE; the straight line fitted to it
//    is no line in metres, and no exact conversion exists. The APPROXIMATE path
//    (UndistortedLineFromDistortedSegment(), BuildFeatureLineFromDistorted()) undistorts
//    points of the fitted segment with kdu (vpPixelMeterConversion::convertPoint) and fits a
//    line to them by total least squares; its error is the sag of the curve, well below a
//    pixel for a moderate lens, where ignoring distortion costs pixels to tens of pixels
//    (servo/feature_line_test.cpp measures both).
//
// ViSP's own vpFeatureBuilder::create(vpFeatureLine&, cam, const vpMeLine&) converts the
// vpMeLine's (rho, theta) with vpPixelMeterConversion::convertLine, which uses px, py, u0, v0
// only: it ignores kdu, i.e. it treats the distorted-image line as if it were undistorted.
// Without distortion it agrees with ours to rounding (the tests check that too).
//
// Sign and angle: (rho, theta) and (-rho, theta + pi) are the same line. vpLine::projection
// gives theta in (-pi, pi], with the orientation set by its planes; ours come out with theta
// in [0, pi) (the pixel -> metre map keeps the normal in the upper half plane). vpServo's
// error (s - s*) is only meaningful when s and s* use the same orientation: align the current
// feature to the desired one with AlignedTo() before building it.
//
// vpFeatureLine::interaction() also needs the plane (A, B, C, D) through the 3-D line, which
// no image gives: these builders set rho and theta only; set the plane with setABCD() (from a
// pose, e.g. the pose evaluation's). They never touch A, B, C, D.
#pragma once

#include <visp3/visual_features/vpFeatureLine.h>

#include "detector/detector.h"
#include "detector/lens.h"
#include "detector/line.h"

namespace oal {

/// A line in the normalised image plane, vpFeatureLine's convention (see the file comment).
struct MetricLine {
  double rho_m = 0.0;      ///< metres at unit depth (normalised coordinates), may be < 0
  double theta_rad = 0.0;  ///< [0, pi) from our functions; AlignedTo() may move it by pi
};

/// Exact conversion of a line in undistorted pixels (u' = u0 + px·x, v' = v0 + py·y) to
/// metres; any kdu/kud of `camera` is irrelevant here. Result theta in [0, pi).
MetricLine MetricLineFromUndistorted(const LineParams& undistorted, const Lens& camera);

/// The inverse: a metric line to undistorted pixels (theta in [0, pi), line.h).
LineParams UndistortedFromMetricLine(const MetricLine& line, const Lens& camera);

/// APPROXIMATE undistorted-pixel line for the segment a-b of a line fitted in the distorted
/// image (e.g. its visible part): `samples` points spread evenly from a to b (>= 2; the ends
/// included) are undistorted with the kdu model of `camera` and fitted by total least
/// squares. `rms_px`, if given, receives the RMS distance of the undistorted samples from the
/// fit (0 without distortion; it grows with the curvature the straight fit ignored). Without
/// distortion in `camera` the result is the line through a and b. Throws
/// std::invalid_argument if a == b or samples < 2.
LineParams UndistortedLineFromDistortedSegment(const Point2d& a, const Point2d& b,
                                               const Lens& camera, int samples = 16,
                                               double* rms_px = nullptr);

/// The same line with the orientation whose theta is closest to `reference_theta_rad`
/// (angles compared modulo 2 pi): (rho, theta) or (-rho, theta + pi), theta in (-pi, pi].
MetricLine AlignedTo(const MetricLine& line, double reference_theta_rad);

/// Sets rho and theta of `*feature` (vpFeatureLine::buildFrom); A, B, C, D are untouched.
void BuildFeatureLine(const MetricLine& line, vpFeatureLine* feature);

/// Exact: a line in undistorted pixels (OalDetector with the camera) to `*feature`.
void BuildFeatureLineFromUndistorted(const LineParams& undistorted, const Lens& camera,
                                     vpFeatureLine* feature);

/// Approximate: the segment a-b of a line fitted in the distorted image to `*feature`, via
/// UndistortedLineFromDistortedSegment(). Exact when `camera` has no distortion.
void BuildFeatureLineFromDistorted(const Point2d& a, const Point2d& b, const Lens& camera,
                                   vpFeatureLine* feature, int samples = 16);

/// A detector line to `*feature`: the exact path when the detector undistorted its points
/// (`detector_undistorts`, OalDetector::Undistorts()), otherwise the approximate path on the
/// line's end points (image pixels).
void BuildFeatureLine(const DetectedLine& line, bool detector_undistorts, const Lens& camera,
                      vpFeatureLine* feature);

}  // namespace oal
