// `oalservo calibrate-accuracy`: camera calibration from the printed line target on rendered
// views of known cameras (fixed seeds): each camera drawn (focal length, principal point off
// centre, lens), its views rendered on the evaluation bench, found as `calibrate` finds them,
// calibrated, and compared with the truth.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "calibration/calibrate.h"
#include "detector/lens.h"
#include "eval/rendered/rendered_frames.h"
#include "scene/bench_scene.h"
#include "servo/target_tracker.h"
#include "target/line_target.h"

namespace oal {

struct CalibrateAccuracyOptions : RenderedFrameOptions {
  LineTarget target = FourLineA3Target();
  int cameras = 5;  ///< cameras drawn, [1, 1000]; RenderedFrameOptions::frames: views of each
  double min_focal_px = 600.0, max_focal_px = 900.0;  ///< px drawn in; py within 1 % of it
  double max_centre_offset_px = 20.0;                 ///< u0, v0 this far from the centre
  double min_kdu = 0.0, max_kdu = 0.35;               ///< the lens drawn in (ViSP's kdu)
  /// Every camera this lens (e.g. OpenCV's model from a camera file) instead of drawn ones,
  /// its views drawn afresh for each; the image size is then the lens's.
  std::optional<Lens> lens;
  /// The views: the camera aimed near the sheet's middle from its near to far distances,
  /// tilted min..max_tilt_deg in any direction, any roll, the crossings in view.
  PoseSampling sampling;
  double min_tilt_deg = 15.0;
  DetectorOptions detector;
  PoseOptions pose;
  TargetTrackerOptions tracking;

  /// Throws std::invalid_argument naming the option and its range.
  void Check() const;
};

/// One camera's calibration against its truth.
struct CameraCalibrationTrial {
  Lens truth, found;
  int views = 0, used = 0;
  double rms_px = 0.0;
  std::string failed;  ///< why the calibration refused (then `found` is unset)
  double px_error_pct() const;
  double py_error_pct() const;
  double u0_error_px() const;
  double v0_error_px() const;
  /// The worst distance between the ideal pixels the found and the true lens give the same
  /// pixel, within kLensJudgedFraction of the way to the image's corners (beyond, the views
  /// rarely reach and the lens is extrapolated), pixels.
  double lens_error_px = 0.0;
};

/// How far towards the image's corners a calibrated lens is judged.
constexpr double kLensJudgedFraction = 0.7;

std::vector<CameraCalibrationTrial> EvaluateCalibration(
    const CalibrateAccuracyOptions& options,
    const std::function<void(int done, int total)>& progress = {});

}  // namespace oal
