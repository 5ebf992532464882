// The servo loop with the camera in the loop: each iteration takes a frame, finds the target's
// pose (servo/target_tracker.h), checks it against the robot's own motion, and commands one
// step of the PBVS law (servo/pbvs.h) through the safety runner, until it converges or a stop
// condition holds; the robot is stopped however it ends. It takes plain values (ServoSetup),
// a FrameSource and the robot (LoopRobot); `oalservo servo` builds them from its
// configuration (app/servo_run.h). The iteration's steps, the first pose's confirmation, the
// frame sources and every stop: docs/SERVO_LOOP.md.
#pragma once

#include <visp3/core/vpHomogeneousMatrix.h>

#include <atomic>
#include <functional>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "base/field_names.h"
#include "detector/detector.h"
#include "detector/lens.h"
#include "loop/frame_source.h"
#include "robots/robot.h"
#include "robots/safe_robot.h"
#include "servo/pbvs.h"
#include "servo/pose.h"
#include "servo/target_tracker.h"
#include "target/line_target.h"

namespace oal {

/// The law and the loop's stop conditions (a configuration's `servo:` section).
struct ServoLoopOptions {
  ServoOptions law;
  /// Frames processed before iteration-limit, not counting those the loop held at or skipped,
  /// [0, 1e6]; 0: the law's own (IterationLimit).
  int max_iterations = 0;
  double max_time_s = 60.0;        ///< wall time before time-limit, s, > 0
  double max_pose_jump_m = 0.05;   ///< estimate vs odometry prediction, m, > 0
  double max_pose_jump_deg = 5.0;  ///< ... and degrees, (0, 180]
  /// The largest position move (point-and-go, exponential) the loop commands: a larger step
  /// stops the run (limit) before the robot moves. m, > 0.
  double max_step_m = 0.5;
  double max_step_deg = 60.0;  ///< ... and degrees, (0, 180]
  /// A frame without a pose, or whose pose disagrees with the robot's motion, holds the robot
  /// (nothing more is commanded; a velocity law commands zero) while the loop keeps looking;
  /// it carries on once a pose is found and confirmed again (two frames, the robot still,
  /// agreeing with each other and with where the motion puts the target). The run stops
  /// after holding this long: seconds on the wall clock, [0, 3600], or frames, [0, 1e6],
  /// whichever comes first (0 frames: the first such frame stops it).
  double max_lost_s = 2.0;
  int max_lost_frames = 60;

  /// The iteration limit in force: max_iterations when set; else none for a replay (it runs
  /// to its end), 300 frames for the velocity law (its error falls by e in 1/gain s: from
  /// 0.1 m to 1 mm takes about 120 periods of 40 ms at gain 1/s) and 30 for the position
  /// laws (a few moves, each two frames).
  int IterationLimit(bool replay) const;

  /// Throws std::invalid_argument naming the field, its value and the violated constraint.
  void Check() const;
};

/// Everything the loop runs with, as values.
struct ServoSetup {
  LineTarget target;
  /// The camera model the detector and the pose use (a pinhole camera, px, py, u0, v0 only,
  /// when estimate_distortion is set or the lens is not to be corrected), and the size its
  /// frames must have.
  Lens camera;
  int width = 640, height = 480;
  /// Tell the lens from the target's stripes over the first frames, the robot still, and use
  /// it from then on (loop/lens_estimate.h); `camera` must then be a pinhole camera.
  bool estimate_distortion = false;
  DetectorOptions detector;
  PoseOptions pose;  ///< its camera and image size are the setup's
  TargetTrackerOptions tracking;
  ServoLoopOptions loop;
  SafetyOptions safety;      ///< the safety runner's limits (robots/safe_robot.h)
  vpHomogeneousMatrix wMo;   ///< the target in the world (robot base) frame
  vpHomogeneousMatrix cdMo;  ///< the goal: the target in the goal camera frame
  /// A taught goal instead of cdMo: the target's pose in this frame (of the camera's size),
  /// found with the setup's camera and tracker before anything moves; `goal_image_name` names
  /// it in messages.
  cv::Mat goal_image;
  std::string goal_image_name;
  /// Open loop: the law's commands are computed and logged, the robot never moves (a
  /// recording replayed).
  bool open_loop = false;
  /// A simulation's camera as it is really mounted on the end effector, when the robot's
  /// eMc is only what the loop believes (TrueCameraPose); unset: the robot's camera pose.
  std::optional<vpHomogeneousMatrix> true_eMc;
  /// How the caller's user names the setup's fields in the loop's messages: "width",
  /// "height", "estimate_distortion", "latency_s" (the frame source's), "loop.max_step_m",
  /// "loop.law.delta", "safety.workspace_min_m", ... (a path from here), and "calibrate" (how
  /// the user calibrates a camera); each unnamed one keeps its own name.
  FieldNames names;
};

/// The target tracker the setup describes (TargetPoseTracker with its camera, detector, pose
/// and tracking options; no covariance, which the loop does not use).
TargetPoseTracker MakeTracker(const ServoSetup& setup);

/// The pose of the target in `gray` (of the setup's size) with the setup's camera and tracker.
/// Throws std::runtime_error starting with `where` when the frame has another size or shows
/// no pose.
vpHomogeneousMatrix TeachGoal(const ServoSetup& setup, const cv::Mat& gray,
                              const std::string& where);

/// A robot's position as the log's and servo.csv's columns show it.
struct PoseColumns {
  double x_mm = 0, y_mm = 0, z_mm = 0;
  double pitch_deg = 0, roll_deg = 0, yaw_deg = 0;
};

/// The robot the loop drives, opened (not connected) by the caller, and how its positions are
/// shown.
struct LoopRobot {
  /// A robot shown with Table 3's columns (a Robot converts: RunServoLoop(setup, frames,
  /// robot, log)).
  LoopRobot(Robot& robot) : driver(&robot) {}  // NOLINT(google-explicit-constructor)

