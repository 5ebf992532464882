// One run of the loop in one file: its steps (grab, pose, checks, command, log row) are small
// functions around one ServoRun, and every stop path must reach the same StopGuard; split,
// they would each need the run's state handed across files.
#include "loop/servo_loop.h"

#include <visp3/core/vpMath.h>
#include <visp3/core/vpRotationMatrix.h>
#include <visp3/core/vpThetaUVector.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <deque>
#include <iomanip>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <utility>
#include <vector>

#include "base/field_names.h"
#include "base/format.h"
#include "detector/detector.h"
#include "detector/image_view.h"
#include "detector/lens.h"
#include "loop/lens_estimate.h"  // LensMismatchWarning
#include "scene/scene.h"
#include "servo/pbvs.h"
#include "servo/pose.h"
#include "servo/target_tracker.h"

namespace oal {
namespace {

// Stops the robot however the loop ends (also on an exception) and unregisters it from the
// command's signal handler first. Declared after the SafeRobot, so destroyed before it: the
// handler never sees a destroyed robot.
class StopGuard {
 public:
  StopGuard(SafeRobot& robot, const ServoLoopHooks& hooks) : robot_(robot), hooks_(hooks) {
    if (!hooks_.on_robot) return;
    try {
      hooks_.on_robot(&robot_);
    } catch (...) {
      Unregister();  // a hook that registered the robot and then threw
      throw;
    }
  }
  ~StopGuard() {
    if (!stopped_) Stop();
  }
  StopGuard(const StopGuard&) = delete;
  StopGuard& operator=(const StopGuard&) = delete;

  // Unregisters the robot and stops it; the destructor then has nothing left to do.
  RobotResult Stop() noexcept {
    stopped_ = true;
    Unregister();
    return robot_.Stop();
  }

 private:
  void Unregister() noexcept {
    if (!hooks_.on_robot) return;
    try {
      hooks_.on_robot(nullptr);
    } catch (...) {  // the stop must still be sent; nothing else to do about it
    }
  }

