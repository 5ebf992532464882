// What a servo configuration opens, shared by the servo run and the hand-eye routine: the
// loop's setup (loop/servo_loop.h) from the configuration's sections, the frame source
// (rendered, V4L2 or a recording) and the robot (the simulated camera, or the Scorbot, with
// its controller simulator).
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "app/config.h"
#include "loop/frame_source.h"
#include "loop/servo_loop.h"
#include "robots/robot.h"
#include "robots/scorbot_controller_sim.h"

namespace oal {

/// The loop's setup from the configuration: the camera model the detector and the pose use
/// (the configured lens, or a pinhole camera with the same intrinsics when
/// camera.correct_distortion is false, the paper's condition, or camera.estimate_distortion
/// is set), the target, the options, the goal cdMo (not a taught one: RunServo teaches it),
/// and open loop for a replay.
ServoSetup ServoSetupOf(const ServoAppConfig& config);

/// The robot the configuration names. For the Scorbot with port "simulator", the Controller-A
/// simulator runs on a pseudo-terminal in this process and the real driver talks to it; it is
/// declared before the driver so that it outlives it.
struct RobotRig {
  std::unique_ptr<ScorbotControllerSim> controller;
  std::unique_ptr<Robot> driver;
  /// The controller's own position columns (the Scorbot's X Y Z P R); unset: Table 3's.
  std::function<PoseColumns(const vpHomogeneousMatrix& wMc)> columns;
  bool has_yaw = true;  ///< the columns have a yaw
  /// Appended to a failure to connect: which setting to check ("" when none).
  std::string connect_hint;

  /// The driver and its columns as the loop takes them.
  LoopRobot Loop() const;
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
std::unique_ptr<FrameSource> OpenFrames(const ServoAppConfig& config,
                                        std::vector<std::string>* warnings);

/// "FILE:LINE: key" where the configuration set `key`, or "key" when no file set it.
std::string KeyAt(const ServoAppConfig& config, const std::string& key);

}  // namespace oal
