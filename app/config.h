// oalservo's YAML configuration. Only the app reads YAML: this file fills the libraries'
// Options structs and rejects what it does not understand, naming the file, the line and
// the key (config/detector.yaml documents every key).
//
//   detector:            # oal::DetectorOptions; keys are exactly its field names
//     paper: true        # start from DetectorOptions::Paper() instead of the defaults
//     step_px: 5
//
//   target: {name: four-line-a3}   # a shipped target (scene/scene.h TargetNames), or in full:
//   target:              # oal::LineTarget (config/four-line-board.yaml documents the keys)
//     name: my-board     # required
//     board_width_m: 0.4 # required, > 0; the board is centred on the object origin
//     board_height_m: 0.3
//     board_grey: 215    # optional, [0, 255]
//     line_grey: 35      # optional, [0, 255]
//     lines:             # required, may be empty; metres on the board plane (x right, y down)
//       - {from: [-0.08, -0.15], to: [-0.08, 0.15], width: 0.03}
//
// A target section replaces the whole target (it never modifies the base's target).
//
//   pose:                # oal::PoseOptions' tunables (config/pose.yaml documents the keys);
//     max_residual_px: 2.0   # the camera, lines_undistorted and the image size come from the
//                            # command (--camera, the detector, the frame), not from here
//
//   tracking: {scan: image}  # oal::TargetTrackerOptions (config/pose.yaml documents the keys)
//   scene:                   # SceneOptions: what a rendered camera sees around the target
//     background: bench.png  # (config/servo-sim.yaml, config/scene-dark-table.yaml)
//
// The servo app's sections (config/servo-sim.yaml documents every key):
//
//   camera:   px, py, u0, v0, kdu, width, height, noise, blur, eMc    (CameraConfig)
//   robot:    type: simulated | scorbot, start (wMc), velocity limits, workspace box,
//             scorbot: {port, baud, ..., geometry, simulator} (RobotConfig)
//   servo:    the law (ServoOptions) and the loop's limits             (ServoLoopOptions)
//   goal:     cdMo, the target as the camera should see it at the goal, or image: a taught goal
//   target_pose: wMo, the target's pose in the world (robot base) frame
//   source:   simulated (rendered), v4l2 (device, format, width, height, fps) or replay (path)
//   output:   directory, display (auto/on/off), save_frames               (OutputConfig)
//
// A pose is a map {translation_m: [x, y, z], rxyz_deg: [rx, ry, rz]} with the rotation
// R = Rx(rx)·Ry(ry)·Rz(rz) (vpRxyzVector); both keys are required.
//
// A configured robot.start (simulated robot, or the Scorbot's controller simulator) must lie
// inside the workspace box (robot.workspace_min_m / workspace_max_m) when the box is enabled.
//
// The section reserved for later versions (render) is rejected with a message saying so,
// rather than silently ignored.
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>

#include <map>
#include <optional>
#include <string>

#include "detector/lens.h"
#include "detector/options.h"
#include "io/scene_options.h"
#include "io/v4l2_modes.h"
#include "loop/servo_loop.h"
#include "robots/safe_robot.h"
#include "robots/scorbot_controller_sim.h"
#include "robots/scorbot_robot.h"
#include "scene/scene.h"
#include "servo/pbvs.h"
#include "servo/pose.h"
#include "servo/target_tracker.h"