  SafeRobot& robot_;
  const ServoLoopHooks& hooks_;
  bool stopped_ = false;
};

// The table's header and rows; `yaw`: with the yaw column (not for the 5-axis Scorbot).
// The console's table: one row per frame (Table 3's columns); the estimated error to the goal
// and, in a simulation, the true one beside it; "-" where a value is unknown (no pose, or the
// row after a stop, which has no frame).
struct TableColumns {
  bool yaw = true;    ///< a yaw column (not for the 5-axis Scorbot)
  bool truth = true;  ///< true error columns (the simulated camera knows it)
};

void LogHeader(const TableColumns& columns, std::ostream& log) {
  log << "frame     X mm     Y mm     Z mm pitch deg  roll deg" << (columns.yaw ? "   yaw deg" : "")
      << "    est mm   est deg" << (columns.truth ? "   true mm  true deg" : "") << "  status\n";
}

void LogValue(double value, int width, int precision, std::ostream& log) {
  if (std::isfinite(value)) {
    log << std::setw(width) << std::setprecision(precision) << value;
  } else {
    log << std::setw(width) << "-";
  }
}

void LogRow(const ServoIteration& row, const TableColumns& columns, std::ostream& log) {
  log << std::setw(5) << row.iteration << std::fixed;
  for (const double mm : {row.x_mm, row.y_mm, row.z_mm}) LogValue(mm, 9, 1, log);
  LogValue(row.pitch_deg, 10, 2, log);
  LogValue(row.roll_deg, 10, 2, log);
  if (columns.yaw) LogValue(row.yaw_deg, 10, 2, log);
  LogValue(row.translation_error_mm, 10, 3, log);
  LogValue(row.rotation_error_deg, 10, 3, log);
  if (columns.truth) {
    LogValue(row.true_translation_error_mm, 10, 3, log);
    LogValue(row.true_rotation_error_deg, 10, 3, log);
  }
  log << "  " << row.status << '\n' << std::defaultfloat;
}

ServoRunStatus StatusOfRefusal(const RobotResult& result, const SafeRobot& robot) {
  switch (result.status) {
    case RobotStatus::kWorkspace:
    case RobotStatus::kLimit:
    case RobotStatus::kUnreachable:
      return ServoRunStatus::kLimit;
    default:
      break;
  }
  if (robot.EmergencyStopRequested()) return ServoRunStatus::kInterrupted;
  return ServoRunStatus::kError;
}

// Why the loop ends, for the report.
struct Stop {
  ServoRunStatus status;
  std::string message;
};

// Who asked for a stop, for "interrupted by ...".
std::string InterruptedBy(const ServoLoopHooks& hooks) {
  return hooks.interrupt_reason ? hooks.interrupt_reason() : "Ctrl-C or a stop from the window";
}

// "1 move", "3 moves".
// The setup's image size as its user names it ("width x height").
std::string SizeWords(const FieldNames& names) {
  return names("width") + " x " + names("height");
}

std::string Counted(int count, const std::string& noun) {
  return std::to_string(count) + " " + noun + (count == 1 ? "" : "s");
}

// Step 1 (after the operator's stop): the time and the iteration limits. A recording that
// ends where the iteration limit does was played to its end: end-of-input.
std::optional<Stop> LimitReached(const ServoLoopOptions& loop, const FieldNames& names, int limit,
                                 int iteration, std::chrono::steady_clock::time_point start,
                                 FrameSource& frames) {
  const double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (elapsed_s > loop.max_time_s) {
    return Stop{ServoRunStatus::kTimeLimit, "time limit reached: " + names("loop.max_time_s") +
                                                " = " + Number(loop.max_time_s) + " s (" +
                                                Fixed(elapsed_s, 3) +
                                                " s elapsed) without converging"};
  }
  if (iteration >= limit) {
    const std::string setting = names("loop.max_iterations") + " = " + std::to_string(limit) +
                                (loop.max_iterations == 0 ? ", the law's own" : "");
    if (frames.AtEnd()) {
      return Stop{ServoRunStatus::kEndOfInput, "end of " + frames.Name() + " after " +
                                                   std::to_string(iteration) + " frames (" +
                                                   setting + ")"};
    }
    return Stop{ServoRunStatus::kIterationLimit,
                "iteration limit reached: " + setting + " frames without converging"};
  }
  return std::nullopt;
}

// The frame of this iteration, of the camera's size; a stop when there is none.
// `on_grab` (ServoLoopHooks) sees the frame before it is checked.
std::optional<Stop> Grab(FrameSource& frames, int width, int height, const FieldNames& names,
                         const Capture& capture, const std::function<void(int, cv::Mat*)>& on_grab,
                         cv::Mat* gray) {
  const int iteration = capture.iteration;
  bool have_frame = false;
  try {
    have_frame = frames.Grab(capture, gray);
  } catch (const std::exception& error) {
    return Stop{ServoRunStatus::kError, "cannot read the next frame at iteration " +
                                            std::to_string(iteration) + ": " + error.what()};
  }
  if (!have_frame) {
    return Stop{ServoRunStatus::kEndOfInput,
                "end of " + frames.Name() + " after " + std::to_string(iteration) + " frames"};
  }
  if (on_grab) on_grab(iteration, gray);
  if (gray->empty()) {
    return Stop{ServoRunStatus::kError, "cannot read the next frame at iteration " +
                                            std::to_string(iteration) + ": " + frames.Name() +
                                            " gave an empty frame"};
  }
  if (gray->cols != width || gray->rows != height) {
    return Stop{ServoRunStatus::kError, frames.Name() + " gives " + std::to_string(gray->cols) +
                                            "x" + std::to_string(gray->rows) + " frames but " +
                                            SizeWords(names) + " is " + std::to_string(width) +
                                            "x" + std::to_string(height)};
  }
  return std::nullopt;
}

// The table row of a camera pose: the Table 3 columns (the Scorbot's own X Y Z P R) and, in
// simulation, the true error to the goal; the estimate's columns are filled in later.
ServoIteration RowAt(const LoopRobot& robot, bool knows_truth, int iteration,
                     const vpHomogeneousMatrix& wMc, const vpHomogeneousMatrix& true_cMo,
                     const vpHomogeneousMatrix& cdMo) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  ServoIteration row;
  row.iteration = iteration;
  PoseColumns at;
  if (robot.columns) {
    at = robot.columns(wMc);
  } else {
    Table3Columns(wMc, &at.x_mm, &at.y_mm, &at.z_mm, &at.pitch_deg, &at.roll_deg, &at.yaw_deg);
  }
  row.x_mm = at.x_mm, row.y_mm = at.y_mm, row.z_mm = at.z_mm;
  row.pitch_deg = at.pitch_deg, row.roll_deg = at.roll_deg, row.yaw_deg = at.yaw_deg;
  row.true_translation_error_mm = row.true_rotation_error_deg = kNaN;
  if (knows_truth) {
    const PoseDistance truth = Distance(cdMo * true_cMo.inverse(), vpHomogeneousMatrix());
    row.true_translation_error_mm = truth.translation_m * 1e3;
    row.true_rotation_error_deg = vpMath::deg(truth.rotation_rad);
  }
  row.translation_error_mm = row.rotation_error_deg = kNaN;
  row.status = "running";
  return row;
}

// Why a frame has no pose, in the tracker's words: the pose's status and message.
std::string NoPoseReason(const TargetFrame& tracked) {
  const PoseResult& pose = tracked.pose;
  // The pose's own status when it failed, else what the tracker refused it for.
  const bool pose_failed = pose.status != PoseStatus::kOk;
  const std::string& message = pose_failed ? pose.message : tracked.message;
  return (pose_failed ? ToString(pose.status) : ToString(tracked.status)) +
         (message.empty() ? "" : " (" + message + ")");
}

// How far cMo is from `reference` (the odometry's prediction, or the pose it should confirm)
// when beyond servo.max_pose_jump_m or max_pose_jump_deg; nothing when it agrees.
std::optional<PoseDistance> Disagreement(const vpHomogeneousMatrix& cMo,
                                         const vpHomogeneousMatrix& reference,
                                         const ServoLoopOptions& loop) {
  const PoseDistance jump = Distance(reference, cMo);
  if (jump.translation_m <= loop.max_pose_jump_m &&
      vpMath::deg(jump.rotation_rad) <= loop.max_pose_jump_deg) {
    return std::nullopt;
  }
  return jump;
}

std::string Apart(const PoseDistance& jump, const ServoLoopOptions& loop, const FieldNames& names) {
  return Fixed(jump.translation_m * 1e3, 1) + " mm and " +
         Fixed(vpMath::deg(jump.rotation_rad), 2) + " deg (limits " +
         Fixed(loop.max_pose_jump_m * 1e3, 1) + " mm, " + Fixed(loop.max_pose_jump_deg, 2) +
         " deg: " + names("loop.max_pose_jump_m") + ", " + names("loop.max_pose_jump_deg") + ")";
}

// A motion that failed: refused before it began (`started` false: the robot did not move),
// or stopped on its way.
Stop RefusalStop(const RobotResult& moved, bool started, const SafeRobot& robot, int iteration,
                 const ServoLoopHooks& hooks) {
  const ServoRunStatus status = StatusOfRefusal(moved, robot);
  const std::string move = "the move of iteration " + std::to_string(iteration);
  if (status == ServoRunStatus::kInterrupted) {
    return {status, "interrupted by " + InterruptedBy(hooks) +
                        (started ? " during " + move : " before " + move + " began (refused)")};
  }
  return {status,
          ToString(status) + " at iteration " + std::to_string(iteration) + ": " +
              (started ? "stopped during the move: " : "move refused, the robot did not move: ") +
              moved.message};
}

// A position step larger than max_step_m / max_step_deg: the run stops before it.
std::optional<Stop> StepTooLarge(const ServoStep& step, const ServoLoopOptions& loop,
                                 const FieldNames& names, int iteration) {
  const PoseDistance size = Distance(vpHomogeneousMatrix(), step.c_T_cnew);
  if (size.translation_m <= loop.max_step_m &&
      vpMath::deg(size.rotation_rad) <= loop.max_step_deg) {
    return std::nullopt;
  }
  return Stop{ServoRunStatus::kLimit,
              "limit at iteration " + std::to_string(iteration) + ": the move of " +
                  Fixed(size.translation_m * 1e3, 1) + " mm and " +
                  Fixed(vpMath::deg(size.rotation_rad), 2) + " deg exceeds " +
                  names("loop.max_step_m") + " = " + Number(loop.max_step_m) + " m or " +
                  names("loop.max_step_deg") + " = " + Number(loop.max_step_deg) +
                  " deg, the robot did not move (a wrong pose, or a goal farther than one move "
                  "may go: raise them, or use the exponential law with a smaller " +
                  names("loop.law.delta") + ")"};
}

// What the end of the run did to the robot, appended to the stop message.
std::string StopOutcome(const RobotResult& stopped, ServoRunStatus status, bool connected) {
  if (!stopped.ok()) {
    return "; STOP COULD NOT BE SENT: " + stopped.message + " — check the arm";
  }
  const bool says_so =
      status != ServoRunStatus::kConverged && status != ServoRunStatus::kEndOfInput && connected;
  return says_so ? "; robot stopped" : "";
}

// A robot that starts outside the workspace box (a real arm stands where it stands): a
// warning, since every move is still checked against the box.
void WarnIfOutsideWorkspace(SafeRobot& robot, const FieldNames& names, std::ostream& log) {
  const SafetyOptions& safety = robot.options();
  const RobotPose at = robot.GetPosition(safety.workspace_frame);
  if (!at.result.ok()) return;  // the loop's first read reports it
  const std::string why = safety.OutsideWorkspace(at.pose.getTranslationVector());
  if (why.empty()) return;
  log << "warning: the robot starts outside the workspace box: the "
      << ToString(safety.workspace_frame) << "'s " << why << " (" << names("safety.workspace_min_m")
      << " / " << names("safety.workspace_max_m")
      << "); every move is still checked against the "
         "box and may be refused: bring the arm into the box or widen it\n";
}

}  // namespace

