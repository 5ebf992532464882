#include "app/servo_loop.h"

#include <visp3/core/vpMath.h>
#include <visp3/core/vpRotationMatrix.h>
#include <visp3/core/vpThetaUVector.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <iomanip>
#include <limits>
#include <optional>
#include <sstream>
#include <utility>

#include "detector/detector.h"
#include "detector/image_view.h"
#include "robots/simulated_camera.h"
#include "scene/scene.h"
#include "servo/pbvs.h"
#include "servo/pose.h"

namespace oal {
namespace {

constexpr std::uint64_t kNoiseSeed = 20240605;

// Stops the robot however the loop ends (also on an exception) and unregisters it from the
// command's signal handler first.
class StopGuard {
 public:
  StopGuard(SafeRobot& robot, const ServoRunHooks& hooks) : robot_(robot), hooks_(hooks) {
    if (hooks_.on_robot) hooks_.on_robot(&robot_);
  }
  ~StopGuard() {
    if (hooks_.on_robot) hooks_.on_robot(nullptr);
    robot_.Stop();
  }
  StopGuard(const StopGuard&) = delete;
  StopGuard& operator=(const StopGuard&) = delete;

 private:
  SafeRobot& robot_;
  const ServoRunHooks& hooks_;
};

std::string Fixed(double value, int digits) {
  std::ostringstream text;
  text << std::fixed << std::setprecision(digits) << value;
  return text.str();
}

void LogRow(const ServoIteration& row, std::ostream& log) {
  log << std::setw(4) << row.iteration << std::fixed << std::setprecision(1) << std::setw(9)
      << row.x_mm << std::setw(9) << row.y_mm << std::setw(9) << row.z_mm << std::setprecision(2)
      << std::setw(9) << row.pitch_deg << std::setw(9) << row.roll_deg << std::setprecision(3)
      << std::setw(11) << row.translation_error_mm << std::setw(10) << row.rotation_error_deg
      << "  " << row.status << '\n'
      << std::defaultfloat;
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
    case ServoRunStatus::kError:
      return "error";
  }
  return "error";
}

void Table3Columns(const vpHomogeneousMatrix& wMc, double* x_mm, double* y_mm, double* z_mm,
                   double* pitch_deg, double* roll_deg) {
  // wRc = Rx(π)·Rx(pitch)·Rz(roll)  =>  M = Rx(-π)·wRc = Rx(pitch)·Rz(roll).
  const vpRotationMatrix M =
      vpRotationMatrix(vpThetaUVector(-M_PI, 0, 0)) * wMc.getRotationMatrix();
  *x_mm = wMc[0][3] * 1e3;
  *y_mm = wMc[1][3] * 1e3;
  *z_mm = wMc[2][3] * 1e3;
  *pitch_deg = vpMath::deg(std::atan2(-M[1][2], M[2][2]));
  *roll_deg = vpMath::deg(std::atan2(-M[0][1], M[0][0]));
}

void WriteServoCsv(const ServoRunReport& report, std::ostream& out) {
  out << "iteration,x_mm,y_mm,z_mm,pitch_deg,roll_deg,translation_error_mm,rotation_error_deg,"
         "true_translation_error_mm,true_rotation_error_deg,status\n";
  for (const ServoIteration& row : report.iterations) {
    out << row.iteration << ',' << Fixed(row.x_mm, 4) << ',' << Fixed(row.y_mm, 4) << ','
        << Fixed(row.z_mm, 4) << ',' << Fixed(row.pitch_deg, 5) << ',' << Fixed(row.roll_deg, 5)
        << ',' << Fixed(row.translation_error_mm, 5) << ',' << Fixed(row.rotation_error_deg, 6)
        << ',' << Fixed(row.true_translation_error_mm, 5) << ','
        << Fixed(row.true_rotation_error_deg, 6) << ',' << row.status << '\n';
  }
}

ServoRunReport RunServo(const ServoAppConfig& config, std::ostream& log,
                        const ServoRunHooks& hooks) {
  // Everything checked before the robot moves.
  config.camera.Check();
  config.robot.Check();
  config.servo.Check();
  const vpCameraParameters camera = config.camera.Camera();
  RenderOptions render;
  render.width = config.camera.width;
  render.height = config.camera.height;
  render.camera = camera;
  render.noise_sigma = config.camera.noise;
  render.blur_sigma_px = config.camera.blur;
  const SceneRenderer renderer(config.target, render);
  // What the detector and the pose believe about the lens: the true one, or (the paper's
  // condition) a pinhole camera with the same intrinsics.
  const vpCameraParameters model = config.camera.correct_distortion
                                       ? camera
                                       : vpCameraParameters(config.camera.px, config.camera.py,
                                                            config.camera.u0, config.camera.v0);
  OalDetector detector(config.detector, model);
  PoseOptions pose_options = config.pose;
  pose_options.camera = model;
  pose_options.lines_undistorted = detector.Undistorts();
  pose_options.image_width = config.camera.width;
  pose_options.image_height = config.camera.height;
  pose_options.compute_covariance = false;  // the loop does not use it
  pose_options.Check();

  SimulatedCameraOptions sim_options;
  sim_options.sampling_time_s = config.robot.sampling_time_s;
  sim_options.move_mode = SimulatedCameraOptions::MoveMode::kJump;
  sim_options.wMc = config.robot.start_wMc;
  sim_options.eMc = config.camera.eMc;
  SimulatedCamera simulated(sim_options);
  SafeRobot robot(simulated, config.robot.safety);

  ServoRunReport report;
  auto finish = [&](ServoRunStatus status, std::string message) {
    report.status = status;
    report.message = std::move(message);
    robot.Stop();
    report.robot_stopped = robot.state() == SafeRobotState::kStopped;
    report.final_wMc = simulated.wMc();
    if (!report.iterations.empty()) report.iterations.back().status = ToString(status);
    return report;
  };

  if (RobotResult r = robot.Connect(); !r.ok()) {
    return finish(ServoRunStatus::kError, "cannot connect the robot: " + r.message);
  }
  StopGuard guard(robot, hooks);
  if (RobotResult r = robot.Enable(); !r.ok()) {
    return finish(ServoRunStatus::kError, "cannot enable the robot: " + r.message);
  }

  const ServoLoopOptions& loop = config.servo;
  const bool velocity = loop.law.mode == ServoMode::kVelocity;
  const auto start = std::chrono::steady_clock::now();
  std::optional<vpHomogeneousMatrix> previous_cMo;
  vpHomogeneousMatrix previous_wMc;
  log << "iter     X mm     Y mm     Z mm    pitch     roll   err mm   err deg  status\n";
  for (int iteration = 0;; ++iteration) {
    if ((hooks.interrupt != nullptr && hooks.interrupt->load()) || robot.EmergencyStopRequested()) {
      robot.RequestEmergencyStop();
      return finish(
          ServoRunStatus::kInterrupted,
          "interrupted (Ctrl-C) after " + std::to_string(iteration) + " iterations; robot stopped");
    }
    const double elapsed_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (elapsed_s > loop.max_time_s) {
      return finish(ServoRunStatus::kTimeLimit,
                    "time limit: " + Fixed(elapsed_s, 2) + " s > servo.max_time_s = " +
                        Fixed(loop.max_time_s, 2) + " s without converging");
    }
    if (iteration >= loop.max_iterations) {
      return finish(ServoRunStatus::kIterationLimit, "iteration limit: servo.max_iterations = " +
                                                         std::to_string(loop.max_iterations) +
                                                         " frames without converging");
    }

    const RobotPose read = robot.GetPosition(RobotFrame::kCamera);
    if (!read.result.ok()) {
      return finish(ServoRunStatus::kError, "cannot read the camera pose: " + read.result.message);
    }
    const vpHomogeneousMatrix wMc = read.pose;
    const vpHomogeneousMatrix true_cMo = wMc.inverse() * config.target_wMo;

    ServoIteration row;
    row.iteration = iteration;
    Table3Columns(wMc, &row.x_mm, &row.y_mm, &row.z_mm, &row.pitch_deg, &row.roll_deg);
    const PoseDistance truth =
        Distance(config.goal_cdMo * true_cMo.inverse(), vpHomogeneousMatrix());
    row.true_translation_error_mm = truth.translation_m * 1e3;
    row.true_rotation_error_deg = vpMath::deg(truth.rotation_rad);
    row.translation_error_mm = std::numeric_limits<double>::quiet_NaN();
    row.rotation_error_deg = std::numeric_limits<double>::quiet_NaN();
    row.status = "running";
    report.iterations.push_back(row);

    const RenderedFrame frame = renderer.Render(true_cMo, kNoiseSeed + iteration);
    const std::vector<DetectedLine>& lines = detector.Detect(ViewOf(frame.image));
    const PoseResult pose = EstimatePose(lines, config.target, pose_options, previous_cMo);
    if (pose.status != PoseStatus::kOk) {
      LogRow(report.iterations.back(), log);
      return finish(
          ServoRunStatus::kTargetLost,
          "target lost at iteration " + std::to_string(iteration) + ": " + ToString(pose.status) +
              (pose.message.empty() ? "" : " (" + pose.message + ")") + "; robot stopped");
    }
    if (previous_cMo) {
      const vpHomogeneousMatrix predicted = wMc.inverse() * previous_wMc * *previous_cMo;
      const PoseDistance jump = Distance(predicted, pose.cMo);
      if (jump.translation_m > loop.max_pose_jump_m ||
          vpMath::deg(jump.rotation_rad) > loop.max_pose_jump_deg) {
        LogRow(report.iterations.back(), log);
        return finish(ServoRunStatus::kPoseJump,
                      "pose jump at iteration " + std::to_string(iteration) + ": the estimate is " +
                          Fixed(jump.translation_m * 1e3, 1) + " mm and " +
                          Fixed(vpMath::deg(jump.rotation_rad), 2) +
                          " deg from the previous one moved by the robot (limits " +
                          Fixed(loop.max_pose_jump_m * 1e3, 1) + " mm, " +
                          Fixed(loop.max_pose_jump_deg, 2) + " deg); robot stopped");
      }
    }
    previous_cMo = pose.cMo;
    previous_wMc = wMc;

    const ServoStep step = ComputeServoStep(pose.cMo, config.goal_cdMo, loop.law);
    report.iterations.back().translation_error_mm = step.translation_error_m * 1e3;
    report.iterations.back().rotation_error_deg = vpMath::deg(step.rotation_error_rad);
    if (step.status == ServoStatus::kConverged) {
      report.iterations.back().status = "converged";
      LogRow(report.iterations.back(), log);
      return finish(ServoRunStatus::kConverged,
                    "converged in " + std::to_string(iteration) + " moves: estimated error " +
                        Fixed(step.translation_error_m * 1e3, 3) + " mm, " +
                        Fixed(vpMath::deg(step.rotation_error_rad), 4) + " deg");
    }
    LogRow(report.iterations.back(), log);

    RobotResult moved;
    if (velocity) {
      moved = robot.SetVelocity(RobotFrame::kCamera, step.twist).result;
    } else {
      moved = robot.MovePosition(RobotFrame::kCamera, wMc * step.c_T_cnew).result;
    }
    ++report.moves;
    if (!moved.ok()) {
      const ServoRunStatus status = StatusOfRefusal(moved, robot);
      if (status == ServoRunStatus::kInterrupted) {
        return finish(status, "interrupted (Ctrl-C) during the move of iteration " +
                                  std::to_string(iteration) + "; robot stopped");
      }
      return finish(status, ToString(status) + " at iteration " + std::to_string(iteration) + ": " +
                                moved.message + "; robot stopped");
    }
  }
}

}  // namespace oal
