// The servo loop with the camera in the loop (issue 5): each iteration reads the camera pose
// from the robot, renders the frame the simulated camera sees, detects the lines, estimates
// the pose and commands one step of the PBVS law, until it converges or a stop condition
// holds. A plain function that tests call directly; `oalservo servo` (servo_command.h) wraps it.
//
// Frames (docs/ARCHITECTURE.md): w world (robot base), c current camera, o target.
//   wMc   from the robot (SafeRobot over SimulatedCamera);
//   wMo   the target in the world (config `target_pose`), so the true cMo = wMc⁻¹·wMo;
//   cdMo  the goal (config `goal.cdMo`).
//
// One iteration:
//   1. stop (interrupted) if the interrupt flag is set, (time-limit) past servo.max_time_s;
//   2. render the frame from the true cMo (camera intrinsics, kdu, noise and blur from the
//      config), detect (OalDetector with the camera: undistorted lines), EstimatePose seeded
//      by the previous estimate;
//   3. stop (target-lost) when the pose status is not ok;
//   4. stop (pose-jump) when the estimate disagrees with the previous estimate carried by the
//      robot's own motion (odometry: predicted cMo = wMc⁻¹·wMc_prev·cMo_prev) by more than
//      servo.max_pose_jump_m or max_pose_jump_deg;
//   5. ComputeServoStep(estimate, cdMo): converged ends the run (converged); otherwise
//   6. position laws: SafeRobot::MovePosition(camera, wMc·c_T_cnew); velocity law:
//      SafeRobot::SetVelocity(camera, twist) for one sampling period. A refusal ends the run:
//      a workspace, velocity or reach limit (limit), the emergency stop (interrupted), any
//      other failure (error);
//   7. after servo.max_iterations frames without convergence: iteration-limit.
// Whatever the outcome, the robot is stopped when RunServo returns (a guard stops it also on
// an exception).
#pragma once

#include <atomic>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include "app/config.h"
#include "robots/safe_robot.h"

namespace oal {

enum class ServoRunStatus {
  kConverged,
  kTargetLost,
  kPoseJump,
  kLimit,
  kIterationLimit,
  kTimeLimit,
  kInterrupted,
  kError,
};

/// "converged", "target-lost", "pose-jump", "limit", "iteration-limit", "time-limit",
/// "interrupted", "error".
std::string ToString(ServoRunStatus status);

/// One iteration (one frame): where the camera was when the frame was taken and what the law
/// saw. Table 3's columns: X, Y, Z of the camera in the base frame and pitch, roll with
/// wRc = Rx(π)·Rx(pitch)·Rz(roll) (the camera looks down at pitch = roll = 0).
struct ServoIteration {
  int iteration = 0;
  double x_mm = 0, y_mm = 0, z_mm = 0;
  double pitch_deg = 0, roll_deg = 0;
  /// Error to the goal from the estimated pose (NaN when there is no pose).
  double translation_error_mm = 0, rotation_error_deg = 0;
  /// Error to the goal from the true pose (simulation ground truth).
  double true_translation_error_mm = 0, true_rotation_error_deg = 0;
  std::string status;  ///< "running", "converged", or the stop status
};

struct ServoRunReport {
  ServoRunStatus status = ServoRunStatus::kError;
  std::string message;  ///< why the run ended, one line for the user
  std::vector<ServoIteration> iterations;
  vpHomogeneousMatrix final_wMc;  ///< the camera where the run left it
  bool robot_stopped = false;     ///< the robot was stopped at the end (always true)
  int moves = 0;                  ///< motion commands sent
};

/// Hooks for the command: `interrupt` is polled every iteration (and on set, the robot's
/// emergency stop is requested); `on_robot` is called with the SafeRobot once it is running
/// and with nullptr before it is destroyed, so a signal handler can reach
/// SafeRobot::RequestEmergencyStop().
struct ServoRunHooks {
  const std::atomic<bool>* interrupt = nullptr;
  std::function<void(SafeRobot*)> on_robot;
};

/// Runs the loop (see the file comment). Writes one line per iteration to `log`. Throws
/// std::invalid_argument / std::runtime_error for a bad configuration, before the robot moves.
ServoRunReport RunServo(const ServoAppConfig& config, std::ostream& log,
                        const ServoRunHooks& hooks = ServoRunHooks());

/// The Table 3 columns of a camera pose wMc: X, Y, Z (mm), pitch, roll (deg).
void Table3Columns(const vpHomogeneousMatrix& wMc, double* x_mm, double* y_mm, double* z_mm,
                   double* pitch_deg, double* roll_deg);

/// The report as CSV: a header and one row per iteration.
void WriteServoCsv(const ServoRunReport& report, std::ostream& out);

}  // namespace oal