std::string ToString(ServoRunStatus status) {
  switch (status) {
    case ServoRunStatus::kConverged:
      return "converged";
    case ServoRunStatus::kTargetLost:
      return "target-lost";
    case ServoRunStatus::kPoseJump:
      return "pose-jump";
    case ServoRunStatus::kLimit:
      return "limit";
    case ServoRunStatus::kIterationLimit:
      return "iteration-limit";
    case ServoRunStatus::kTimeLimit:
      return "time-limit";
    case ServoRunStatus::kInterrupted:
      return "interrupted";
    case ServoRunStatus::kEndOfInput:
      return "end-of-input";
    case ServoRunStatus::kError:
      return "error";
  }
  return "error";
}

void Table3Columns(const vpHomogeneousMatrix& wMc, double* x_mm, double* y_mm, double* z_mm,
                   double* pitch_deg, double* roll_deg, double* yaw_deg) {
  // wRc = Rx(π)·Rx(pitch)·Ry(yaw)·Rz(roll)  =>  M = Rx(-π)·wRc = Rx(pitch)·Ry(yaw)·Rz(roll),
  // whose x-y-z Euler angles these are (the config's rxyz_deg with 180 taken off rx).
  const vpRotationMatrix M =
      vpRotationMatrix(vpThetaUVector(-M_PI, 0, 0)) * wMc.getRotationMatrix();
  *x_mm = wMc[0][3] * 1e3;
  *y_mm = wMc[1][3] * 1e3;
  *z_mm = wMc[2][3] * 1e3;
  *pitch_deg = vpMath::deg(std::atan2(-M[1][2], M[2][2]));
  *yaw_deg = vpMath::deg(std::asin(std::clamp(M[0][2], -1.0, 1.0)));
  *roll_deg = vpMath::deg(std::atan2(-M[0][1], M[0][0]));
}

namespace {

// A CSV field: quoted, its quotes doubled, when it holds a comma, a quote or a line break.
std::string CsvQuoted(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  return quoted + '"';
}

}  // namespace

void WriteServoCsv(const ServoRunReport& report, std::ostream& out) {
  out << "iteration,x_mm,y_mm,z_mm,pitch_deg,roll_deg,yaw_deg,translation_error_mm,"
         "rotation_error_deg,true_translation_error_mm,true_rotation_error_deg,held,status\n";
  for (const ServoIteration& row : report.iterations) {
    out << row.iteration << ',' << Fixed(row.x_mm, 4) << ',' << Fixed(row.y_mm, 4) << ','
        << Fixed(row.z_mm, 4) << ',' << Fixed(row.pitch_deg, 5) << ',' << Fixed(row.roll_deg, 5)
        << ',' << Fixed(row.yaw_deg, 5) << ',' << Fixed(row.translation_error_mm, 5) << ','
        << Fixed(row.rotation_error_deg, 6) << ',' << Fixed(row.true_translation_error_mm, 5) << ','
        << Fixed(row.true_rotation_error_deg, 6) << ',' << CsvQuoted(row.held) << ',' << row.status
        << '\n';
  }
}

int ServoLoopOptions::IterationLimit(bool replay) const {
  if (max_iterations > 0) return max_iterations;
  if (replay) return std::numeric_limits<int>::max();
  return law.mode == ServoMode::kVelocity ? 300 : 30;
}

