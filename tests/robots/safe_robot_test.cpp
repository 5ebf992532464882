// The SafeRobot runner on the simulated camera: saturation, workspace box (targets and whole
// paths), stop-on-error, idempotent Stop(), the emergency flag, position moves.
#include "robots/safe_robot.h"

#include <gtest/gtest.h>
#include <visp3/core/vpExponentialMap.h>
#include <visp3/core/vpMath.h>

#include <algorithm>
#include <functional>
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

// A simulated camera behind a driver that counts what it is told and runs the test's hooks:
// during Enable() (a Ctrl-C while CON runs), after each poll (a Ctrl-C during a move). Its
// moves may follow a path that bulges out along +x (bulge_x_m at mid-way) from the simulated
// camera's screw, as a joint-interpolated arm's does.
class HookedRobot final : public Robot {
 public:
  explicit HookedRobot(SimulatedCamera& camera) : camera_(camera) {}

  std::string Name() const override { return "hooked-" + camera_.Name(); }
  RobotCapabilities Capabilities() const override { return camera_.Capabilities(); }
  RobotResult Connect() override { return camera_.Connect(); }
  RobotResult Enable() override {
    if (enable_fails) return RobotResult::Fail(RobotStatus::kError, "CON failed");
    const RobotResult r = camera_.Enable();
    if (on_enable) on_enable();
    return r;
  }
  RobotResult Disable() noexcept override { return camera_.Disable(); }
  RobotResult Stop() noexcept override {
    ++stops;
    return camera_.Stop();
  }
  RobotPose GetPosition(RobotFrame frame) override { return camera_.GetPosition(frame); }
  RobotResult StartMove(RobotFrame frame, const vpHomogeneousMatrix& target) override {
    ++start_moves;
    return camera_.StartMove(frame, target);
  }
  MoveProgress PollMove() override {
    const MoveProgress p = camera_.PollMove();
    ++polls;
    if (on_poll) on_poll(polls);
    return p;
  }
  RobotResult SetVelocity(RobotFrame frame, const vpColVector& v) override {
    return camera_.SetVelocity(frame, v);
  }
  RobotPose NearestReachable(RobotFrame frame, const vpHomogeneousMatrix& target) override {
    return camera_.NearestReachable(frame, target);
  }
  RobotPose PoseAlongMove(RobotFrame frame, const vpHomogeneousMatrix& from,
                          const vpHomogeneousMatrix& target, double fraction) const override {
    RobotPose p = Robot::PoseAlongMove(frame, from, target, fraction);
    p.pose[0][3] += 4 * bulge_x_m * fraction * (1 - fraction);
    return p;
  }
  vpHomogeneousMatrix eMc() const override { return camera_.eMc(); }

  std::function<void()> on_enable;
  std::function<void(int polls)> on_poll;
  double bulge_x_m = 0;
  bool enable_fails = false;
  int start_moves = 0;
  int polls = 0;
  int stops = 0;

 private:
  SimulatedCamera& camera_;
};

