// The detector's accuracy evaluation: rendered frames with ground truth, our detector with
// and without point undistortion, the paper's algorithm, and OpenCV's HoughLines, on the
// same frames. Deterministic for a given seed.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "detector/options.h"
#include "eval/rendered/rendered_frames.h"
#include "scene/scene.h"
#include "servo/pose.h"
#include "servo/target_tracker.h"

namespace oal {

/// RenderedFrameOptions (frames, seed, camera, degradations) and what this evaluation adds.
struct AccuracyOptions : RenderedFrameOptions {
  LineTarget target = FourLineTarget();
  /// A target line fails when its best match among the first N detected lines (N = number
  /// of target lines) is further than either bound.
  double max_angle_deg = 1.0;
  double max_offset_px = 2.0;
  PoseSampling sampling = DefaultSampling();
  DetectorOptions detector;
  /// A '#' target is also found by the target tracker (servo/target_tracker.h, a config's
  /// `tracking:`), each frame on its own: the lines of the borders it scanned on the target.
  TargetTrackerOptions tracking;

  static PoseSampling DefaultSampling() {
    PoseSampling sampling;
    sampling.min_distance_m = 0.4;
    sampling.max_distance_m = 0.9;
    sampling.max_tilt_deg = 30.0;
    sampling.min_visible_length_px = 150.0;
    return sampling;
  }
  void Check() const;
};

/// What one method did over all frames.
struct MethodAccuracy {
  std::string name;
  std::string reference;  ///< "ideal" (undistorted truth) or "distorted fit"
  int frames = 0;
  int failed_frames = 0;
  std::vector<double> angle_error_deg;  ///< per target line, best match
  std::vector<double> offset_error_px;
  std::vector<double> time_us;  ///< per frame
  std::vector<int> failed_frame_indices;

  double FailureRate() const { return frames ? static_cast<double>(failed_frames) / frames : 0.0; }
};

struct AccuracyReport {
  AccuracyOptions options;
  std::vector<MethodAccuracy> methods;
};

/// Runs the evaluation; `progress(done, total)` is called after each frame if set.
AccuracyReport EvaluateDetectorAccuracy(const AccuracyOptions& options,
                                        const std::function<void(int, int)>& progress = {});

}  // namespace oal
