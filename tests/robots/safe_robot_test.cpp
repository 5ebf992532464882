// The SafeRobot runner on the simulated camera: saturation, workspace box, stop-on-error,
// idempotent Stop(), the emergency flag, position moves.
#include "robots/safe_robot.h"

#include <gtest/gtest.h>
#include <visp3/core/vpExponentialMap.h>
#include <visp3/core/vpMath.h>

#include <memory>
#include <stdexcept>

#include "robots/simulated_camera.h"

namespace oal {
namespace {

constexpr double kTol = 1e-12;

bool SamePose(const vpHomogeneousMatrix& a, const vpHomogeneousMatrix& b, double tol = kTol) {
  const PoseDistance d = Distance(a, b);
  return d.translation_m <= tol && d.rotation_rad <= tol;
}

// A simulated camera at (0, 0, 0.5) m behind its runner, connected and enabled; workspace box
// [-0.5, 0.5] x [-0.5, 0.5] x [0.2, 1.0] m.
struct Rig {
  explicit Rig(SafetyOptions safety = Defaults(),
               SimulatedCameraOptions sim_options = SimDefaults()) {
    camera = std::make_unique<SimulatedCamera>(sim_options);
    robot = std::make_unique<SafeRobot>(*camera, safety);
    EXPECT_TRUE(robot->Connect().ok());
    EXPECT_TRUE(robot->Enable().ok());
  }
  static SafetyOptions Defaults() {
    SafetyOptions o;
    o.max_translation_mps = 0.2;
    o.max_rotation_radps = 0.5;
    o.workspace_min_m = {-0.5, -0.5, 0.2};
    o.workspace_max_m = {0.5, 0.5, 1.0};
    return o;
  }
  static SimulatedCameraOptions SimDefaults() {
    SimulatedCameraOptions o;
    o.sampling_time_s = 0.1;
    o.wMc = vpHomogeneousMatrix(0, 0, 0.5, 0, 0, 0);
    return o;
  }
  std::unique_ptr<SimulatedCamera> camera;
  std::unique_ptr<SafeRobot> robot;
};

TEST(SafeRobot, SaturationScalesTheTwistKeepingItsDirection) {
  Rig rig;
  const vpColVector request({0.1, -0.4, 0.05, 0.2, 0.0, 0.25});  // vy twice its limit
  const vpHomogeneousMatrix before = rig.camera->wMc();
  const CycleReport report = rig.robot->SetVelocity(RobotFrame::kCamera, request);
  ASSERT_TRUE(report.result.ok()) << report.result.message;
  EXPECT_TRUE(report.saturated);
  EXPECT_DOUBLE_EQ(report.scale, 0.5);
  EXPECT_EQ(report.limiting_axis, 1);
  for (unsigned i = 0; i < 6; ++i) EXPECT_NEAR(report.twist[i], 0.5 * request[i], kTol) << i;
  EXPECT_TRUE(SamePose(rig.camera->wMc(), before * vpExponentialMap::direct(report.twist, 0.1)));
}

TEST(SafeRobot, TwistWithinLimitsIsSentUnchanged) {
  Rig rig;
  const vpColVector request({0.1, -0.2, 0.05, 0.5, 0.0, -0.25});
  const CycleReport report = rig.robot->SetVelocity(RobotFrame::kCamera, request);
  ASSERT_TRUE(report.result.ok());
  EXPECT_FALSE(report.saturated);
  EXPECT_EQ(report.scale, 1.0);
  EXPECT_EQ(report.limiting_axis, -1);
  for (unsigned i = 0; i < 6; ++i) EXPECT_EQ(report.twist[i], request[i]);
}

TEST(SafeRobot, VelocityLeavingTheWorkspaceIsRefusedAndTheRobotStaysPutAndStopped) {
  SimulatedCameraOptions sim = Rig::SimDefaults();
  sim.wMc = vpHomogeneousMatrix(0, 0, 0.21, 0, 0, 0);  // 1 cm above the box's floor
  Rig rig(Rig::Defaults(), sim);
  const vpHomogeneousMatrix before = rig.camera->wMc();
  // Camera z is world z here: -0.2 m/s for 0.1 s would reach z = 0.19 m.
  const CycleReport report =
      rig.robot->SetVelocity(RobotFrame::kCamera, vpColVector({0, 0, -0.2, 0, 0, 0}));
  EXPECT_EQ(report.result.status, RobotStatus::kWorkspace);
  EXPECT_NE(report.result.message.find("z = 0.19"), std::string::npos) << report.result.message;
  EXPECT_NE(report.result.message.find("[0.2, 1]"), std::string::npos) << report.result.message;
  EXPECT_TRUE(SamePose(rig.camera->wMc(), before, 0));
  EXPECT_EQ(rig.robot->state(), SafeRobotState::kStopped);
  EXPECT_EQ(rig.robot->stop_reason().status, RobotStatus::kWorkspace);
  // Even a harmless command is now refused, with the reason.
  const CycleReport next =
      rig.robot->SetVelocity(RobotFrame::kCamera, vpColVector({0, 0, 0.1, 0, 0, 0}));
  EXPECT_EQ(next.result.status, RobotStatus::kStopped);
  EXPECT_NE(next.result.message.find("workspace box"), std::string::npos) << next.result.message;
  EXPECT_TRUE(SamePose(rig.camera->wMc(), before, 0));
}

TEST(SafeRobot, MoveTargetOutsideTheWorkspaceIsRefused) {
  Rig rig;
  const vpHomogeneousMatrix before = rig.camera->wMc();
  const MoveReport report =
      rig.robot->MovePosition(RobotFrame::kCamera, vpHomogeneousMatrix(0.7, 0, 0.5, 0, 0, 0));
  EXPECT_EQ(report.result.status, RobotStatus::kWorkspace);
  EXPECT_NE(report.result.message.find("x = 0.7"), std::string::npos) << report.result.message;
  EXPECT_EQ(report.polls, 0);
  EXPECT_TRUE(SamePose(rig.camera->wMc(), before, 0));
  EXPECT_EQ(rig.robot->state(), SafeRobotState::kStopped);
}

TEST(SafeRobot, InjectedErrorStopsTheRobotUntilReEnabled) {
  Rig rig;
  rig.camera->InjectFault(RobotStatus::kError, "controller error 317 BAD CARTESIAN POINT");
  const CycleReport failed =
      rig.robot->SetVelocity(RobotFrame::kCamera, vpColVector({0, 0, 0.1, 0, 0, 0}));
  EXPECT_EQ(failed.result.status, RobotStatus::kError);
  EXPECT_EQ(rig.robot->state(), SafeRobotState::kStopped);
  const vpHomogeneousMatrix stopped_at = rig.camera->wMc();
  for (int k = 0; k < 3; ++k) {
    const CycleReport refused =
        rig.robot->SetVelocity(RobotFrame::kCamera, vpColVector({0, 0, 0.1, 0, 0, 0}));
    EXPECT_EQ(refused.result.status, RobotStatus::kStopped);
    EXPECT_NE(refused.result.message.find("317 BAD CARTESIAN POINT"), std::string::npos)
        << refused.result.message;
  }
  const MoveReport move =
      rig.robot->MovePosition(RobotFrame::kCamera, vpHomogeneousMatrix(0, 0, 0.6, 0, 0, 0));
  EXPECT_EQ(move.result.status, RobotStatus::kStopped);
  EXPECT_TRUE(SamePose(rig.camera->wMc(), stopped_at, 0));
  ASSERT_TRUE(rig.robot->Enable().ok());
  EXPECT_TRUE(rig.robot->stop_reason().ok());
  EXPECT_TRUE(
      rig.robot->SetVelocity(RobotFrame::kCamera, vpColVector({0, 0, 0.1, 0, 0, 0})).result.ok());
  EXPECT_FALSE(SamePose(rig.camera->wMc(), stopped_at, 0));
}

TEST(SafeRobot, ErrorDuringAMoveStopsItWhereItIs) {
  SimulatedCameraOptions sim = Rig::SimDefaults();
  sim.move_mode = SimulatedCameraOptions::MoveMode::kIntegrate;
  sim.move_duration_s = 1.0;  // 10 polls
  Rig rig(Rig::Defaults(), sim);
  const vpHomogeneousMatrix start = rig.camera->wMc();
  // StartMove and 3 polls succeed, the 4th poll fails.
  rig.camera->InjectFault(RobotStatus::kError, "impact protection axis 2", 4);
  const MoveReport report =
      rig.robot->MovePosition(RobotFrame::kCamera, vpHomogeneousMatrix(0.1, 0, 0.5, 0, 0, 0));
  EXPECT_EQ(report.result.status, RobotStatus::kError);
  EXPECT_EQ(report.result.message, "impact protection axis 2");
  EXPECT_EQ(report.polls, 4);
  EXPECT_EQ(rig.robot->state(), SafeRobotState::kStopped);
  EXPECT_FALSE(rig.camera->moving());
  const vpHomogeneousMatrix stopped_at = rig.camera->wMc();
  EXPECT_NEAR(stopped_at[0][3], 0.03, 1e-9);  // 3 of 10 steps along x
  EXPECT_FALSE(SamePose(stopped_at, start, 0));
  // Polling the driver again does not resume the move.
  EXPECT_TRUE(rig.camera->PollMove().done);
  EXPECT_TRUE(SamePose(rig.camera->wMc(), stopped_at, 0));
}

TEST(SafeRobot, StopIsIdempotentAndSafeInAnyState) {
  SimulatedCamera camera;
  SafeRobot robot(camera, SafetyOptions());
  EXPECT_TRUE(robot.Stop().ok());  // before Connect()
  EXPECT_EQ(robot.state(), SafeRobotState::kDisconnected);
  ASSERT_TRUE(robot.Connect().ok());
  ASSERT_TRUE(robot.Enable().ok());
  const vpHomogeneousMatrix before = camera.wMc();
  for (int k = 0; k < 3; ++k) {
    EXPECT_TRUE(robot.Stop().ok());
    EXPECT_EQ(robot.state(), SafeRobotState::kStopped);
    EXPECT_EQ(robot.stop_reason().message, "Stop() called");
  }
  EXPECT_TRUE(SamePose(camera.wMc(), before, 0));
  EXPECT_TRUE(robot.Disable().ok());
  EXPECT_TRUE(robot.Disable().ok());
  EXPECT_TRUE(robot.Stop().ok());
  EXPECT_EQ(robot.state(), SafeRobotState::kDisabled);
}

TEST(SafeRobot, EmergencyFlagStopsTheNextCycle) {
  Rig rig;
  ASSERT_TRUE(
      rig.robot->SetVelocity(RobotFrame::kCamera, vpColVector({0, 0, 0.1, 0, 0, 0})).result.ok());
  rig.robot->RequestEmergencyStop();  // what a SIGINT handler does
  rig.robot->RequestEmergencyStop();
  const vpHomogeneousMatrix before = rig.camera->wMc();
  const CycleReport report =
      rig.robot->SetVelocity(RobotFrame::kCamera, vpColVector({0, 0, 0.1, 0, 0, 0}));
  EXPECT_EQ(report.result.status, RobotStatus::kStopped);
  EXPECT_NE(report.result.message.find("emergency stop"), std::string::npos)
      << report.result.message;
  EXPECT_TRUE(SamePose(rig.camera->wMc(), before, 0));
  EXPECT_EQ(rig.robot->state(), SafeRobotState::kStopped);
  ASSERT_TRUE(rig.robot->Enable().ok());
  EXPECT_FALSE(rig.robot->EmergencyStopRequested());
  EXPECT_TRUE(
      rig.robot->SetVelocity(RobotFrame::kCamera, vpColVector({0, 0, 0.1, 0, 0, 0})).result.ok());
}

TEST(SafeRobot, PositionMoveReachesTheTarget) {
  for (const auto mode :
       {SimulatedCameraOptions::MoveMode::kJump, SimulatedCameraOptions::MoveMode::kIntegrate}) {
    SimulatedCameraOptions sim = Rig::SimDefaults();
    sim.move_mode = mode;
    sim.move_duration_s = 1.0;
    Rig rig(Rig::Defaults(), sim);
    const vpHomogeneousMatrix target(0.1, -0.05, 0.6, vpMath::rad(5), vpMath::rad(-10), 0.2);
    const MoveReport report = rig.robot->MovePosition(RobotFrame::kCamera, target);
    ASSERT_TRUE(report.result.ok()) << report.result.message;
    EXPECT_TRUE(SamePose(report.reached, target, 1e-9));
    EXPECT_TRUE(SamePose(rig.camera->wMc(), target, 1e-9));
    EXPECT_EQ(report.polls, mode == SimulatedCameraOptions::MoveMode::kJump ? 1 : 10);
    EXPECT_EQ(rig.robot->timing().cycles, report.polls);
    EXPECT_EQ(rig.robot->state(), SafeRobotState::kEnabled);
  }
}

TEST(SafeRobot, EndEffectorMoveGoesThroughTheHandEye) {
  SimulatedCameraOptions sim = Rig::SimDefaults();
  sim.eMc = vpHomogeneousMatrix(0, 0, 0.1, 0, 0, vpMath::rad(90));
  Rig rig(Rig::Defaults(), sim);
  const vpHomogeneousMatrix wMe(0.05, 0.0, 0.4, 0, 0, 0);
  const MoveReport report = rig.robot->MovePosition(RobotFrame::kEndEffector, wMe);
  ASSERT_TRUE(report.result.ok()) << report.result.message;
  EXPECT_TRUE(SamePose(rig.camera->wMc(), wMe * sim.eMc, 1e-9));
}

TEST(SafeRobot, EmergencyFlagStopsAMoveBetweenPolls) {
  SimulatedCameraOptions sim = Rig::SimDefaults();
  sim.move_mode = SimulatedCameraOptions::MoveMode::kIntegrate;
  Rig rig(Rig::Defaults(), sim);
  rig.robot->RequestEmergencyStop();
  const vpHomogeneousMatrix before = rig.camera->wMc();
  const MoveReport report =
      rig.robot->MovePosition(RobotFrame::kCamera, vpHomogeneousMatrix(0.1, 0, 0.5, 0, 0, 0));
  EXPECT_EQ(report.result.status, RobotStatus::kStopped);
  EXPECT_EQ(report.polls, 0);
  EXPECT_TRUE(SamePose(rig.camera->wMc(), before, 0));
}

TEST(SafeRobot, MoveThatTimesOutStops) {
  SafetyOptions safety = Rig::Defaults();
  safety.move_timeout_s = 0.5;  // 5 polls of 0.1 s; the move needs 10
  SimulatedCameraOptions sim = Rig::SimDefaults();
  sim.move_mode = SimulatedCameraOptions::MoveMode::kIntegrate;
  sim.move_duration_s = 1.0;
  Rig rig(safety, sim);
  const MoveReport report =
      rig.robot->MovePosition(RobotFrame::kCamera, vpHomogeneousMatrix(0.1, 0, 0.5, 0, 0, 0));
  EXPECT_EQ(report.result.status, RobotStatus::kTimeout);
  EXPECT_EQ(report.polls, 5);
  EXPECT_FALSE(rig.camera->moving());
  EXPECT_EQ(rig.robot->state(), SafeRobotState::kStopped);
}

TEST(SafeRobot, CommandsBeforeEnableAreRefused) {
  SimulatedCamera camera;
  SafeRobot robot(camera, SafetyOptions());
  EXPECT_EQ(robot.SetVelocity(RobotFrame::kCamera, vpColVector({0, 0, 0.1, 0, 0, 0})).result.status,
            RobotStatus::kNotReady);
  ASSERT_TRUE(robot.Connect().ok());
  EXPECT_EQ(robot.MovePosition(RobotFrame::kCamera, vpHomogeneousMatrix()).result.status,
            RobotStatus::kNotReady);
}

TEST(SafeRobot, OptionsCheckNamesTheField) {
  SafetyOptions o;
  o.workspace_min_m[2] = 2.0;
  try {
    o.Check();
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("workspace_min_m/workspace_max_m [z]"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace oal
