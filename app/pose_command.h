// `oalservo pose`: the camera pose from the four-line target (servo/pose.h) in every frame of
// the same inputs as `oalservo detect`, found by the target tracker (servo/target_tracker.h),
// one JSON object per frame (JSON Lines):
//
//   {"frame":0,"source":"x.png","width":640,"height":480,"status":"ok","message":"",
//    "pose_status":"ok","cMo":{"matrix":[[...],...],"t_m":[x,y,z],"thetau_rad":[tux,tuy,tuz]},
//    "roll_deg":..,"pitch_deg":..,"yaw_deg":..,"line1_roll_deg":..,
//    "plane_angles_deg":[a1,a2],"residual_px":..,"covariance":[[..6..],..6 rows..],
//    "method":"homography","from_previous":false,
//    "lines":[i1,i2,i3,i4],"coordinates":"image","corners_px":[[u,v],[u,v],[u,v],[u,v]],
//    "scan":{"mode":"target","source":"middle-cell","borders":16,"candidates":1,
//            "region":[[u,v],...]},
//    "stripe_agreement":..,"straightness_px":..,
//    "lens":{"kdu_error":..,"kdu_error_sd":..,"lines":4,"contradicts_camera":false},
//    "time_us":{"find":..,"detect":..,"pose":..}}
//
// status is TargetStatus's ToString() ("ok", "not-found", "model-mismatch", "jump") and
// message its reason ("" when ok); pose_status is the last estimate's PoseStatus ("ok",
// "not-enough-lines", "not-identifiable", "degenerate"). Every object has every key: cMo,
// roll_deg ... from_previous (covariance included) are null unless the status is ok;
// lines[k] is the index, in the detector's lines of that frame, of target line k + 1 (-1 when
// not identified); corners_px (corner k = line k+1 ∩ line k+2, in `coordinates`:
// "undistorted" when the detector corrects distortion, else "image") is null until the lines
// are identified. Angles are PoseResult's. scan says where the target was looked for
// (ScanJson, io/json_io.h: mode "target" or "image"; source "prior", "middle-cell", "image"
// or "none"; region the outermost border scanned, empty for the whole image);
// stripe_agreement is the model check's worst fraction over lines 1-4 (null when no pose was
// estimated). straightness_px and lens are the lens check (TargetFrame::lens): how far lines
// 1-4 still bend after the camera file's correction, and the camera's kdu less the lens's that
// the bend shows, with its standard deviation, the lines that told it and whether the frame
// contradicts the camera file (ContradictsLens); null unless ok, lens also when the lines
// cannot tell (all near the principal point). Over the run, most frames contradicting the
// file gives a warning.
//
// The pose needs the camera's intrinsics: --camera FILE, or, without it, the camera.xml that
// `oalservo render` writes next to the frames (the directory of the first input), which is
// then used with a warning saying so. Without either the command fails before any output.
// Within one input the last accepted pose is the tracker's prior for the next frame (the
// borders it scans, the lines it seeds, the jump check; so a sequence does not flip between
// the two poses of a planar target); with `independent` every frame is found on its own.
#pragma once

#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "app/frame_command.h"
#include "detector/line_fit.h"
#include "loop/lens_estimate.h"  // kLensFrames

namespace oal {

/// FrameCommandOptions: inputs; camera_name from the camera file; out_path (empty: the
/// stream passed to EstimatePoses()); annotate_dir (pose_0000.png...); max_frames.
struct PoseCommandOptions : FrameCommandOptions {
  /// YAML configuration: `detector:`, `target:`, `pose:` and `tracking:` sections
  /// (config/detector.yaml, config/four-line-a3.yaml, config/pose.yaml); empty: the
  /// target.yaml `oalservo render` writes next to the frames, else the defaults (the A3 sheet).
  std::string config_path;
  /// ViSP camera XML; empty: camera.xml in the first input's directory, else an error.
  std::string camera_path;
  /// Each frame on its own (e.g. a rendered data set of random poses); false: the frames of
  /// one input are a sequence, the target followed from one to the next.
  bool independent = false;
  /// The camera file has no distortion: kdu is estimated from the target's stripes in the
  /// first `estimate_frames` frames with a pose (read ahead and then processed as all others,
  /// calibration/plumb_line.h) and used for every frame.
  bool estimate_distortion = false;
  int estimate_frames = kLensFrames;  ///< Range [1, 100].

  /// Throws std::invalid_argument naming the field and the violated constraint.
  void Check() const;
};

struct PoseSummary {
  int frames = 0;
  int ok = 0;  ///< frames with status ok
  /// The camera file used (--camera, or the camera.xml found next to the inputs).
  std::string camera_path;
  /// For the user (camera found automatically, skipped files, camera size mismatch, a camera
  /// file whose lens model leaves the stripes bent).
  std::vector<std::string> warnings;
  /// What was done for the user (the lens estimated).
  std::vector<std::string> notes;
  bool stopped_by_user = false;  ///< a click or a key in the live window (--display)
  /// kdu told from the stripes (--estimate-distortion), when it was.
  std::optional<double> estimated_kdu;
  /// TargetFrame::lens of the frames with a pose, in order.
  std::vector<RadialBend> lens;
};

/// Estimates the pose in every frame of every input. Output goes to options.out_path
/// (atomically: nothing is left there on error) or, without one, to `out`, flushed after each
/// frame. A frame without a pose is a row with its status, not an error. Throws
/// std::runtime_error / std::invalid_argument on bad input or configuration, or when no
/// camera is given or found ("pose needs the camera intrinsics: give --camera FILE").
PoseSummary EstimatePoses(const PoseCommandOptions& options, std::ostream& out);

/// `oalservo pose ...`; argv[0] is "pose".
int RunPose(int argc, char** argv);

}  // namespace oal
