// Pictures of detections for people: the lines drawn over the frame.
#pragma once

#include <visp3/core/vpCameraParameters.h>

#include <opencv2/core/mat.hpp>
#include <optional>
#include <vector>

#include "detector/detector.h"

namespace oal {

/// The visible part of `line` in a width x height frame, as polylines in frame pixels. With
/// `undistorted_by` the line is in undistorted coordinates (OalDetector::Undistorts()) and
/// comes out as the curve it is in the distorted frame: points sampled along the line are
/// mapped back with DistortedPixel (ideal pixel -> metres -> distorted pixel).
std::vector<std::vector<cv::Point2d>> LineInFrame(
    const LineParams& line, int width, int height,
    const std::optional<vpCameraParameters>& undistorted_by);

/// A colour copy of the grey `frame` with `lines` drawn (thickness 2, one colour per line,
/// labelled with their index in `lines`).
cv::Mat AnnotateLines(const cv::Mat& frame, const std::vector<DetectedLine>& lines,
                      const std::optional<vpCameraParameters>& undistorted_by);

}  // namespace oal
