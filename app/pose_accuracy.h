// The pose's accuracy evaluation (issue 4): rendered four-line frames with distortion and
// noise at random poses, our detector with point undistortion, then EstimatePose; errors
// against the rendered cMo. Deterministic for a given seed.
#pragma once

#include <array>
#include <functional>
#include <string>
#include <vector>

#include "app/accuracy_frames.h"
#include "detector/options.h"
#include "scene/scene.h"
#include "servo/pose.h"

namespace oal {

/// RenderedFrameOptions (the detector evaluation's frames and lens) and the pose sampling.
struct PoseAccuracyOptions : RenderedFrameOptions {
  PoseSampling sampling = DefaultSampling();
  DetectorOptions detector;
  /// EstimatePose's tunables (a config's `pose:`); its camera, lines_undistorted and image
  /// size are ignored: the evaluation sets them from the rendered frames and the detector.
  PoseOptions pose;

  /// Distance 0.3-1.0 m, tilt up to 40 deg, any roll, every line crossing 150 px of image.
  static PoseSampling DefaultSampling() {
    PoseSampling sampling;
    sampling.min_distance_m = 0.3;
    sampling.max_distance_m = 1.0;
    sampling.max_tilt_deg = 40.0;
    sampling.min_visible_length_px = 150.0;
    return sampling;
  }
  /// RenderedFrameOptions::Check(), the detector's and the pose's options (with the camera).
  void Check() const;
};

struct PoseAccuracyReport {
  PoseAccuracyOptions options;
  int frames = 0;
  std::array<int, 4> status_counts{};         ///< by PoseStatus (its numeric value)
  std::vector<double> translation_error_pct;  ///< |t - t_true| / |t_true|, frames with a pose
  std::vector<double> rotation_error_deg;     ///< angle of R R_true^T
  std::vector<double> roll_error_deg;         ///< |roll - roll_true| wrapped to [0, 180]
  int roll_flips = 0;                         ///< frames with a roll error above 45 deg
  std::vector<double> pose_time_us;           ///< EstimatePose alone
  std::vector<double> detect_time_us;
  std::vector<int> failed_frames;  ///< frames without a pose

  int posed() const { return status_counts[0]; }
};

PoseAccuracyReport EvaluatePoseAccuracy(const PoseAccuracyOptions& options,
                                        const std::function<void(int, int)>& progress = {});

}  // namespace oal
