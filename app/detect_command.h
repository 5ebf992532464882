// `oalservo detect`: the OAL detector over images, a directory, a printf pattern, a video or
// a V4L2 camera, one JSON object per frame (JSON Lines).
//
//   {"frame":0,"source":"x.png","width":640,"height":480,"time_us":312.5,
//    "coordinates":"image","scan":{"mode":"image","region":[]},
//    "lines":[{"rho":..,"theta":..,"votes":..,"count":..,"borders":..,
//    "support":..,"width":..,"end_a":[u,v],"end_b":[u,v]}, ...]}
//
// `frame` is the frame's position in the run, from 0, counted over all inputs in order (not
// the number in the file name, which `compare` and `edge-reference` use: match by `source`,
// the image path or "<video>#<index>"). `coordinates` is "undistorted" when a camera with
// distortion (kdu != 0) was given: the lines are then those an ideal pinhole camera would see
// (detector.h). `scan` is always the paper's scan of the whole image's concentric borders
// (`oalservo pose` writes where it looked for the target in the same key).
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

#include "app/frame_command.h"

namespace oal {

/// FrameCommandOptions: inputs; camera_name from camera_path; out_path (empty: the stream
/// passed to DetectImages()); annotate_dir (lines_0000.png...); max_frames.
struct DetectCommandOptions : FrameCommandOptions {
  /// YAML configuration (config/detector.yaml); empty: none.
  std::string config_path;
  /// Start from DetectorOptions::Paper() instead of the defaults; the config still overrides.
  bool paper = false;
  /// ViSP camera XML; empty: no camera (lines in image coordinates), and camera_name must be
  /// empty too.
  std::string camera_path;

  /// Throws std::invalid_argument naming the field and the violated constraint.
  void Check() const;
};

struct DetectSummary {
  int frames = 0;
  int lines = 0;
  /// For the user (skipped files, camera size mismatch); the caller prints them.
  std::vector<std::string> warnings;
  /// Each frame's straightness_px (frames with at least four lines).
  std::vector<double> straightness_px;
  bool stopped_by_user = false;  ///< a click or a key in the live window (--display)
};

/// Detects lines in every frame of every input. Output goes to options.out_path (atomically:
/// nothing is left there on error) or, without one, to `out`, flushed after each frame.
/// Throws std::runtime_error / std::invalid_argument on bad input or configuration.
DetectSummary DetectImages(const DetectCommandOptions& options, std::ostream& out);

/// `oalservo detect ...`; argv[0] is "detect".
int RunDetect(int argc, char** argv);

}  // namespace oal