void ServoLoopOptions::Check() const {
  law.Check();
  RequireOption(max_iterations >= 0 && max_iterations <= 1000000,
                "ServoLoopOptions::max_iterations", max_iterations,
                "0 <= max_iterations <= 1000000 (0: the law's own limit)");
  RequireOption(max_time_s > 0.0 && std::isfinite(max_time_s), "ServoLoopOptions::max_time_s",
                max_time_s, "max_time_s > 0");
  RequireOption(max_pose_jump_m > 0.0 && std::isfinite(max_pose_jump_m),
                "ServoLoopOptions::max_pose_jump_m", max_pose_jump_m, "max_pose_jump_m > 0");
  RequireOption(max_pose_jump_deg > 0.0 && max_pose_jump_deg <= 180.0,
                "ServoLoopOptions::max_pose_jump_deg", max_pose_jump_deg,
                "0 < max_pose_jump_deg <= 180");
  RequireOption(max_step_m > 0.0 && std::isfinite(max_step_m), "ServoLoopOptions::max_step_m",
                max_step_m, "max_step_m > 0");
  RequireOption(max_step_deg > 0.0 && max_step_deg <= 180.0, "ServoLoopOptions::max_step_deg",
                max_step_deg, "0 < max_step_deg <= 180");
  RequireOption(max_lost_s >= 0.0 && max_lost_s <= 3600.0, "ServoLoopOptions::max_lost_s",
                max_lost_s, "0 <= max_lost_s <= 3600");
  RequireOption(max_lost_frames >= 0 && max_lost_frames <= 1000000,
                "ServoLoopOptions::max_lost_frames", max_lost_frames,
                "0 <= max_lost_frames <= 1000000");
}

TargetPoseTracker MakeTracker(const ServoSetup& setup) {
  // The tracker sets the camera, the undistortion and the image size from its own.
  PoseOptions pose = setup.pose;
  pose.compute_covariance = false;  // the loop does not use it
  return TargetPoseTracker(setup.target, setup.camera, setup.detector, pose, setup.tracking);
}

vpHomogeneousMatrix TeachGoal(const ServoSetup& setup, const cv::Mat& gray,
                              const std::string& where) {
  if (gray.cols != setup.width || gray.rows != setup.height) {
    throw std::runtime_error(where + " is " + std::to_string(gray.cols) + "x" +
                             std::to_string(gray.rows) + " but " + SizeWords(setup.names) + " is " +
                             std::to_string(setup.width) + "x" + std::to_string(setup.height));
  }
  TargetPoseTracker tracker = MakeTracker(setup);
  const TargetFrame& found = tracker.Track(ViewOf(gray));
  if (found.status != TargetStatus::kOk) {
    const bool pose_failed = found.pose.status != PoseStatus::kOk;
    throw std::runtime_error(where + ": no pose of target '" + setup.target.name + "' in it: " +
                             (pose_failed ? ToString(found.pose.status) : ToString(found.status)) +
                             (found.message.empty() ? "" : " (" + found.message + ")"));
  }
  return found.pose.cMo;
}

RobotPose TrueCameraPose(SafeRobot& robot, const std::optional<vpHomogeneousMatrix>& true_eMc) {
  if (!true_eMc) return robot.GetPosition(RobotFrame::kCamera);
  RobotPose wMe = robot.GetPosition(RobotFrame::kEndEffector);
  if (wMe.result.ok()) wMe.pose = wMe.pose * *true_eMc;
  return wMe;
}

bool TellTheLens(const ServoSetup& setup, SafeRobot& robot, FrameSource& frames, Lens* camera,
                 TargetPoseTracker* tracker, std::ostream& log, std::string* why) {
  // The frames read, the robot still: their noise seeds apart from the loop's.
  constexpr int kLensFrameIndex = 1000000;
  cv::Mat gray;
  int read = 0;
  std::string pose_error;
  const ToldLens told = TellLensFromStripes(*tracker, *camera, [&](GrayImageView* view) {
    const RobotPose at = TrueCameraPose(robot, setup.true_eMc);
    if (!at.result.ok()) {
      pose_error = "the camera's pose cannot be read: " + at.result.message;
      return false;
    }
    Capture capture;
    capture.true_cMo = at.pose.inverse() * setup.wMo;
    capture.iteration = kLensFrameIndex + read++;
    if (!frames.Grab(capture, &gray)) {
      return false;
    }
    *view = ViewOf(gray);
    return true;
  });
  if (!told.lens) {
    *why = pose_error.empty() ? told.why : pose_error;
    return false;
  }
  const PlumbLineResult& lens = *told.lens;
  *camera = WithLens(*camera, lens);
  ServoSetup with_lens = setup;
  with_lens.camera = *camera;
  *tracker = MakeTracker(with_lens);
  log << "lens told from the stripes of " << told.frames << " frames: kdu " << Fixed(lens.kdu, 4)
      << " +- " << Fixed(lens.kdu_sd, 4) << " (kud " << Fixed(lens.kud, 4) << ")"
      << " (they bent " << Fixed(lens.rms_before_px, 2) << " px RMS, "
      << Fixed(lens.rms_after_px, 2) << " px corrected)\n";
  return true;
}

namespace {

// Where the camera was at a time of the loop's clock: the poses read each frame and at the
// end of each move, interpolated along the constant twist between two of them (as the
// simulated robot moves: a velocity held for a period, a move along one twist).
class PoseHistory {
 public:
  void Add(double time_s, const vpHomogeneousMatrix& wMc) {
    if (!poses_.empty() && time_s <= poses_.back().first) poses_.pop_back();  // the same time
    poses_.emplace_back(time_s, wMc);
    if (poses_.size() > kKept) poses_.pop_front();
  }
  // The earliest kept when `time_s` is before it.
  vpHomogeneousMatrix At(double time_s) const {
    if (poses_.empty()) return vpHomogeneousMatrix();
    if (time_s <= poses_.front().first) return poses_.front().second;
    for (std::size_t i = 1; i < poses_.size(); ++i) {
      const auto& [t1, M1] = poses_[i];
      if (time_s > t1) continue;
      const auto& [t0, M0] = poses_[i - 1];
      const double s = (time_s - t0) / (t1 - t0);
      return M0 * Se3Exp(s * Se3Log(M0.inverse() * M1));
    }
    return poses_.back().second;
  }

