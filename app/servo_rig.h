// What a servo configuration opens, shared by the servo loop and the hand-eye routine: the
// camera model and the target tracker, the frame source (rendered, V4L2 or a recording) and
// the robot (the simulated camera, or the Scorbot, with its controller simulator).
#pragma once

#include <visp3/core/vpCameraParameters.h>
#include <visp3/core/vpHomogeneousMatrix.h>

#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <ostream>
#include <string>
#include <vector>

#include "app/config.h"
#include "robots/robot.h"
#include "robots/safe_robot.h"
#include "robots/scorbot_controller_sim.h"
#include "servo/target_tracker.h"

namespace oal {

// What the detector and the pose believe about the lens: the configured one, or a pinhole
// camera with the same intrinsics (the paper's condition, camera.correct_distortion false; or
// camera.estimate_distortion before the stripes have told the lens).
struct LoopModel {
  const ServoAppConfig& config;
  vpCameraParameters camera;

  explicit LoopModel(const ServoAppConfig& c)
      : config(c),
        camera(c.camera.correct_distortion && !c.camera.estimate_distortion
                   ? c.camera.Camera()
                   : vpCameraParameters(c.camera.px, c.camera.py, c.camera.u0, c.camera.v0)) {}

  // The tracker sets the camera, the undistortion and the image size from its own.
  PoseOptions Pose() const {
    PoseOptions options = config.pose;
    options.compute_covariance = false;  // the loop does not use it
    return options;
  }
  TargetPoseTracker Tracker() const {
    return TargetPoseTracker(config.target, camera, config.detector, Pose(), config.tracking);
  }
};

// A robot's position as the log's and servo.csv's columns show it.
struct PoseColumns {
  double x_mm = 0, y_mm = 0, z_mm = 0;
  double pitch_deg = 0, roll_deg = 0, yaw_deg = 0;
};

// Where the loop's frames come from (config `source:`).
class LoopCamera {
 public:
  virtual ~LoopCamera() = default;
  /// The frame of iteration `iteration`: seen from `true_cMo` (simulation) or the next one of
  /// the source; false at the end of a recording. Throws std::runtime_error when a frame cannot
  /// be read.
  virtual bool Grab(const vpHomogeneousMatrix& true_cMo, int iteration, cv::Mat* gray) = 0;
  /// True when a recording has no frame left (the next Grab() would return false); a camera
  /// never ends.
  virtual bool AtEnd() { return false; }
  virtual std::string Name() const = 0;
};

// The robot the configuration names. For the Scorbot with port "simulator", the Controller-A
// simulator runs on a pseudo-terminal in this process and the real driver talks to it; it is
// declared before the driver so that it outlives it.
struct RobotRig {
  std::unique_ptr<ScorbotControllerSim> controller;
  std::unique_ptr<Robot> driver;
  /// Where a camera pose wMc puts the robot, as its controller would say it: the log's and
  /// servo.csv's position columns (ServoIteration). yaw NaN for an arm without a free yaw.
  std::function<PoseColumns(const vpHomogeneousMatrix& wMc)> columns;
  bool has_yaw = true;  ///< the columns have a yaw
  /// Appended to a failure to connect: which setting to check ("" when none).
  std::string connect_hint;
};

/// The Controller-A simulator of a Scorbot configuration (robot.simulator, the arm's geometry
/// and baud rate), its arm started at the joints of the nearest reachable pose to the
/// configured camera start (robot.start through camera.eMc). Throws std::invalid_argument when
/// robot.start is out of the arm's reach.
ScorbotSimOptions ControllerSimOptions(const ServoAppConfig& config);

/// The robot the configuration names (robot.type), not connected. `on_poll`: the simulated
/// camera's per-poll hook (SimulatedCameraOptions::on_poll).
RobotRig OpenConfiguredRobot(const ServoAppConfig& config, std::function<void(int poll)> on_poll);

/// The frame source of `source:`. Files after a printf pattern's gap are reported in
/// `warnings`. Throws std::runtime_error naming the key when it cannot be opened.
std::unique_ptr<LoopCamera> OpenLoopCamera(const ServoAppConfig& config,
                                           std::vector<std::string>* warnings);

/// Where the camera is: the robot's camera pose, or, with camera.true_eMc (a simulation whose
/// camera is not mounted as eMc says), the end effector's pose through true_eMc.
RobotPose TrueCameraPose(SafeRobot& robot, const ServoAppConfig& config);

/// camera.estimate_distortion: the lens from the stripes of the first frames that show the
/// target, the robot still (app/lens_estimate.h); `model` and `tracker` then use it, and `log`
/// gets one line saying what it is. False with `why` when the frames cannot tell it.
bool TellTheLens(const ServoAppConfig& config, SafeRobot& robot, LoopCamera& frames,
                 LoopModel* model, TargetPoseTracker* tracker, std::ostream& log, std::string* why);

/// "FILE:LINE: key" where the configuration set `key`, or "key" when no file set it.
std::string KeyAt(const ServoAppConfig& config, const std::string& key);

}  // namespace oal
