// Pictures of detections for people: the lines drawn over the frame.
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>

#include <opencv2/core/mat.hpp>
#include <optional>
#include <vector>

#include "detector/detector.h"
#include "detector/lens.h"
#include "scene/scene.h"
#include "servo/pose.h"

namespace oal {

/// The visible part of `line` in a width x height frame, as polylines in frame pixels. With
/// `undistorted_by` the line is in undistorted coordinates (OalDetector::Undistorts()) and
/// comes out as the curve it is in the distorted frame: points sampled along the line are
/// mapped back with DistortedPixel (ideal pixel -> metres -> distorted pixel).
std::vector<std::vector<cv::Point2d>> LineInFrame(const LineParams& line, int width, int height,
                                                  const std::optional<Lens>& undistorted_by);

/// A colour copy of the grey `frame` with `lines` drawn (thickness 2, one colour per line,
/// labelled with their index in `lines`).
cv::Mat AnnotateLines(const cv::Mat& frame, const std::vector<DetectedLine>& lines,
                      const std::optional<Lens>& undistorted_by);

/// A colour copy of the grey `gray` with the lines the pose identified labelled 1-4, the
/// corners and, when the pose is ok, the target frame's axes (x red, y green, z blue, 5 cm
/// long) projected with `camera`; the pose status top left. `lines` are the lines the pose
/// was estimated from (pose.line_index indexes them).
cv::Mat AnnotatePose(const cv::Mat& gray, const std::vector<DetectedLine>& lines,
                     const PoseResult& pose, const Lens& camera,
                     const std::optional<Lens>& undistorted_by,
                     const std::vector<Point2d>& region = {});

/// Lines 1-4 of `target` where the camera sees them at the goal `cdMo` (through `camera`'s lens),
/// dashed and thin, in the colours AnnotatePose gives them: what the servo loop steers towards.
void DrawGoalLines(cv::Mat* image, const LineTarget& target, const vpHomogeneousMatrix& cdMo,
                   const Lens& camera);

}  // namespace oal