 private:
  static constexpr std::size_t kKept = 256;
  std::deque<std::pair<double, vpHomogeneousMatrix>> poses_;
};

// One run of the loop, in its steps: Prepare (before the robot is touched), Begin (connect,
// enable, the lens), then one Iterate per frame until a Stop, and Finish (the stop sent, the
// last row, the report) on every way out.
class ServoRun {
 public:
  ServoRun(const ServoSetup& setup, FrameSource& frames, const LoopRobot& rig, std::ostream& log,
           const ServoLoopHooks& hooks)
      : setup_(setup),
        frames_(frames),
        rig_(rig),
        log_(log),
        hooks_(hooks),
        camera_(setup.camera),
        tracker_(MakeTracker(setup)),
        robot_(*rig.driver, setup.safety),
        columns_{rig.has_yaw, frames.KnowsTruth()} {}

  ServoRunReport Run() {
    Prepare();
    if (std::optional<Stop> stop = Begin()) return Finish(*stop);
    const auto start = std::chrono::steady_clock::now();
    const int iteration_limit = setup_.loop.IterationLimit(setup_.open_loop);
    log_ << "frame 0 finds the target; frame 1, the robot still, confirms it; then each frame "
            "commands one move. A frame without a pose, or whose pose disagrees with the "
            "robot's motion, holds the robot until the target is found and confirmed again. "
            "Errors to the goal: est by the estimated pose"
         << (columns_.truth ? ", true by the simulation's truth" : "") << ".\n";
    LogHeader(columns_, log_);
    for (int iteration = 0;; ++iteration) {
      if (std::optional<Stop> stop = Interrupted(iteration)) return Finish(*stop);
      // Frames held count towards the hold's own limits, not the law's.
      if (std::optional<Stop> stop =
              LimitReached(setup_.loop, setup_.names, iteration_limit,
                           iteration - report_.held_frames - skipped_frames_, start, frames_)) {
        return Finish(*stop);
      }
      if (std::optional<Stop> stop = Iterate(iteration)) return Finish(*stop);
    }
  }

 private:
  // What is checked, and the goal taught, before the robot is touched.
  void Prepare() {
    const bool velocity_law = setup_.loop.law.mode == ServoMode::kVelocity;
    if (velocity_law && !rig_.driver->Capabilities().velocity) {
      throw std::invalid_argument(
          setup_.names("loop.law.mode") + " velocity needs a robot driven in velocity; " +
          rig_.driver->Name() + " takes position moves only: use exponential or point-and-go");
    }
    const bool taught = !setup_.goal_image.empty();
    report_.cdMo =
        taught ? TeachGoal(setup_, setup_.goal_image, setup_.goal_image_name) : setup_.cdMo;
    if (taught) {
      const vpTranslationVector t = report_.cdMo.getTranslationVector();
      log_ << "goal taught from " << setup_.goal_image_name << ": target at (" << Fixed(t[0], 4)
           << ", " << Fixed(t[1], 4) << ", " << Fixed(t[2], 4) << ") m in the goal camera\n";
    }
    if (setup_.open_loop) {
      log_ << "replay of " << frames_.Name() << ": open loop, the robot is not moved\n";
    }
  }

  // The robot connected and enabled, the run begun, the lens told when it is to be.
  std::optional<Stop> Begin() {
    if (RobotResult r = robot_.Connect(); !r.ok()) {
      return Stop{ServoRunStatus::kError,
                  "cannot connect the robot: " + r.message + rig_.connect_hint};
    }
    guard_.emplace(robot_, hooks_);
    if (RobotResult r = robot_.Enable(); !r.ok()) {
      return Stop{ServoRunStatus::kError, "cannot enable the robot: " + r.message};
    }
    WarnIfOutsideWorkspace(robot_, setup_.names, log_);
    period_s_ = rig_.driver->Capabilities().sampling_time_s;
    begun_ = std::chrono::steady_clock::now();
    report_.started = true;
    if (hooks_.on_started) hooks_.on_started();
    if (setup_.estimate_distortion) {
      std::string why;
      if (!TellTheLens(setup_, robot_, frames_, &camera_, &tracker_, log_, &why)) {
        return Stop{ServoRunStatus::kError, "cannot tell the lens: " + why};
      }
    }
    return std::nullopt;
  }

  // The operator's stop (the hook's flag, or the robot's emergency stop).
  std::optional<Stop> Interrupted(int iteration) {
    const bool interrupted = (hooks_.interrupt != nullptr && hooks_.interrupt->load()) ||
                             robot_.EmergencyStopRequested();
    if (!interrupted) return std::nullopt;
    robot_.RequestEmergencyStop();
    return Stop{ServoRunStatus::kInterrupted, "interrupted by " + InterruptedBy(hooks_) +
                                                  " after " + std::to_string(iteration) +
                                                  " iterations"};
  }

