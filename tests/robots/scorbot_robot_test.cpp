// ScorbotRobot through SafeRobot against the Controller-A simulator on a real pty: moves that
// reach their targets, the 5-axis projection, Stop() during a move, controller errors with the
// controller's text, a silent controller, the port closed during a move, reconnection, a move
// whose joint-interpolated arc leaves the workspace box.
#include "robots/scorbot_robot.h"

#include <gtest/gtest.h>
#include <unistd.h>
#include <visp3/core/vpExponentialMap.h>
#include <visp3/core/vpMath.h>
#include <visp3/core/vpRzyxVector.h>

#include <cmath>
#include <stdexcept>
#include <thread>

#include "robots/safe_robot.h"
#include "scorbot_test_util.h"

namespace oal {
namespace {

using testing_scorbot::FastSim;
using testing_scorbot::WaitFor;

// The camera 5 cm ahead of the TCP along the tool axis, rotated 90 deg about it.
vpHomogeneousMatrix HandEye() {
  return vpHomogeneousMatrix(0, 0, 0.05, 0, 0, vpMath::rad(90));
}

ScorbotOptions RobotOptions(const std::string& port) {
  ScorbotOptions o;
  o.port = port;
  o.sampling_time_s = 0.01;
  o.reply_timeout_s = 1.0;
  o.move_timeout_s = 5.0;
  o.speed_percent = 100;
  o.eMc = HandEye();
  return o;
}

SafetyOptions Safety() {
  SafetyOptions s;
  s.workspace_min_m = {-0.2, -0.5, 0.05};
  s.workspace_max_m = {0.9, 0.5, 1.0};
  s.move_timeout_s = 10;
  return s;
}

struct Rig {
  explicit Rig(ScorbotSimOptions sim_options = FastSim()) : sim(sim_options) {
    sim.Start();
    robot = std::make_unique<ScorbotRobot>(RobotOptions(sim.ConnectPath()));
    safe = std::make_unique<SafeRobot>(*robot, Safety());
    const RobotResult c = safe->Connect();
    EXPECT_TRUE(c.ok()) << c.message;
    const RobotResult e = safe->Enable();
    EXPECT_TRUE(e.ok()) << e.message;
  }
  ScorbotControllerSim sim;
  std::unique_ptr<ScorbotRobot> robot;
  std::unique_ptr<SafeRobot> safe;
};

TEST(ScorbotRobot, ReadsThePoseFromTheControllerThroughTheKinematics) {
  Rig rig;
  const RobotPose e = rig.safe->GetPosition(RobotFrame::kEndEffector);
  ASSERT_TRUE(e.result.ok()) << e.result.message;
  const vpHomogeneousMatrix expected = ForwardKinematics(ScorbotGeometry(), rig.sim.joints());
  EXPECT_LE(Distance(e.pose, expected).translation_m, 1e-12);
  const RobotPose c = rig.safe->GetPosition(RobotFrame::kCamera);
  ASSERT_TRUE(c.result.ok());
  EXPECT_LE(Distance(c.pose, expected * HandEye()).translation_m, 1e-12);
  const RobotCapabilities caps = rig.robot->Capabilities();
  EXPECT_TRUE(caps.position);
  EXPECT_FALSE(caps.velocity);
  EXPECT_EQ(caps.dof, 5);
  const vpMatrix J = rig.robot->eJe();
  EXPECT_EQ(J.getRows(), 6u);
  EXPECT_EQ(J.getCols(), 5u);
}

// LISTPV prints the joints' counts and X Y Z P R: a reading whose two disagree (a garbled
// reply; here an arm whose upper arm is 2 cm longer than the driver believes) is refused, not
// taken for where the arm is.
TEST(ScorbotRobot, AReadingWhoseCountsAndCoordinatesDisagreeIsRefused) {
  ScorbotSimOptions longer_arm = FastSim();
  longer_arm.geometry.upper_arm_m += 0.02;
  ScorbotControllerSim sim(longer_arm);
  sim.Start();
  ScorbotRobot robot(RobotOptions(sim.ConnectPath()));
  ASSERT_TRUE(robot.Connect().ok());
  const RobotPose read = robot.GetPosition(RobotFrame::kEndEffector);
  EXPECT_EQ(read.result.status, RobotStatus::kError);
  EXPECT_NE(read.result.message.find("LISTPV POSITION disagrees with itself"), std::string::npos)
      << read.result.message;
  EXPECT_NE(read.result.message.find("position_check_mm"), std::string::npos);
  // Without the check the reading stands (through the driver's geometry).
  ScorbotOptions unchecked = RobotOptions(sim.ConnectPath());
  unchecked.position_check_mm = 0;
  robot.Disconnect();
  ScorbotRobot trusting(unchecked);
  ASSERT_TRUE(trusting.Connect().ok());
  EXPECT_TRUE(trusting.GetPosition(RobotFrame::kEndEffector).result.ok());
}

TEST(ScorbotRobot, SequenceOfCameraMovesReachesEveryTarget) {
  Rig rig;
  const RobotPose start = rig.safe->GetPosition(RobotFrame::kCamera);
  ASSERT_TRUE(start.result.ok());
  // Steps in the camera frame, including rotations 5 axes cannot follow exactly.
  const vpHomogeneousMatrix steps[] = {
      vpHomogeneousMatrix(0.02, 0, 0, 0, 0, 0),
      vpHomogeneousMatrix(0, 0.03, -0.02, 0, 0, 0),
      vpHomogeneousMatrix(0, 0, 0.01, vpMath::rad(5), vpMath::rad(-4), vpMath::rad(10)),
      vpHomogeneousMatrix(-0.04, 0.01, 0.0, 0, vpMath::rad(3), 0),
  };
  vpHomogeneousMatrix wMc = start.pose;
  for (const vpHomogeneousMatrix& step : steps) {
    const MoveReport report = rig.safe->MovePosition(RobotFrame::kCamera, wMc * step);
    ASSERT_TRUE(report.result.ok()) << report.result.message;
    EXPECT_GE(report.polls, 1);
    const PoseDistance d = Distance(report.target, report.reached);
    EXPECT_LE(d.translation_m, 1e-3);
    EXPECT_LE(d.rotation_rad, vpMath::rad(0.2));
    // The projected target keeps the requested camera position up to the ACL resolution.
    EXPECT_LE((report.target.getTranslationVector() - (wMc * step).getTranslationVector())
                  .frobeniusNorm(),
              2e-4);
    wMc = report.reached;
  }
  EXPECT_EQ(rig.sim.stats().moves_completed, 4);
  // Only the coordinates that changed were sent: fewer SETPVC than 5 per move is possible, and
  // the pose read by each poll served the runner's read.
  EXPECT_GT(rig.robot->link_stats().link.bytes_written, 0u);
}

TEST(ScorbotRobot, ClosedLoopConvergesToAReachableGoal) {
  // The exponential-map position law on poses alone (no camera): each iteration reads wMc and
  // moves by lambda times the error screw, projected onto what 5 axes reach.
  Rig rig;
  const RobotPose start = rig.safe->GetPosition(RobotFrame::kCamera);
  ASSERT_TRUE(start.result.ok());
  const RobotPose goal = rig.robot->NearestReachable(
      RobotFrame::kCamera,
      start.pose * vpHomogeneousMatrix(0.06, -0.04, 0.03, vpMath::rad(8), vpMath::rad(-6), 0.3));
  ASSERT_TRUE(goal.result.ok()) << goal.result.message;
  const double lambda = 0.6;
  int iterations = 0;
  PoseDistance error = Distance(start.pose, goal.pose);
  while (iterations < 30 && (error.translation_m > 1e-3 || error.rotation_rad > vpMath::rad(0.3))) {
    const RobotPose now = rig.safe->GetPosition(RobotFrame::kCamera);
    ASSERT_TRUE(now.result.ok()) << now.result.message;
    const vpColVector screw = vpExponentialMap::inverse(now.pose.inverse() * goal.pose, 1.0);
    const MoveReport move = rig.safe->MovePosition(
        RobotFrame::kCamera, now.pose * vpExponentialMap::direct(screw, lambda));
    ASSERT_TRUE(move.result.ok()) << "iteration " << iterations << ": " << move.result.message;
    error = Distance(move.reached, goal.pose);
    ++iterations;
  }
  EXPECT_LE(error.translation_m, 1e-3);
  EXPECT_LE(error.rotation_rad, vpMath::rad(0.3));
  EXPECT_LT(iterations, 30);
}

TEST(ScorbotRobot, StartMoveRefusesPosesFiveAxesCannotReach) {
  Rig rig;
  const RobotPose e = rig.safe->GetPosition(RobotFrame::kEndEffector);
  // The tool points down; tilting it sideways (about the world X axis) leaves the arm plane.
  vpHomogeneousMatrix tilted = e.pose;
  tilted.insert(vpRotationMatrix(vpRzyxVector(0, 0, vpMath::rad(10))) * e.pose.getRotationMatrix());
  const RobotResult r = rig.robot->StartMove(RobotFrame::kEndEffector, tilted);
  EXPECT_EQ(r.status, RobotStatus::kUnreachable);
  EXPECT_NE(r.message.find("NearestReachable"), std::string::npos) << r.message;
  // Out of the arm's reach: refused by NearestReachable, through the runner.
  const MoveReport far =
      rig.safe->MovePosition(RobotFrame::kEndEffector, vpHomogeneousMatrix(0.85, 0, 0.3, 0, 0, 0));
  EXPECT_EQ(far.result.status, RobotStatus::kUnreachable);
  EXPECT_EQ(rig.safe->state(), SafeRobotState::kStopped);
  EXPECT_EQ(rig.sim.stats().moves_started, 0);
}

// MOVE is joint-interpolated: from (0.79, 0.20) to (0.79, -0.20) m the base swings the tool at
// a radius of 0.815 m, out of scorbot-sim.yaml's box (x <= 0.80 m) mid-way though both ends
// are in it. The runner refuses it before anything is sent; with room for the arc it runs.
TEST(ScorbotRobot, MoveWhoseArcLeavesTheBoxIsRefusedBeforeAnythingIsSent) {
  const ScorbotGeometry geometry;
  const AclPose from_acl{7900, 2000, 4500, -100, 0};  // tool 10 deg below the horizontal
  const AclPose to_acl{7900, -2000, 4500, -100, 0};
  const ScorbotIk start = InverseKinematics(geometry, FromAclPose(from_acl));
  ASSERT_TRUE(start.ok) << start.why;
  ScorbotSimOptions sim_options = FastSim();
  for (int i = 0; i < 5; ++i) sim_options.start_deg[i] = vpMath::deg(start.q[i]);
  const vpHomogeneousMatrix eMc(0, 0, 0, 0, 0, vpMath::rad(90));  // as scorbot-sim.yaml
  for (const double x_max : {0.80, 0.82}) {
    ScorbotControllerSim sim(sim_options);
    sim.Start();
    ScorbotOptions o = RobotOptions(sim.DevicePath());
    o.eMc = eMc;
    ScorbotRobot robot(o);
    SafetyOptions safety = Safety();
    safety.workspace_min_m = {0.25, -0.30, 0.30};  // scorbot-sim.yaml's box
    safety.workspace_max_m = {x_max, 0.30, 0.90};
    safety.reach_tolerance_rad = 0.005;
    SafeRobot safe(robot, safety);
    ASSERT_TRUE(safe.Connect().ok());
    ASSERT_TRUE(safe.Enable().ok());
    const RobotPose from = safe.GetPosition(RobotFrame::kCamera);
    ASSERT_TRUE(from.result.ok()) << from.result.message;
    const vpHomogeneousMatrix target = FromAclPose(to_acl) * eMc;
    // The straight chord stays at x = 0.79 m; the arc does not.
    const RobotPose mid = robot.PoseAlongMove(RobotFrame::kCamera, from.pose, target, 0.5);
    ASSERT_TRUE(mid.result.ok()) << mid.result.message;
    EXPECT_NEAR(mid.pose[0][3], std::hypot(0.79, 0.20), 1e-3);
    EXPECT_NEAR(mid.pose[1][3], 0, 2e-4);  // the start is read through the encoders
    const ScorbotJoints before = sim.joints();
    const MoveReport report = safe.MovePosition(RobotFrame::kCamera, target);
    if (x_max < 0.81) {
      EXPECT_EQ(report.result.status, RobotStatus::kWorkspace);
      EXPECT_NE(report.result.message.find("the move's path, at 0."), std::string::npos)
          << report.result.message;
      EXPECT_NE(report.result.message.find("would take the camera to x = 0.80"), std::string::npos)
          << report.result.message;
      EXPECT_NE(report.result.message.find("outside the workspace box [0.25, 0.8] m"),
                std::string::npos)
          << report.result.message;
      EXPECT_EQ(report.polls, 0);
      EXPECT_EQ(sim.stats().moves_started, 0);
      EXPECT_FALSE(sim.moving());
      EXPECT_EQ(sim.joints(), before);
      EXPECT_EQ(safe.state(), SafeRobotState::kStopped);
    } else {
      EXPECT_TRUE(report.result.ok()) << report.result.message;
      EXPECT_EQ(sim.stats().moves_completed, 1);
      EXPECT_LE(Distance(report.reached, target).translation_m, 1e-3);
    }
  }
}

TEST(ScorbotRobot, StopAbortsAMove) {
  ScorbotControllerSim sim(FastSim());
  sim.Start();
  ScorbotOptions o = RobotOptions(sim.DevicePath());
  o.speed_percent = 2;  // a move of seconds even at the test's time scale
  ScorbotRobot robot(o);
  ASSERT_TRUE(robot.Connect().ok());
  ASSERT_TRUE(robot.Enable().ok());
  EXPECT_EQ(sim.speed_percent(), 2);
  const RobotPose e = robot.GetPosition(RobotFrame::kEndEffector);
  ASSERT_TRUE(e.result.ok());
  const RobotPose target = robot.NearestReachable(
      RobotFrame::kEndEffector, vpHomogeneousMatrix(0, 0.15, 0, 0, 0, 0) * e.pose);
  ASSERT_TRUE(target.result.ok()) << target.result.message;
  ASSERT_TRUE(robot.StartMove(RobotFrame::kEndEffector, target.pose).ok());
  ASSERT_TRUE(sim.moving());
  const MoveProgress p = robot.PollMove();
  ASSERT_TRUE(p.result.ok()) << p.result.message;
  EXPECT_FALSE(p.done);
  EXPECT_TRUE(robot.Stop().ok());
  EXPECT_FALSE(sim.moving());
  const ScorbotJoints at = sim.joints();
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(sim.joints(), at);
  EXPECT_TRUE(robot.PollMove().done);  // nothing queued any more
  EXPECT_TRUE(robot.Stop().ok());      // idempotent
  // The arm stopped on the way: not at the target.
  const RobotPose now = robot.GetPosition(RobotFrame::kEndEffector);
  ASSERT_TRUE(now.result.ok());
  EXPECT_GT(Distance(now.pose, target.pose).translation_m, 0.01);
}

TEST(ScorbotRobot, EmergencyStopThroughTheRunnerAbortsAMove) {
  ScorbotControllerSim sim(FastSim());
  sim.Start();
  ScorbotOptions o = RobotOptions(sim.DevicePath());
  o.speed_percent = 2;  // seconds of motion
  ScorbotRobot robot(o);
  SafeRobot safe(robot, Safety());
  ASSERT_TRUE(safe.Connect().ok());
  ASSERT_TRUE(safe.Enable().ok());
  const RobotPose c = safe.GetPosition(RobotFrame::kCamera);
  ASSERT_TRUE(c.result.ok());
  // What a SIGINT handler does, from another context, once the arm is moving.
  std::thread ctrl_c([&] {
    WaitFor([&] { return sim.moving(); });
    safe.RequestEmergencyStop();
  });
  const MoveReport report =
      safe.MovePosition(RobotFrame::kCamera, c.pose * vpHomogeneousMatrix(0.1, 0, 0, 0, 0, 0));
  ctrl_c.join();
  EXPECT_EQ(report.result.status, RobotStatus::kStopped);
  EXPECT_NE(report.result.message.find("emergency stop"), std::string::npos)
      << report.result.message;
  EXPECT_FALSE(sim.moving());
  const ScorbotJoints at = sim.joints();
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_EQ(sim.joints(), at);
  EXPECT_GT(Distance(report.reached, report.target).translation_m, 0.01);
}

TEST(ScorbotRobot, ImpactDuringAMoveStopsTheRunnerWithTheControllersText) {
  Rig rig;
  rig.sim.InjectImpact(3);
  const RobotPose c = rig.safe->GetPosition(RobotFrame::kCamera);
  const MoveReport report = rig.safe->MovePosition(
      RobotFrame::kCamera, c.pose * vpHomogeneousMatrix(0.05, 0, 0, 0, 0, 0));
  EXPECT_EQ(report.result.status, RobotStatus::kError);
  EXPECT_NE(report.result.message.find("IMPACT PROTECTION axis 3"), std::string::npos)
      << report.result.message;
  EXPECT_EQ(rig.safe->state(), SafeRobotState::kStopped);
  // The controller switched control off: Enable() sends CON, and moves work again.
  ASSERT_TRUE(rig.safe->Enable().ok());
  EXPECT_TRUE(rig.sim.control_enabled());
  const RobotPose now = rig.safe->GetPosition(RobotFrame::kCamera);
  ASSERT_TRUE(now.result.ok()) << now.result.message;
  const MoveReport again = rig.safe->MovePosition(
      RobotFrame::kCamera, now.pose * vpHomogeneousMatrix(0.01, 0, 0, 0, 0, 0));
  EXPECT_TRUE(again.result.ok()) << again.result.message;
}

TEST(ScorbotRobot, ControllerErrorsMapToStatuses) {
  Rig rig;
  const RobotPose e = rig.robot->GetPosition(RobotFrame::kEndEffector);
  const RobotPose target = rig.robot->NearestReachable(
      RobotFrame::kEndEffector, vpHomogeneousMatrix(0.01, 0, 0, 0, 0, 0) * e.pose);
  ASSERT_TRUE(target.result.ok());
  rig.sim.InjectBadCartesianPoint();
  RobotResult r = rig.robot->StartMove(RobotFrame::kEndEffector, target.pose);
  EXPECT_EQ(r.status, RobotStatus::kUnreachable);
  EXPECT_NE(r.message.find("317 BAD CARTESIAN POINT"), std::string::npos) << r.message;
  ASSERT_TRUE(rig.robot->Disable().ok());  // COFF
  ASSERT_FALSE(rig.sim.control_enabled());
  r = rig.robot->StartMove(RobotFrame::kEndEffector, target.pose);
  EXPECT_EQ(r.status, RobotStatus::kNotReady);  // refused before anything is sent
  rig.sim.InjectHomeFailure(2);
  ASSERT_TRUE(rig.robot->Enable().ok());
  r = rig.robot->Home();
  EXPECT_EQ(r.status, RobotStatus::kError);
  EXPECT_NE(r.message.find("HOME FAILURE AXIS 2"), std::string::npos) << r.message;
  EXPECT_EQ(rig.robot->SetVelocity(RobotFrame::kCamera, vpColVector(6, 0.0)).status,
            RobotStatus::kUnsupported);
  EXPECT_THROW(rig.robot->SetVelocity(RobotFrame::kCamera, vpColVector(5, 0.0)),
               std::invalid_argument);
}

// A robot connected and enabled on `sim`, at 2 % speed, and a move of seconds started.
struct SlowMove {
  SlowMove(ScorbotControllerSim& sim, bool echo, double reply_timeout_s,
           bool control_off_at_end = false) {
    ScorbotOptions o = RobotOptions(sim.DevicePath());
    o.control_off_at_end = control_off_at_end;
    o.speed_percent = 2;
    o.echo = echo;
    o.reply_timeout_s = reply_timeout_s;
    robot = std::make_unique<ScorbotRobot>(o);
    const RobotResult c = robot->Connect();
    EXPECT_TRUE(c.ok()) << c.message;
    EXPECT_TRUE(robot->Enable().ok());
    const RobotPose e = robot->GetPosition(RobotFrame::kEndEffector);
    EXPECT_TRUE(e.result.ok()) << e.result.message;
    target = robot->NearestReachable(RobotFrame::kEndEffector,
                                     vpHomogeneousMatrix(0, 0.15, 0, 0, 0, 0) * e.pose);
    EXPECT_TRUE(target.result.ok()) << target.result.message;
    const RobotResult m = robot->StartMove(RobotFrame::kEndEffector, target.pose);
    EXPECT_TRUE(m.ok()) << m.message;
    EXPECT_TRUE(sim.moving());
  }
  std::unique_ptr<ScorbotRobot> robot;
  RobotPose target;
};

TEST(ScorbotRobot, SilentControllerFailsConnectAndStartMoveWithTimeouts) {
  ScorbotControllerSim sim(FastSim());
  sim.Start();
  sim.SetSilent(true);
  ScorbotOptions o = RobotOptions(sim.DevicePath());
  o.reply_timeout_s = 0.2;
  ScorbotRobot robot(o);
  const RobotResult r = robot.Connect();
  EXPECT_EQ(r.status, RobotStatus::kTimeout);
  EXPECT_NE(r.message.find("no prompt from the controller"), std::string::npos) << r.message;
  EXPECT_FALSE(robot.connected());
  sim.SetSilent(false);
  EXPECT_TRUE(robot.Connect().ok());
  // Silent before a move: the driver's first command of StartMove (a SETPVC) times out.
  ASSERT_TRUE(robot.Enable().ok());
  const RobotPose e = robot.GetPosition(RobotFrame::kEndEffector);
  ASSERT_TRUE(e.result.ok());
  const vpHomogeneousMatrix target = vpHomogeneousMatrix(0.01, 0, 0, 0, 0, 0) * e.pose;
  sim.SetSilent(true);
  const RobotResult start = robot.StartMove(RobotFrame::kEndEffector, target);
  EXPECT_EQ(start.status, RobotStatus::kTimeout) << start.message;
  EXPECT_NE(start.message.find("no reply to 'SETPVC"), std::string::npos) << start.message;
  // Through the runner, the pose read for the path check comes first: it times out, the
  // runner stops, and no move was started.
  sim.SetSilent(false);
  SafeRobot safe(robot, Safety());
  ASSERT_TRUE(safe.Connect().ok());
  ASSERT_TRUE(safe.Enable().ok());
  sim.SetSilent(true);
  const MoveReport report = safe.MovePosition(RobotFrame::kEndEffector, target);
  EXPECT_EQ(report.result.status, RobotStatus::kTimeout) << report.result.message;
  EXPECT_NE(report.result.message.find("no reply to '"), std::string::npos)
      << report.result.message;
  EXPECT_EQ(safe.state(), SafeRobotState::kStopped);
  EXPECT_EQ(sim.stats().moves_started, 0);
}

TEST(ScorbotRobot, SilentControllerDuringAMoveTimesOutThePoll) {
  ScorbotControllerSim sim(FastSim());
  sim.Start();
  SlowMove move(sim, /*echo=*/true, 0.2);
  ScorbotRobot& robot = *move.robot;
  sim.SetSilent(true);  // after MOVE was answered
  const MoveProgress p = robot.PollMove();
  EXPECT_EQ(p.result.status, RobotStatus::kTimeout) << p.result.message;
  EXPECT_NE(p.result.message.find("no reply to 'LISTPV POSITION'"), std::string::npos)
      << p.result.message;
  // Nothing confirms the stop while the controller is silent.
  const RobotResult stop = robot.Stop();
  EXPECT_EQ(stop.status, RobotStatus::kTimeout) << stop.message;
  // It lost what we sent meanwhile (the abort, the resynchronisation): connect again, which
  // aborts the move (Ctrl-A is sent whatever the state of the exchange).
  sim.SetSilent(false);
  const RobotResult c = robot.Connect();
  ASSERT_TRUE(c.ok()) << c.message;
  EXPECT_FALSE(sim.moving());
  ASSERT_TRUE(robot.Enable().ok());
  EXPECT_TRUE(robot.GetPosition(RobotFrame::kEndEffector).result.ok());
}

TEST(ScorbotRobot, ImpactRightAfterAPollsPromptFailsThePoll) {
  ScorbotControllerSim sim(FastSim());
  sim.Start();
  SlowMove move(sim, /*echo=*/true, 1.0);
  ScorbotRobot& robot = *move.robot;
  sim.InjectImpactAfterNextPrompt(2);
  // The LISTPV of the poll is answered, then the impact comes in the same write: this poll
  // reports it (or, if the pty cut the read after the prompt, the next one).
  MoveProgress p = robot.PollMove();
  if (p.result.ok() && !p.done) p = robot.PollMove();
  EXPECT_EQ(p.result.status, RobotStatus::kError) << p.result.message;
  EXPECT_NE(p.result.message.find("IMPACT PROTECTION axis 2"), std::string::npos)
      << p.result.message;
  EXPECT_FALSE(p.done);
  EXPECT_FALSE(sim.control_enabled());
  EXPECT_FALSE(sim.moving());
}

TEST(ScorbotRobot, LateAnswerToAPollIsNotTakenForTheStopsAnswer) {
  for (const bool echo : {false, true}) {
    SCOPED_TRACE(echo ? "echo" : "noecho");
    ScorbotControllerSim sim(FastSim());
    sim.Start();
    SlowMove move(sim, echo, 0.2);
    ScorbotRobot& robot = *move.robot;
    sim.InjectLateReply();  // the poll's LISTPV is answered after the driver gave up
    const MoveProgress p = robot.PollMove();
    EXPECT_EQ(p.result.status, RobotStatus::kTimeout) << p.result.message;
    const RobotResult stop = robot.Stop();
    ASSERT_TRUE(stop.ok()) << stop.message;
    EXPECT_EQ(sim.last_command(), "CLRBUF");  // answered, after the resynchronisation
    EXPECT_FALSE(sim.moving());
    EXPECT_EQ(sim.echo(), echo);
    const RobotPose now = robot.GetPosition(RobotFrame::kEndEffector);
    ASSERT_TRUE(now.result.ok()) << now.result.message;
    EXPECT_LE(Distance(now.pose, ForwardKinematics(ScorbotGeometry(), sim.joints())).translation_m,
              1e-4);  // encoder resolution
    // Every command ran once, plus NOECHO, ECHO, LISTPV POSITION (and NOECHO) of the resync.
    EXPECT_EQ(sim.stats().commands, robot.link_stats().commands + (echo ? 3 : 4));
  }
}

// By default the session end aborts and leaves control on, so the servos hold the arm where
// it stopped (an arm whose axes can be back-driven would sag with control off).
TEST(ScorbotRobot, SessionEndAbortsAndHoldsThePose) {
  ScorbotControllerSim sim(FastSim());
  sim.Start();
  {
    SlowMove move(sim, /*echo=*/true, 1.0);
    EXPECT_TRUE(sim.control_enabled());
  }  // the driver is destroyed with the arm moving
  EXPECT_FALSE(sim.moving());
  EXPECT_TRUE(sim.control_enabled());
  EXPECT_EQ(sim.last_command(), "CLRBUF");
}

TEST(ScorbotRobot, SessionEndTurnsControlOffWhenAsked) {
  ScorbotControllerSim sim(FastSim());
  sim.Start();
  {
    SlowMove move(sim, /*echo=*/true, 1.0, /*control_off_at_end=*/true);
    EXPECT_TRUE(sim.control_enabled());
  }
  EXPECT_FALSE(sim.moving());
  EXPECT_FALSE(sim.control_enabled());
  EXPECT_EQ(sim.last_command(), "COFF");
}

TEST(ScorbotRobot, SecondProgramCannotOpenTheControllersPort) {
  Rig rig;
  ScorbotRobot other(RobotOptions(rig.sim.ConnectPath()));
  const RobotResult r = other.Connect();
  EXPECT_EQ(r.status, RobotStatus::kError);
  EXPECT_NE(r.message.find(rig.sim.ConnectPath()), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("in use by another program"), std::string::npos) << r.message;
  EXPECT_TRUE(rig.robot->GetPosition(RobotFrame::kCamera).result.ok());  // undisturbed
  rig.robot->Disconnect();
  const RobotResult again = other.Connect();
  EXPECT_TRUE(again.ok()) << again.message;
}

TEST(ScorbotRobot, PortClosedDuringAMoveAndReconnection) {
  ScorbotSimOptions o = FastSim();
  o.link_path =
      testing_scorbot::TestTmpDir() + "/scorbot-robot-test-link-" + std::to_string(::getpid());
  ::unlink(o.link_path.c_str());
  Rig rig(o);
  const RobotPose e = rig.robot->GetPosition(RobotFrame::kEndEffector);
  ASSERT_TRUE(e.result.ok());
  ASSERT_TRUE(
      rig.robot
          ->StartMove(RobotFrame::kEndEffector,
                      rig.robot
                          ->NearestReachable(RobotFrame::kEndEffector,
                                             vpHomogeneousMatrix(0, 0.2, 0, 0, 0, 0) * e.pose)
                          .pose)
          .ok());
  rig.sim.Stop();  // the cable is pulled
  const MoveProgress p = rig.robot->PollMove();
  EXPECT_EQ(p.result.status, RobotStatus::kError);
  EXPECT_NE(p.result.message.find("closed"), std::string::npos) << p.result.message;
  EXPECT_FALSE(rig.robot->connected());
  EXPECT_EQ(rig.robot->GetPosition(RobotFrame::kCamera).result.status, RobotStatus::kNotReady);
  // The controller may still be running its queued move: a stop that cannot be sent is not ok,
  // and says why (the driver contract: "returns an error status, but still tries").
  const RobotResult stop = rig.robot->Stop();
  EXPECT_EQ(stop.status, RobotStatus::kError);
  EXPECT_NE(stop.message.find("the link to the controller is lost"), std::string::npos)
      << stop.message;
  EXPECT_FALSE(rig.robot->Stop().ok());  // still nothing confirmed it: idempotent
  EXPECT_EQ(p.result.message.find("Connect()"), std::string::npos) << p.result.message;
  // The controller comes back (a new pty behind the same link): Connect() again.
  rig.sim.Start();
  const RobotResult c = rig.robot->Connect();
  ASSERT_TRUE(c.ok()) << c.message;
  ASSERT_TRUE(rig.robot->Enable().ok());
  const RobotPose now = rig.robot->GetPosition(RobotFrame::kEndEffector);
  ASSERT_TRUE(now.result.ok()) << now.result.message;
  EXPECT_LE(
      Distance(now.pose, ForwardKinematics(ScorbotGeometry(), rig.sim.joints())).translation_m,
      1e-4);  // encoder resolution
}

TEST(ScorbotRobot, OptionsCheckNamesTheField) {
  ScorbotOptions o;
  o.speed_percent = 0;
  try {
    ScorbotRobot robot(o);
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("ScorbotOptions::speed_percent = 0"), std::string::npos)
        << e.what();
  }
  o = ScorbotOptions();
  o.point_name = "9X";
  EXPECT_THROW(ScorbotRobot{o}, std::invalid_argument);
  o = ScorbotOptions();
  o.baud = 1234;
  EXPECT_THROW(ScorbotRobot{o}, std::invalid_argument);
  // Not connected: everything but Stop() says so; Stop() is fine.
  ScorbotRobot idle((ScorbotOptions()));
  EXPECT_TRUE(idle.Stop().ok());
  EXPECT_EQ(idle.GetPosition(RobotFrame::kCamera).result.status, RobotStatus::kNotReady);
  EXPECT_EQ(idle.Enable().status, RobotStatus::kNotReady);
  const RobotResult open = [] {
    ScorbotOptions bad;
    bad.port = "/nonexistent/tty";
    ScorbotRobot r(bad);
    return r.Connect();
  }();
  EXPECT_EQ(open.status, RobotStatus::kError);
  EXPECT_NE(open.message.find("/nonexistent/tty"), std::string::npos) << open.message;
}

}  // namespace
}  // namespace oal
