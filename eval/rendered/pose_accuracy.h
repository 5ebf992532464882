// The pose's accuracy evaluation: rendered frames of a four-line target (by default the A3
// sheet on photographs of a bench) at random poses, each found on its own by the target
// tracker (servo/target_tracker.h: the sheet's middle cell, borders on its plane, the checks),
// errors against the rendered cMo. Deterministic for a given seed. Or, on the same frames, a
// marker users would print on the sheet instead (eval/rendered/marker_method.h: an AprilTag, a
// ChArUco board) and its own detection and pose.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "detector/options.h"
#include "eval/rendered/marker_method.h"
#include "eval/rendered/rendered_frames.h"
#include "loop/lens_estimate.h"  // kLensFrames
#include "scene/bench_scene.h"   // SheetSampling
#include "scene/scene.h"
#include "servo/pose.h"
#include "servo/target_tracker.h"

namespace oal {

/// RenderedFrameOptions (frames, lens, degradations, surface) and what the pose needs.
struct PoseAccuracyOptions : RenderedFrameOptions {
  LineTarget target = FourLineA3Target();
  PoseSampling sampling = SheetSampling(FourLineA3Target());
  DetectorOptions detector;
  /// EstimatePose's tunables (a config's `pose:`); its camera, lines_undistorted and image
  /// size are ignored: the evaluation sets them from the rendered frames and the detector.
  PoseOptions pose;
  TargetTrackerOptions tracking;  ///< a config's `tracking:`
  /// A pose off by more than either is wrong (and counted apart), % of the distance and deg.
  double wrong_translation_pct = 2.0;
  double wrong_rotation_deg = 2.0;
  /// A target line is found when one of the frame's lines is within both of its truth.
  double line_angle_deg = 1.0;
  double line_offset_px = 2.0;
  /// The tracker is not told the lens: kdu is estimated from the target's stripes in the first
  /// `estimate_frames` frames (of poses drawn apart from the evaluated ones) a pinhole tracker
  /// finds it in, then used for every frame (loop/lens_estimate.h).
  bool estimate_distortion = false;
  int estimate_frames = kLensFrames;  ///< Range [1, 100].
  /// The lens the tracker (or the marker's method) is told instead of the rendered one: a
  /// calibration's result, to measure what it costs. Unset: the rendered lens. Not with
  /// estimate_distortion.
  std::optional<Lens> given_camera;
  /// What the sheet carries: our stripes, or a marker printed instead (kAprilTag, kCharuco),
  /// posed by its own method on the same frames: the same poses (drawn for `target`, its
  /// crossings in view), bench, lived-in effects and noise, the frame rendered with `target`'s
  /// board carrying the marker instead of the stripes (MarkerSheet). A marker's method is given
  /// the rendered camera, lens included (estimate_distortion is for our stripes only); the
  /// detector, pose and tracking options are ours and do not apply to it.
  SheetMarker marker = SheetMarker::kOal;

  /// The paper's board (its first evaluation): 0.3-1.0 m, tilt up to 40 deg, any roll, every
  /// line crossing 150 px of the image.
  static PoseSampling BoardSampling();
  /// RenderedFrameOptions::Check(), the detector's, the pose's (with the camera) and the
  /// tracking's options; no estimate_distortion with a marker.
  void Check() const;
};

/// With a marker, the fields of our tracker (pose_status_counts, source_counts, lines_found,
/// find_time_us, the estimated lens) stay empty.
struct PoseAccuracyReport {
  PoseAccuracyOptions options;
  int frames = 0;
  /// By TargetStatus ("ok", "not-found", ...); with a marker, by MarkerStatus ("ok",
  /// "not-found", "no-pose").
  std::map<std::string, int> status_counts;
  std::map<std::string, int> pose_status_counts;  ///< of the frames without a pose, by PoseStatus
  std::map<std::string, int> source_counts;       ///< of the frames with a pose, by ScanSource
  std::vector<double> translation_error_pct;      ///< |t - t_true| / |t_true|, frames with a pose
  std::vector<double> rotation_error_deg;         ///< angle of R R_true^T
  std::vector<double> roll_error_deg;             ///< |roll - roll_true| wrapped to [0, 180]
  int roll_flips = 0;                             ///< frames with a roll error above 45 deg
  std::vector<int> wrong_frames;                  ///< poses off by more than the wrong_ bounds
  int lines_found = 0;  ///< frames whose four target lines were all found (line_ bounds)
  std::vector<double> find_time_us, detect_time_us, pose_time_us, total_time_us;
  std::vector<int> failed_frames;  ///< frames without a pose
  /// With estimate_distortion: the lens told from the stripes (NaN when it could not be), kdu's
  /// standard deviation, and why not.
  double estimated_kdu = 0.0, estimated_kdu_sd = 0.0;
  std::string estimate_failed;
  /// With a marker: what was printed (MarkerPrint::description), the frames that show all of
  /// its outline, and of those the frames with a pose (the poses are drawn for our target's
  /// crossings: a large marker is partly out of the nearest views).
  std::string marker_description;
  int marker_in_view = 0;
  int posed_in_view = 0;

  int posed() const;
};

/// A frame counted against the tracker, as it was rendered: without a pose, or with a wrong one.
struct PoseAccuracyMiss {
  int frame = 0;
  const RenderedFrame& rendered;
  const RenderOptions& render;  ///< the scene it was rendered with (camera, size, surface)
  std::uint64_t noise_seed = 0;
  FrameEffects effects;
  const TargetFrame& result;  ///< what the tracker made of it
  bool wrong = false;         ///< a pose was given and is wrong; else none was
  double translation_error_pct = 0.0, rotation_error_deg = 0.0;  ///< of a wrong pose
};

/// `on_miss` sees each frame without a pose or with a wrong one, to keep it for a replay (our
/// target's frames only: a marker's are not kept).
PoseAccuracyReport EvaluatePoseAccuracy(
    const PoseAccuracyOptions& options, const std::function<void(int, int)>& progress = {},
    const std::function<void(const PoseAccuracyMiss&)>& on_miss = {});

}  // namespace oal