  // One frame: where the camera is, the frame, the pose and its checks, the law, the move.
  std::optional<Stop> Iterate(int iteration) {
    const RobotPose read = TrueCameraPose(robot_, setup_.true_eMc);
    if (!read.result.ok()) {
      return Stop{ServoRunStatus::kError, "cannot read the camera pose: " + read.result.message};
    }
    if (iteration > 0) simulated_s_ += period_s_;  // one frame of the simulated camera
    const double now_s = Now();
    history_.Add(now_s, read.pose);
    // The frame was taken a latency ago: the scene then, and everything the loop predicts
    // and commands from it, is where the camera was then.
    Capture capture;
    capture.iteration = iteration;
    capture.time_s = now_s - frames_.LatencyS();
    vpHomogeneousMatrix wMc = capture.time_s < now_s ? history_.At(capture.time_s) : read.pose;
    capture.true_cMo = wMc.inverse() * setup_.wMo;
    capture.velocity = velocity_;
    if (std::optional<Stop> stop = Grab(frames_, setup_.width, setup_.height, setup_.names, capture,
                                        hooks_.on_grab, &gray_)) {
      return stop;
    }
    // A camera that says when it took the frame (V4L2 timestamps, the monotonic clock).
    if (const std::optional<double> taken = frames_.TakenAt(); taken && !frames_.KnowsTruth()) {
      const double begun_s = std::chrono::duration<double>(begun_.time_since_epoch()).count();
      capture.time_s = std::min(*taken - begun_s, now_s);
      wMc = history_.At(capture.time_s);
    }
    report_.iterations.push_back(RowAt(rig_, columns_.truth, iteration, read.pose,
                                       read.pose.inverse() * setup_.wMo, report_.cdMo));
    moved_since_row_ = false;
    ServoIteration& current = report_.iterations.back();
    // A frame taken before the last move ended shows the arm on its way: the next one, taken
    // with the arm still, is the one to act on.
    if (move_ended_s_ && capture.time_s < *move_ended_s_) {
      current.status = "skipped";
      current.held = "taken before the move ended (camera latency)";
      ++skipped_frames_;
      // A camera whose frames stay older than the move (a wrong timestamp or latency) would
      // be skipped for ever.
      if (++skipped_in_a_row_ > setup_.loop.max_lost_frames) {
        const Stop stop{ServoRunStatus::kError,
                        std::to_string(skipped_in_a_row_) + " frames in a row were taken " +
                            Fixed(*move_ended_s_ - capture.time_s, 3) +
                            " s or more before the last move ended: the camera's timestamps (or " +
                            setup_.names("latency_s") +
                            ") say its frames are older than they can be"};
        current.status = ToString(stop.status);
        LogRow(current, columns_, log_);
        return stop;
      }
      LogRow(current, columns_, log_);
      return std::nullopt;
    }
    skipped_in_a_row_ = 0;

    // Where the robot's motion since the last confirmed estimate puts the target.
    std::optional<vpHomogeneousMatrix> predicted_cMo;
    if (previous_cMo_) predicted_cMo = wMc.inverse() * previous_wMc_ * *previous_cMo_;
    // A pose found on the last frame, the robot still since, is confirmed by this one, found
    // on its own, so that a wrong pose cannot seed its own confirmation. Otherwise the
    // prediction places the borders on the target and seeds the accumulator list and the
    // estimate: the lines' identities and the solution of the planar pose ambiguity carried
    // through the move (after a move that rolled the camera by 60 deg, the pose before it is
    // nearer a 90-deg-turned assignment of a near-square target's lines than the right one).
    const bool confirming = candidate_cMo_.has_value();
    if (confirming) tracker_.Reset();
    tracker_.set_measure_lens(lens_frames_.size() < kLensCheckFrames);
    const TargetFrame& tracked =
        tracker_.Track(ViewOf(gray_), confirming ? std::nullopt : predicted_cMo);
    const PoseResult& pose = tracked.pose;
    CheckLensOnce(tracked);
    std::optional<ServoStep> step;
    if (tracked.status == TargetStatus::kOk) {
      // The law acts now: the estimate, made where the camera was when the frame was taken,
      // carried to where it is by the robot's own motion since (a late frame's delay is not
      // the law's).
      step = ComputeServoStep(read.pose.inverse() * wMc * pose.cMo, report_.cdMo, setup_.loop.law);
      current.translation_error_mm = step->translation_error_m * 1e3;
      current.rotation_error_deg = vpMath::deg(step->rotation_error_rad);
    }
    const Verdict verdict = Judge(tracked, predicted_cMo, confirming, iteration);
    if (verdict.hold) {
      Hold(iteration, *verdict.hold, &current);
    } else if (step->status == ServoStatus::kConverged) {
      current.status = "converged";
    } else if (verdict.found) {
      current.status = "found";
    }
    if (hooks_.on_frame) {
      hooks_.on_frame(ServoFrame{gray_, tracker_.lines(), pose, tracked, current, camera_,
                                 setup_.target, report_.cdMo, tracker_.detector().Undistorts()});
    }
    std::optional<Stop> stop = verdict.stop;
    if (!stop && verdict.hold) stop = HeldTooLong();
    if (stop) current.status = ToString(stop->status);
    LogRow(current, columns_, log_);
    if (stop) return stop;
    if (verdict.hold) return HoldStill(iteration);
    if (verdict.found) {
      if (step->status != ServoStatus::kConverged) return std::nullopt;  // the next confirms it
    } else {
      EndHold(iteration);
      previous_cMo_ = pose.cMo;
      previous_wMc_ = wMc;
    }
    if (step->status == ServoStatus::kConverged) {
      return Stop{ServoRunStatus::kConverged,
                  "within the tolerances after " + Counted(report_.moves, "move") + " (" +
                      Counted(iteration + 1, "frame") + "): estimated error " +
                      Fixed(step->translation_error_m * 1e3, 3) + " mm, " +
                      Fixed(vpMath::deg(step->rotation_error_rad), 4) + " deg"};
    }
    if (setup_.open_loop) return std::nullopt;
    return Move(iteration, read.pose, *step);
  }

  // What a frame's pose may do: command the robot, wait for the next frame's confirmation
  // (found), hold the robot (why, in the user's words, and the status a stop would have), or
  // stop the run.
  struct HoldReason {
    std::string why;
    ServoRunStatus status = ServoRunStatus::kTargetLost;
    bool found_again = false;  ///< a pose to be confirmed: the hold's reason stays the last
  };
  struct Verdict {
    bool found = false;
    std::optional<HoldReason> hold;
    std::optional<Stop> stop;
  };