  Robot* driver;  ///< not owned; outlives the run
  /// Where a camera pose wMc puts the robot, as its controller would say it (the table's
  /// position columns); unset: Table3Columns. yaw NaN for an arm without a free yaw.
  std::function<PoseColumns(const vpHomogeneousMatrix& wMc)> columns;
  bool has_yaw = true;       ///< the columns have a yaw
  std::string connect_hint;  ///< appended to a failure to connect: which setting to check
};

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
/// with wRc = Rx(π)·Rx(pitch)·Ry(yaw)·Rz(roll) (the camera looks down at 0, 0, 0; a
/// configuration's pose form rxyz_deg [180 + pitch, yaw, roll]): pitch turns about the
/// camera's x axis, yaw about its y axis, roll about its optical axis; the paper's arm has no
/// yaw. For the Scorbot, the controller's own X, Y, Z of the tool centre point and P (the tool
/// axis' angle above the horizontal), R (robots/scorbot_kinematics.h); yaw NaN (5 axes: no
/// independent yaw).
struct ServoIteration {
  int iteration = 0;
  double x_mm = 0, y_mm = 0, z_mm = 0;
  double pitch_deg = 0, roll_deg = 0, yaw_deg = 0;
  /// Error to the goal from the estimated pose (NaN when there is no pose).
  double translation_error_mm = 0, rotation_error_deg = 0;
  /// Error to the goal from the true pose (simulation ground truth).
  double true_translation_error_mm = 0, true_rotation_error_deg = 0;
  /// "running", "converged", "held" (nothing commanded: `held` says why), "found" (a pose
  /// to be confirmed by the next frame, nothing commanded), "skipped" (a late frame taken
  /// before the last position move ended: not looked at), the stop status, or "stopped" for
  /// the row after the stop (where the robot stopped; no frame).
  std::string status;
  /// Why the loop held at (or skipped) this frame, in the user's words (else empty).
  std::string held;
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
  /// Times the loop held (nothing commanded until a pose was found and confirmed again), and
  /// the frames it held at in all.
  int holds = 0;
  int held_frames = 0;
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
  const Lens& camera;               ///< the camera model the detector and pose used
  const LineTarget& target;         ///< the target the loop servos on
  const vpHomogeneousMatrix& cdMo;  ///< the goal: where the lines should end up
  bool lines_undistorted = false;   ///< the lines are in undistorted pixels
};

/// Hooks for the caller: `interrupt` is polled every iteration (and on set, the robot's
/// emergency stop is requested); `on_robot` is called with the SafeRobot once it is running
/// and with nullptr before it is destroyed, on every path out of RunServoLoop (an exception
/// too), so a signal handler can reach SafeRobot::RequestEmergencyStop() while it lives.
struct ServoLoopHooks {
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
  /// Called with the iteration whose motion is about to be commanded.
  std::function<void(int iteration)> on_move;
};

/// Runs the loop (see the file comment) on `frames` and `robot`. Writes one line per iteration
/// to `log`. Throws std::invalid_argument / std::runtime_error for a setup it cannot run (a
/// velocity law on a robot that takes position moves only, a goal image without a pose),
/// before the robot moves.
ServoRunReport RunServoLoop(const ServoSetup& setup, FrameSource& frames, const LoopRobot& robot,
                            std::ostream& log, const ServoLoopHooks& hooks = ServoLoopHooks());

/// Where the camera is: the robot's camera pose, or, with `true_eMc` (a simulation whose camera
/// is not mounted as the robot's eMc says), the end effector's pose through it.
RobotPose TrueCameraPose(SafeRobot& robot, const std::optional<vpHomogeneousMatrix>& true_eMc);

/// The lens from the stripes of the first frames that show the target, the robot still
/// (loop/lens_estimate.h): `*camera` (a pinhole camera) gains it and `*tracker` is rebuilt
/// from the setup with it; `log` gets one line saying what it is. False with `why` when the
/// frames cannot tell it.
bool TellTheLens(const ServoSetup& setup, SafeRobot& robot, FrameSource& frames, Lens* camera,
                 TargetPoseTracker* tracker, std::ostream& log, std::string* why);

/// The Table 3 columns of a camera pose wMc: X, Y, Z (mm), pitch, roll and yaw (deg) with
/// wRc = Rx(π)·Rx(pitch)·Ry(yaw)·Rz(roll) (ServoIteration).
void Table3Columns(const vpHomogeneousMatrix& wMc, double* x_mm, double* y_mm, double* z_mm,
                   double* pitch_deg, double* roll_deg, double* yaw_deg);

/// The report as CSV: a header and one row per iteration.
void WriteServoCsv(const ServoRunReport& report, std::ostream& out);

}  // namespace oal