namespace oal {

/// `camera:` the simulated (or real) camera: intrinsics, kdu distortion, image size, and the
/// rendering's noise and blur.
struct CameraConfig {
  double px = 600.0, py = 600.0;  ///< focal lengths, pixels, > 0
  double u0 = 319.5, v0 = 239.5;  ///< principal point, pixels, finite
  double kdu = 0.0;               ///< ViSP's distorted -> undistorted coefficient; 0: none
  /// `camera.distortion`: OpenCV's coefficients [k1, k2, p1, p2, k3(, k4, k5, k6)] (the
  /// other lens model; all zero: none). Not together with kdu.
  Distortion distortion;
  /// Undistort the feature points with the lens (detector) and use it in the pose; false ignores
  /// the lens in both (the paper's condition: its lines stay curved).
  bool correct_distortion = true;
  /// Tell the lens from the target's stripes over the first frames, the robot still, instead
  /// of from kdu (calibration/plumb_line.h); in a simulation kdu is then the rendered lens
  /// only, which the loop does not see.
  bool estimate_distortion = false;
  int width = 640, height = 480;  ///< image size, pixels, [16, 8192]
  double noise = 0.0;             ///< Gaussian noise of the rendering, grey levels, [0, 100]
  double blur = 0.0;              ///< Gaussian blur of the rendering, pixels, [0, 20]
  /// The simulated camera's exposure: its own motion blurs each frame over it, s, [0, 1].
  double exposure_s = 0.0;
  /// The simulated camera delivers a frame this long after it took it, s, [0, 1].
  double latency_s = 0.0;
  vpHomogeneousMatrix eMc;  ///< hand-eye: the camera in the end-effector frame
  /// Simulation (source: simulated): how the rendered camera is really mounted, when eMc is
  /// only what the loop believes (to try a hand-eye calibration); unset: eMc.
  std::optional<vpHomogeneousMatrix> true_eMc;
  /// `camera.file`: a camera file (ViSP's XML, OpenCV's calibration YAML or ROS's camera_info,
  /// io/camera_file.h) that gives px, py, u0, v0, the lens's distortion and, when it has
  /// them, width and height; empty: the inline keys. Relative to the config file.
  std::string file;
  /// `camera.name`: the camera to read from `file` (empty: its first).
  std::string file_camera;

  /// The lens: OpenCV's model when `distortion` is set, ViSP's when kdu != 0, else the pinhole.
  Lens Camera() const;
  /// Throws std::invalid_argument naming the field, its value and the violated constraint.
  void Check() const;
};

/// `robot.type`: a free-flying camera (vpSimulatorCamera), or the Scorbot ER-VII over RS-232 in
/// ACL (robot.scorbot.port "simulator" runs the Controller-A simulator on a pseudo-terminal in
/// the process).
enum class RobotType { kSimulated, kScorbot };
/// `source.type`: the target rendered from the robot's camera pose every iteration (closed
/// loop, the default); a real camera on the robot (vpV4l2Grabber), closed loop; a video, image
/// directory, printf pattern or /dev/videoN replayed open loop (the law's commands computed and
/// logged, the robot not moved).
enum class SourceType { kSimulated, kV4l2, kReplay };
/// `output.display`: a vpDisplayX window when $DISPLAY is set; a window or an error; none.
enum class DisplayMode { kAuto, kOn, kOff };

/// The one place these meet the configuration's words: "simulated", "scorbot"; "simulated",
/// "v4l2", "replay"; "auto", "on", "off".
std::string ToString(RobotType type);
std::string ToString(SourceType type);
std::string ToString(DisplayMode mode);
/// The word's value; nullopt for a word that is none of them.
std::optional<RobotType> RobotTypeFromString(const std::string& word);
std::optional<SourceType> SourceTypeFromString(const std::string& word);
std::optional<DisplayMode> DisplayModeFromString(const std::string& word);

/// `robot:` which robot, where it starts, and the runner's safety limits.
struct RobotConfig {
  RobotType type = RobotType::kSimulated;
  /// Start pose of the camera in the world: the simulated robot's, or the Scorbot
  /// simulator's (nearest reachable); a real arm starts where it stands.
  vpHomogeneousMatrix start_wMc;
  double sampling_time_s = 0.04;  ///< one velocity command / move poll, s, (0, 1] (simulated)
  SafetyOptions safety;           ///< velocity limits, workspace box, reach tolerances
  ScorbotOptions scorbot;         ///< `robot.scorbot:` (its eMc comes from camera.eMc)
  ScorbotSimOptions simulator;    ///< `robot.scorbot.simulator:` (port: simulator)