  Verdict Judge(const TargetFrame& tracked, const std::optional<vpHomogeneousMatrix>& predicted_cMo,
                bool confirming, int iteration) {
    Verdict verdict;
    if (tracked.status != TargetStatus::kOk) {
      candidate_cMo_.reset();
      verdict.hold = HoldReason{"no pose: " + NoPoseReason(tracked), ServoRunStatus::kTargetLost};
      return verdict;
    }
    const vpHomogeneousMatrix& cMo = tracked.pose.cMo;
    if (setup_.open_loop) {
      // A replay moves nothing and confirms nothing: the prediction is the last estimate, and
      // after a hold the next pose is taken as it is.
      if (predicted_cMo && !hold_) {
        if (std::optional<PoseDistance> jump = Disagreement(cMo, *predicted_cMo, setup_.loop)) {
          previous_cMo_.reset();
          verdict.hold =
              HoldReason{"pose jump: the estimate is " + Apart(*jump, setup_.loop, setup_.names) +
                             " from the previous one",
                         ServoRunStatus::kPoseJump};
        }
      }
      return verdict;
    }
    if (confirming) {
      const vpHomogeneousMatrix candidate = *candidate_cMo_;
      candidate_cMo_.reset();
      if (std::optional<PoseDistance> jump = Disagreement(cMo, candidate, setup_.loop)) {
        candidate_cMo_ = cMo;  // the next frame may confirm this one
        verdict.hold = HoldReason{
            "pose not confirmed: estimated on its own, this frame puts the target " +
                Apart(*jump, setup_.loop, setup_.names) +
                " from where the last frame did, the robot still (the pose is ambiguous or "
                "wrong)",
            ServoRunStatus::kPoseJump};
        return verdict;
      }
      if (predicted_cMo) {
        if (std::optional<PoseDistance> jump = Disagreement(cMo, *predicted_cMo, setup_.loop)) {
          verdict.stop =
              Stop{ServoRunStatus::kPoseJump,
                   "pose jump at iteration " + std::to_string(iteration) +
                       ": found again and confirmed by two frames, the target is " +
                       Apart(*jump, setup_.loop, setup_.names) +
                       " from where the robot's motion puts it: the target or the robot was moved "
                       "while the loop held; the robot was not moved since"};
        }
      }
      confirmed_ = !verdict.stop;  // it commands
      return verdict;
    }
    if (!confirmed_) {
      // The first pose, or the first found again after a hold: the next frame confirms it.
      candidate_cMo_ = cMo;
      verdict.found = !hold_;
      if (hold_) {
        verdict.hold = HoldReason{"found again: the next frame, the robot still, confirms it",
                                  hold_->reason.status, true};
      }
      return verdict;
    }
    if (predicted_cMo) {
      if (std::optional<PoseDistance> jump = Disagreement(cMo, *predicted_cMo, setup_.loop)) {
        verdict.hold =
            HoldReason{"pose jump: the estimate is " + Apart(*jump, setup_.loop, setup_.names) +
                           " from the previous one moved by the robot",
                       ServoRunStatus::kPoseJump};
      }
    }
    return verdict;
  }

  // The loop's clock, s: a simulated camera's time (nothing sleeps in a simulation: a frame
  // takes one sampling period of the robot, a move its polls), else the wall clock.
  double Now() const {
    if (frames_.KnowsTruth()) return simulated_s_;
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - begun_).count();
  }

  // The loop holds at this frame: nothing commanded from it, the confirmation starts again.
  void Hold(int iteration, const HoldReason& reason, ServoIteration* row) {
    if (!hold_) {
      hold_ = HoldState{iteration, Now(), 0, reason};
      ++report_.holds;
      log_ << "holding at frame " << iteration << ", nothing commanded: " << reason.why << '\n';
    }
    if (!reason.found_again) hold_->reason = reason;
    ++hold_->frames;
    ++report_.held_frames;
    confirmed_ = false;
    row->status = "held";
    row->held = reason.why;
  }

  // A hold past servo.max_lost_frames or max_lost_s ends the run.
  std::optional<Stop> HeldTooLong() const {
    const ServoLoopOptions& loop = setup_.loop;
    const double held_s = Now() - hold_->since_s;
    if (hold_->frames <= loop.max_lost_frames && held_s <= loop.max_lost_s) return std::nullopt;
    const bool lost = hold_->reason.status == ServoRunStatus::kTargetLost;
    return Stop{hold_->reason.status,
                std::string(lost ? "target lost" : "no pose confirmed") + ": held " +
                    Counted(hold_->frames, "frame") + " (" + Fixed(held_s, 2) +
                    " s) since iteration " + std::to_string(hold_->since_iteration) +
                    " without a confirmed pose (" + setup_.names("loop.max_lost_frames") + " = " +
                    std::to_string(loop.max_lost_frames) + ", " + setup_.names("loop.max_lost_s") +
                    " = " + Number(loop.max_lost_s) + "); the last reason: " + hold_->reason.why};
  }

  // While the loop holds, a velocity law commands zero (a position move has ended already).
  std::optional<Stop> HoldStill(int iteration) {
    if (setup_.open_loop || setup_.loop.law.mode != ServoMode::kVelocity) return std::nullopt;
    velocity_ = vpColVector(6, 0.0);
    const RobotResult held = robot_.SetVelocity(RobotFrame::kCamera, velocity_).result;
    if (!held.ok()) return RefusalStop(held, false, robot_, iteration, hooks_);
    return std::nullopt;
  }

  // A pose that commands again after a hold: said once.
  void EndHold(int iteration) {
    if (!hold_) return;
    log_ << "carrying on at frame " << iteration << " after holding "
         << Counted(hold_->frames, "frame") << " since frame " << hold_->since_iteration
         << ": the target found again and confirmed\n";
    hold_.reset();
  }

  // The lens check over the first frames with a pose, said once: a camera file that misses
  // the lens biases every pose, which the loop cannot see otherwise.
  void CheckLensOnce(const TargetFrame& tracked) {
    if (tracked.status != TargetStatus::kOk || lens_frames_.size() >= kLensCheckFrames) return;
    lens_frames_.push_back(tracked.lens);
    const LensCheck lens = CheckLens(lens_frames_, static_cast<int>(kLensCheckFrames));
    if (lens.mismatch) {
      // What to do, never what this run already did.
      log_ << "warning: "
           << LensMismatchWarning(
                  lens,
                  setup_.estimate_distortion ? "the lens told from the stripes"
                                             : "the camera model",
                  setup_.estimate_distortion
                      ? setup_.names.With("Calibrate the camera", "calibrate") +
                            ": one radial term told from four stripes does not hold this lens"
                      : setup_.names.With("Calibrate the camera", "calibrate") + ", or set " +
                            setup_.names("estimate_distortion"))
           << '\n';
    }
  }

