// The servo loop with the camera in the loop: each iteration takes a frame, finds the target's
// pose (servo/target_tracker.h), checks it against the robot's own motion, and commands one
// step of the PBVS law (servo/pbvs.h) through the safety runner, until it converges or a stop
// condition holds; the robot is stopped however it ends. A plain function that tests call
// directly; `oalservo servo` (servo_command.h) wraps it. The iteration's steps, the first
// pose's confirmation, the frame sources and every stop: docs/SERVO_LOOP.md.
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <opencv2/core/mat.hpp>
#include <ostream>
#include <string>
#include <vector>

#include "app/config.h"
#include "detector/detector.h"
#include "robots/safe_robot.h"
#include "servo/pose.h"
#include "servo/target_tracker.h"

namespace oal {

enum class ServoRunStatus {
  kConverged,
  kTargetLost,
  kPoseJump,
  kLimit,
  kIterationLimit,
  kTimeLimit,
  kInterrupted,
  kEndOfInput,
  kError,
};

/// "converged", "target-lost", "pose-jump", "limit", "iteration-limit", "time-limit",
/// "interrupted", "end-of-input", "error".
std::string ToString(ServoRunStatus status);

/// One iteration (one frame): where the camera was when the frame was taken and what the law
/// saw. Table 3's columns: X, Y, Z of the camera in the base frame and pitch, roll, and yaw
/// with wRc = Rx(π)·Rx(pitch)·Ry(yaw)·Rz(roll) (the camera looks down at 0, 0, 0; the config's
/// pose form rxyz_deg [180 + pitch, yaw, roll]): pitch turns about the camera's x axis, yaw
/// about its y axis, roll about its optical axis; the paper's arm has no yaw. For the Scorbot,
/// the controller's own X, Y, Z of the tool centre point and P (the tool axis' angle above the
/// horizontal), R (robots/scorbot_kinematics.h); yaw NaN (5 axes: no independent yaw).
struct ServoIteration {
  int iteration = 0;
  double x_mm = 0, y_mm = 0, z_mm = 0;
  double pitch_deg = 0, roll_deg = 0, yaw_deg = 0;
  /// Error to the goal from the estimated pose (NaN when there is no pose).
  double translation_error_mm = 0, rotation_error_deg = 0;
  /// Error to the goal from the true pose (simulation ground truth).
  double true_translation_error_mm = 0, true_rotation_error_deg = 0;
  /// "running", "converged", the stop status, or "stopped" for the row after the stop
  /// (where the robot stopped; no frame).
  std::string status;
};

struct ServoRunReport {
  ServoRunStatus status = ServoRunStatus::kError;
  vpHomogeneousMatrix cdMo;  ///< the goal used (configured or taught)
  std::string message;       ///< why the run ended, one line for the user
  std::vector<ServoIteration> iterations;
  vpHomogeneousMatrix final_wMc;  ///< the camera where the run left it (read after the stop)
  /// The stop was sent and confirmed at the end (or there was nothing to stop); false when it
  /// could not be sent (the link to the arm lost): the message says so.
  bool robot_stopped = false;
  /// The source and the robot were opened and the loop began (Hooks::on_started was called);
  /// false when the run ended before (the robot could not be connected or enabled).
  bool started = false;
  /// Motion commands the robot began: position moves it was polled in, velocity cycles it
  /// took; not those it refused (the message says so).
  int moves = 0;
  /// For a robot on a serial link (the Scorbot) once connected: what the run cost on it, one
  /// line; else empty.
  std::string link_summary;
};

/// What the loop saw in one iteration, for displays and annotated frames (valid during the
/// on_frame call only).
struct ServoFrame {
  const cv::Mat& gray;  ///< the frame, CV_8UC1
  const std::vector<DetectedLine>& lines;
  const PoseResult& pose;      ///< the last pose estimated (tracked.pose)
  const TargetFrame& tracked;  ///< what the tracker did: status, region scanned
  const ServoIteration& row;
  const vpCameraParameters& camera;  ///< the camera model the detector and pose used
  const LineTarget& target;          ///< the target the loop servos on
  const vpHomogeneousMatrix& cdMo;   ///< the goal: where the lines should end up
  bool lines_undistorted = false;    ///< the lines are in undistorted pixels
};

/// Hooks for the command: `interrupt` is polled every iteration (and on set, the robot's
/// emergency stop is requested); `on_robot` is called with the SafeRobot once it is running
/// and with nullptr before it is destroyed, on every path out of RunServo (an exception
/// too), so a signal handler can reach SafeRobot::RequestEmergencyStop() while it lives.
struct ServoRunHooks {
  const std::atomic<bool>* interrupt = nullptr;
  /// Who asked for the stop, for the message "interrupted by ...", called when the loop sees
  /// an interrupt (e.g. "SIGTERM (a request to terminate)"); unset: "Ctrl-C or a stop from the
  /// window".
  std::function<std::string()> interrupt_reason;
  std::function<void(SafeRobot*)> on_robot;
  /// Called once the frame source is open and the robot connected and enabled, before the
  /// first frame: from here on the run has begun and its outputs describe it.
  std::function<void()> on_started;
  /// Called once per frame, after the pose and the law, before the robot moves.
  std::function<void(const ServoFrame&)> on_frame;
  /// Called with each frame before detection; may change it (tests inject occlusions and a
  /// target leaving the view through it; an emptied frame is one that could not be read). The
  /// frame may be a view of the source's buffer.
  std::function<void(int iteration, cv::Mat* gray)> on_grab;
  /// Tests: called at every poll of a position move of the simulated robot (robot.type
  /// simulated, whose moves take one sampling period per poll), with the iteration that
  /// commanded the move and the poll's number in it (0 first), e.g. to stop it on its way.
  std::function<void(int iteration, int poll)> on_move_poll;
  /// Tests and the fault campaign: wraps the driver the configuration opened (to watch what
  /// it is sent, to make it fail); the loop drives the wrapper in its place.
  std::function<std::unique_ptr<Robot>(std::unique_ptr<Robot>)> wrap_driver;
};

/// The goal of a taught configuration: the pose of config.target estimated in the image
/// config.goal_image with the configured camera and detector. Throws std::runtime_error naming
/// config.goal_image_origin and the image when it cannot be read, has another size than the
/// camera, or shows no pose.
vpHomogeneousMatrix TeachGoal(const ServoAppConfig& config);

/// Checks what the loop needs of a configuration beyond each section's own Check(): a V4L2
/// camera on a real robot, the lens either told or given, true_eMc only for a simulated
/// camera. Throws std::invalid_argument naming the key.
void CheckServoConfig(const ServoAppConfig& config);

/// Runs the loop (see the file comment). Writes one line per iteration to `log`. Throws
/// std::invalid_argument / std::runtime_error for a bad configuration, before the robot moves.
ServoRunReport RunServo(const ServoAppConfig& config, std::ostream& log,
                        const ServoRunHooks& hooks = ServoRunHooks());

/// The Table 3 columns of a camera pose wMc: X, Y, Z (mm), pitch, roll and yaw (deg) with
/// wRc = Rx(π)·Rx(pitch)·Ry(yaw)·Rz(roll) (ServoIteration).
void Table3Columns(const vpHomogeneousMatrix& wMc, double* x_mm, double* y_mm, double* z_mm,
                   double* pitch_deg, double* roll_deg, double* yaw_deg);

/// The report as CSV: a header and one row per iteration.
void WriteServoCsv(const ServoRunReport& report, std::ostream& out);

}  // namespace oal