// A HookedRobot on a camera at (0, 0, 0.5) m moving in 10 polls, behind a runner, connected
// (not enabled: a test may want to hook Enable()); same box as Rig.
struct HookedRig {
  HookedRig() {
    SimulatedCameraOptions sim = Rig::SimDefaults();
    sim.move_mode = SimulatedCameraOptions::MoveMode::kIntegrate;
    sim.move_duration_s = 1.0;
    camera = std::make_unique<SimulatedCamera>(sim);
    driver = std::make_unique<HookedRobot>(*camera);
    robot = std::make_unique<SafeRobot>(*driver, Rig::Defaults());
    EXPECT_TRUE(robot->Connect().ok());
  }
  std::unique_ptr<SimulatedCamera> camera;
  std::unique_ptr<HookedRobot> driver;
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
  // Nothing was sent: a zero twist, a 6-vector all the same (copied without a null memcpy).
  ASSERT_EQ(next.twist.size(), 6u);
  EXPECT_EQ(next.twist.frobeniusNorm(), 0.0);
  const CycleReport copy = next;
  EXPECT_EQ(copy.twist.size(), 6u);
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

TEST(SafeRobot, EmergencyFlagSetBeforeAMoveSendsNothing) {
  HookedRig rig;
  ASSERT_TRUE(rig.robot->Enable().ok());
  rig.robot->RequestEmergencyStop();
  const vpHomogeneousMatrix before = rig.camera->wMc();
  const MoveReport report =
      rig.robot->MovePosition(RobotFrame::kCamera, vpHomogeneousMatrix(0.1, 0, 0.5, 0, 0, 0));
  EXPECT_EQ(report.result.status, RobotStatus::kStopped);
  EXPECT_EQ(report.polls, 0);
  EXPECT_EQ(rig.driver->start_moves, 0);
  EXPECT_TRUE(SamePose(rig.camera->wMc(), before, 0));
}

TEST(SafeRobot, EmergencyFlagStopsAMoveBetweenPolls) {
  HookedRig rig;
  ASSERT_TRUE(rig.robot->Enable().ok());
  // What the SIGINT handler does while the move runs: after the 3rd of its 10 polls.
  rig.driver->on_poll = [&](int polls) {
    if (polls == 3) rig.robot->RequestEmergencyStop();
  };
  const MoveReport report =
      rig.robot->MovePosition(RobotFrame::kCamera, vpHomogeneousMatrix(0.1, 0, 0.5, 0, 0, 0));
  EXPECT_EQ(report.result.status, RobotStatus::kStopped);
  EXPECT_NE(report.result.message.find("emergency stop"), std::string::npos)
      << report.result.message;
  EXPECT_EQ(rig.driver->start_moves, 1);
  EXPECT_EQ(report.polls, 3);  // the next cycle saw the flag: no 4th poll
  EXPECT_EQ(rig.driver->polls, 3);
  EXPECT_GE(rig.driver->stops, 1);  // the runner stopped the driver
  EXPECT_FALSE(rig.camera->moving());
  EXPECT_EQ(rig.robot->state(), SafeRobotState::kStopped);
  EXPECT_EQ(rig.robot->stop_reason().status, RobotStatus::kStopped);
  // Stopped on the way: 3 of the 10 steps along x, and there it stays.
  EXPECT_NEAR(rig.camera->wMc()[0][3], 0.03, 1e-9);
  EXPECT_TRUE(rig.camera->PollMove().done);
  EXPECT_NEAR(rig.camera->wMc()[0][3], 0.03, 1e-9);
}

TEST(SafeRobot, EmergencyRequestedWhileEnablingSurvivesEnable) {
  HookedRig rig;
  // A Ctrl-C while CON runs.
  rig.driver->on_enable = [&] { rig.robot->RequestEmergencyStop(); };
  ASSERT_TRUE(rig.robot->Enable().ok());
  EXPECT_TRUE(rig.robot->EmergencyStopRequested());
  const vpHomogeneousMatrix before = rig.camera->wMc();
  const MoveReport refused =
      rig.robot->MovePosition(RobotFrame::kCamera, vpHomogeneousMatrix(0.1, 0, 0.5, 0, 0, 0));
  EXPECT_EQ(refused.result.status, RobotStatus::kStopped);
  EXPECT_NE(refused.result.message.find("emergency stop"), std::string::npos)
      << refused.result.message;
  EXPECT_EQ(rig.driver->start_moves, 0);
  EXPECT_EQ(rig.robot->state(), SafeRobotState::kStopped);
  // Still refused, until the caller enables again (now without a request during it).
  EXPECT_EQ(
      rig.robot->SetVelocity(RobotFrame::kCamera, vpColVector({0, 0, 0.1, 0, 0, 0})).result.status,
      RobotStatus::kStopped);
  EXPECT_TRUE(SamePose(rig.camera->wMc(), before, 0));
  rig.driver->on_enable = nullptr;
  ASSERT_TRUE(rig.robot->Enable().ok());
  EXPECT_FALSE(rig.robot->EmergencyStopRequested());
  const MoveReport moved =
      rig.robot->MovePosition(RobotFrame::kCamera, vpHomogeneousMatrix(0.1, 0, 0.5, 0, 0, 0));
  EXPECT_TRUE(moved.result.ok()) << moved.result.message;
}

TEST(SafeRobot, EmergencyRequestedBeforeAFailedEnableIsKept) {
  HookedRig rig;
  ASSERT_TRUE(rig.robot->Enable().ok());
  rig.robot->RequestEmergencyStop();
  rig.driver->enable_fails = true;
  EXPECT_EQ(rig.robot->Enable().status, RobotStatus::kError);
  EXPECT_TRUE(rig.robot->EmergencyStopRequested());
  rig.driver->enable_fails = false;
  ASSERT_TRUE(rig.robot->Enable().ok());
  EXPECT_FALSE(rig.robot->EmergencyStopRequested());
}

// The default path of a move is the screw the simulated camera integrates: at every poll the
// camera is where PoseAlongMove() says.
TEST(SafeRobot, DefaultPathIsTheSimulatedCamerasScrew) {
  SimulatedCameraOptions sim = Rig::SimDefaults();
  sim.move_mode = SimulatedCameraOptions::MoveMode::kIntegrate;
  sim.move_duration_s = 1.0;  // 10 polls
  sim.eMc = vpHomogeneousMatrix(0.02, 0, 0.1, 0, 0, vpMath::rad(90));
  SimulatedCamera camera(sim);
  ASSERT_TRUE(camera.Connect().ok());
  ASSERT_TRUE(camera.Enable().ok());
  for (const RobotFrame frame : {RobotFrame::kCamera, RobotFrame::kEndEffector}) {
    const vpHomogeneousMatrix from = camera.GetPosition(frame).pose;
    const vpHomogeneousMatrix target =
        from * vpHomogeneousMatrix(0.1, -0.05, 0.08, vpMath::rad(10), vpMath::rad(-20), 0.9);
    ASSERT_TRUE(camera.StartMove(frame, target).ok());
    for (int k = 1; k <= 10; ++k) {
      ASSERT_TRUE(camera.PollMove().result.ok());
      const RobotPose expected = camera.PoseAlongMove(frame, from, target, k / 10.0);
      ASSERT_TRUE(expected.result.ok());
      EXPECT_TRUE(SamePose(camera.GetPosition(frame).pose, expected.pose, 1e-9))
          << ToString(frame) << " poll " << k;
    }
    EXPECT_TRUE(SamePose(camera.PoseAlongMove(frame, from, target, 0).pose, from, 1e-12));
  }
}

// Both ends in the box, the path not: refused before anything is sent.
TEST(SafeRobot, MoveWhosePathLeavesTheBoxIsRefusedBeforeAnythingIsSent) {
  HookedRig rig;
  ASSERT_TRUE(rig.robot->Enable().ok());
  rig.camera->SetPose(vpHomogeneousMatrix(0.4, -0.3, 0.5, 0, 0, 0));
  rig.driver->bulge_x_m = 0.2;  // x = 0.6 m mid-way; the box ends at 0.5 m
  const vpHomogeneousMatrix before = rig.camera->wMc();
  const MoveReport report =
      rig.robot->MovePosition(RobotFrame::kCamera, vpHomogeneousMatrix(0.4, 0.3, 0.5, 0, 0, 0));
  EXPECT_EQ(report.result.status, RobotStatus::kWorkspace);
  // The first sample outside: x = 0.4 + 0.8 f (1 - f) > 0.5 from f = 0.146 on.
  EXPECT_NE(report.result.message.find("the move's path, at 0.15"), std::string::npos)
      << report.result.message;
  EXPECT_NE(report.result.message.find("of the way, would take the camera to x = 0.50"),
            std::string::npos)
      << report.result.message;
  EXPECT_NE(report.result.message.find("outside the workspace box [-0.5, 0.5] m"),
            std::string::npos)
      << report.result.message;
  EXPECT_EQ(rig.driver->start_moves, 0);
  EXPECT_EQ(report.polls, 0);
  EXPECT_FALSE(rig.camera->moving());
  EXPECT_TRUE(SamePose(rig.camera->wMc(), before, 0));
  EXPECT_EQ(rig.robot->state(), SafeRobotState::kStopped);
  EXPECT_EQ(rig.robot->stop_reason().status, RobotStatus::kWorkspace);
  // The same move on a straight path is fine.
  rig.driver->bulge_x_m = 0;
  ASSERT_TRUE(rig.robot->Enable().ok());
  const MoveReport straight =
      rig.robot->MovePosition(RobotFrame::kCamera, vpHomogeneousMatrix(0.4, 0.3, 0.5, 0, 0, 0));
  EXPECT_TRUE(straight.result.ok()) << straight.result.message;
  EXPECT_EQ(rig.driver->start_moves, 1);
}

// The simulated camera's own screw swings out of the box when the camera turns while it
// crosses: refused, where a check of the target alone let it go.
TEST(SafeRobot, ScrewMoveSwingingOutOfTheBoxIsRefused) {
  HookedRig rig;
  ASSERT_TRUE(rig.robot->Enable().ok());
  rig.camera->SetPose(vpHomogeneousMatrix(0.45, -0.3, 0.5, 0, 0, 0));
  const vpHomogeneousMatrix from = rig.camera->wMc();
  const vpHomogeneousMatrix target(0.45, 0.3, 0.5, 0, 0, vpMath::rad(120));
  double max_x = 0;
  for (int k = 0; k <= 100; ++k) {
    max_x = std::max(
        max_x, rig.camera->PoseAlongMove(RobotFrame::kCamera, from, target, k / 100.0).pose[0][3]);
  }
  ASSERT_GT(max_x, 0.55);  // the precondition: the path leaves the box (x <= 0.5)
  const MoveReport report = rig.robot->MovePosition(RobotFrame::kCamera, target);
  EXPECT_EQ(report.result.status, RobotStatus::kWorkspace);
  EXPECT_NE(report.result.message.find("the move's path, at "), std::string::npos)
      << report.result.message;
  EXPECT_EQ(rig.driver->start_moves, 0);
  EXPECT_FALSE(rig.camera->moving());
  EXPECT_TRUE(SamePose(rig.camera->wMc(), from, 0));
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