  // The step commanded: a position move (checked for its size first) or a velocity cycle.
  std::optional<Stop> Move(int iteration, const vpHomogeneousMatrix& wMc, const ServoStep& step) {
    const bool velocity_law = setup_.loop.law.mode == ServoMode::kVelocity;
    if (!velocity_law) {
      if (std::optional<Stop> too_large =
              StepTooLarge(step, setup_.loop, setup_.names, iteration)) {
        return too_large;
      }
    }
    // Only a motion the robot began counts as a move: a velocity cycle it took, a position
    // move it was polled in (a refusal before StartMove leaves the robot where it was).
    moved_since_row_ = true;
    if (hooks_.on_move) hooks_.on_move(iteration);
    RobotResult moved;
    bool started = false;
    if (velocity_law) {
      velocity_ = step.twist;
      moved = robot_.SetVelocity(RobotFrame::kCamera, step.twist).result;
      started = moved.ok();
    } else {
      const MoveReport move = robot_.MovePosition(RobotFrame::kCamera, wMc * step.c_T_cnew);
      moved = move.result;
      started = moved.ok() || move.polls > 0;
      simulated_s_ += move.polls * period_s_;  // the move's time; it ends still
      if (moved.ok()) history_.Add(Now(), move.reached);
      move_ended_s_ = Now();
    }
    if (started) ++report_.moves;
    if (!moved.ok()) return RefusalStop(moved, started, robot_, iteration, hooks_);
    return std::nullopt;
  }

  // The robot stopped, and the report completed: after a move since the last frame, one more
  // row says where it stopped.
  ServoRunReport Finish(Stop stop) {
    report_.status = stop.status;
    const RobotResult stopped = guard_ ? guard_->Stop() : robot_.Stop();
    report_.robot_stopped = stopped.ok();
    // (A run that ends holding says so in its own message.)
    const std::string held = report_.holds == 0 || hold_
                                 ? ""
                                 : "; held " + Counted(report_.holds, "time") + " on the way (" +
                                       Counted(report_.held_frames, "frame") +
                                       " in all, nothing commanded)";
    report_.message =
        std::move(stop.message) + held + StopOutcome(stopped, stop.status, guard_.has_value());
    if (!report_.iterations.empty()) report_.iterations.back().status = ToString(stop.status);
    if (guard_) {
      const RobotPose where = TrueCameraPose(robot_, setup_.true_eMc);
      if (where.result.ok()) {
        report_.final_wMc = where.pose;
        if (moved_since_row_ && !report_.iterations.empty()) {
          ServoIteration row = RowAt(rig_, columns_.truth, report_.iterations.back().iteration + 1,
                                     where.pose, where.pose.inverse() * setup_.wMo, report_.cdMo);
          row.status = "stopped";
          LogRow(row, columns_, log_);
          report_.iterations.push_back(row);
        }
      } else if (moved_since_row_) {
        report_.message += "; position after the stop unknown: " + where.result.message;
      }
      report_.link_summary = rig_.driver->LinkSummary(report_.moves);
    }
    return report_;
  }

  const ServoSetup& setup_;
  FrameSource& frames_;
  const LoopRobot& rig_;
  std::ostream& log_;
  const ServoLoopHooks& hooks_;
  Lens camera_;  ///< the setup's, with the lens once told
  TargetPoseTracker tracker_;
  SafeRobot robot_;
  const TableColumns columns_;
  ServoRunReport report_;
  std::optional<StopGuard> guard_;  ///< from Connect() on; declared after robot_
  bool moved_since_row_ = false;    ///< a motion was commanded after the last row
  bool confirmed_ = false;          ///< the pose confirmed by a second frame, commanding
  /// A pose found with nothing to confirm it yet: the next frame, the robot still, must agree.
  std::optional<vpHomogeneousMatrix> candidate_cMo_;
  struct HoldState {
    int since_iteration = 0;
    double since_s = 0.0;  ///< Now()
    int frames = 0;
    HoldReason reason;
  };
  std::optional<HoldState> hold_;  ///< holding: nothing commanded since since_iteration
  /// The loop's clock (Now()): the simulated camera's, or the wall clock from begun_.
  double period_s_ = 0.04;  ///< the robot's sampling period: a simulated frame's time
  double simulated_s_ = 0.0;
  std::chrono::steady_clock::time_point begun_ = std::chrono::steady_clock::now();
  vpColVector velocity_;  ///< the twist commanded last (velocity law), for the exposure
  PoseHistory history_;   ///< where the camera was, for a frame taken before it is delivered
  std::optional<double> move_ended_s_;  ///< Now() when the last position move ended
  int skipped_frames_ = 0;              ///< taken before a move ended: not acted on, not counted
  int skipped_in_a_row_ = 0;
  /// The last confirmed pose and where the camera was: the odometry's prediction starts here.
  std::optional<vpHomogeneousMatrix> previous_cMo_;
  vpHomogeneousMatrix previous_wMc_;
  /// The lens check's frames: the first ones with a pose (their lines measured, no others).
  static constexpr std::size_t kLensCheckFrames = 5;
  std::vector<RadialBend> lens_frames_;
  cv::Mat gray_;
};

}  // namespace

ServoRunReport RunServoLoop(const ServoSetup& setup, FrameSource& frames, const LoopRobot& rig,
                            std::ostream& log, const ServoLoopHooks& hooks) {
  setup.loop.Check();
  if (rig.driver == nullptr) throw std::invalid_argument("RunServoLoop: no robot driver");
  return ServoRun(setup, frames, rig, log, hooks).Run();
}

}  // namespace oal