  /// Throws std::invalid_argument naming the field, its value and the violated constraint.
  void Check() const;
};

/// `source:` where the servo loop's frames come from.
struct SourceConfig {
  SourceType type = SourceType::kSimulated;
  std::string device = "/dev/video0";  ///< v4l2: the device
  /// v4l2: the pixel format (auto: YUYV where it gives the size and rate, else MJPEG), the
  /// size (0: camera.width/height) and the rate (0: the highest of the mode): one of the
  /// modes `oalservo cameras` lists (io/v4l2_modes.h).
  CameraFormat format = CameraFormat::kAuto;
  int width = 0, height = 0;
  int fps = 0;  ///< Range [0, 1000].
  /// replay: what to play (io/image_source.h); relative paths are relative to the config file.
  std::string path;

  /// Throws std::invalid_argument naming the field, its value and the violated constraint.
  void Check() const;
};

/// `output:` what the servo command writes and shows.
struct OutputConfig {
  /// servo.csv, servo-error.png and frames/ go here (relative to the working directory);
  /// `oalservo servo --out DIR` overrides it. Empty: write nothing.
  std::string directory = "out/servo";
  DisplayMode display = DisplayMode::kAuto;
  /// Without a window, write each iteration's annotated frame to DIR/frames/iter_NNNN.png.
  bool save_frames = true;

  /// Throws std::invalid_argument naming the field, its value and the violated constraint.
  void Check() const;
};

/// Everything a configuration file can set. A new section is a member here plus one row in
/// config.cpp's section table.
struct AppConfig {
  DetectorOptions detector;
  /// The planar target (pose, render, servo, `oalservo target`): the A3 sheet by default.
  LineTarget target = FourLineA3Target();
  PoseOptions pose;  ///< `pose:`; its camera, lines_undistorted and image size stay as given
  /// `tracking:` where the target is looked for in each frame (servo/target_tracker.h).
  TargetTrackerOptions tracking;
  SceneOptions scene;      ///< `scene:`
  CameraConfig camera;     ///< `camera:`
  RobotConfig robot;       ///< `robot:`
  ServoLoopOptions servo;  ///< `servo:` (loop/servo_loop.h)
  /// `goal: {cdMo: POSE}`: the target in the goal camera frame (default 0.5 m ahead).
  vpHomogeneousMatrix goal_cdMo = vpHomogeneousMatrix(0.0, 0.0, 0.5, 0.0, 0.0, 0.0);
  /// `goal: {image: FILE}`: a taught goal, the pose seen in this image (relative to the config
  /// file); replaces goal_cdMo when the loop starts (TeachGoal in app/servo_run.h). Empty: none.
  std::string goal_image;
  std::string goal_image_origin;  ///< "FILE:LINE" of goal.image, for messages
  SourceConfig source;            ///< `source:`
  OutputConfig output;            ///< `output:`
  /// `target_pose: POSE`: wMo, the target in the world frame.
  vpHomogeneousMatrix target_wMo;
  /// Where each key was last set: "FILE:LINE" by full key ("robot.start", "source.path",
  /// "robot.scorbot.port"), for messages about values used after loading; a key no file
  /// set is absent.
  std::map<std::string, std::string> origins;

  /// origins[key], or "" when no file set it.
  std::string Origin(const std::string& key) const;
};

/// The servo command reads the same file: all sections live in AppConfig.
using ServoAppConfig = AppConfig;

/// Applies the YAML file at `path` to `base` and checks the result. Throws
/// std::runtime_error "FILE:LINE: ..." for a missing or malformed file, an unknown section
/// or key, a value of the wrong type, and a value that fails the Options' Check().
AppConfig LoadConfig(const std::string& path, const AppConfig& base = AppConfig());

/// `target` as a configuration's `target:` section (LoadConfig reads it back exactly: numbers
/// with 17 significant digits).
std::string TargetYaml(const LineTarget& target);

/// `pose` in the configuration's form, {translation_m: [x, y, z], rxyz_deg: [rx, ry, rz]},
/// with 12 significant digits (LoadConfig reads it back to far below a micrometre).
std::string PoseYaml(const vpHomogeneousMatrix& pose);

/// As LoadConfig, from YAML text; `file_name` stands for the file in messages.
AppConfig ParseConfig(const std::string& yaml_text, const std::string& file_name,
                      const AppConfig& base = AppConfig());

}  // namespace oal
