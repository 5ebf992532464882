// The simulated camera against ViSP's exponential map, its lifecycle and its fault injection.
#include "robots/simulated_camera.h"

#include <gtest/gtest.h>
#include <visp3/core/vpExponentialMap.h>
#include <visp3/core/vpMath.h>
#include <visp3/core/vpVelocityTwistMatrix.h>

#include <random>
#include <stdexcept>
#include <vector>

namespace oal {
namespace {

constexpr double kPoseTolM = 1e-12;
constexpr double kPoseTolRad = 1e-12;

void ExpectPoseNear(const vpHomogeneousMatrix& a, const vpHomogeneousMatrix& b, double tol_m,
                    double tol_rad) {
  const PoseDistance d = Distance(a, b);
  EXPECT_LE(d.translation_m, tol_m) << "a:\n" << a << "\nb:\n" << b;
  EXPECT_LE(d.rotation_rad, tol_rad) << "a:\n" << a << "\nb:\n" << b;
}

SimulatedCamera ReadyCamera(const SimulatedCameraOptions& options) {
  SimulatedCamera camera(options);
  EXPECT_TRUE(camera.Connect().ok());
  EXPECT_TRUE(camera.Enable().ok());
  return camera;
}

TEST(SimulatedCamera, VelocityIntegrationMatchesExponentialMap) {
  SimulatedCameraOptions options;
  options.sampling_time_s = 0.05;
  options.wMc = vpHomogeneousMatrix(0.1, -0.2, 0.5, 0.1, 0.2, -0.3);
  SimulatedCamera camera = ReadyCamera(options);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uv(-0.3, 0.3);
  std::uniform_real_distribution<double> uw(-1.0, 1.0);
  vpHomogeneousMatrix expected = options.wMc;
  constexpr int kSteps = 50;
  for (int k = 0; k < kSteps; ++k) {
    const vpColVector v({uv(rng), uv(rng), uv(rng), uw(rng), uw(rng), uw(rng)});
    ASSERT_TRUE(camera.SetVelocity(RobotFrame::kCamera, v).ok());
    expected = expected * vpExponentialMap::direct(v, options.sampling_time_s);
  }
  ExpectPoseNear(camera.GetPosition(RobotFrame::kCamera).pose, expected, kPoseTolM, kPoseTolRad);
  EXPECT_NEAR(camera.Time(), kSteps * options.sampling_time_s, 1e-12);
}

TEST(SimulatedCamera, EndEffectorTwistGoesThroughTheHandEye) {
  SimulatedCameraOptions options;
  options.eMc = vpHomogeneousMatrix(0.0, 0.05, 0.1, 0.0, vpMath::rad(90), 0.0);
  SimulatedCamera camera = ReadyCamera(options);
  const vpHomogeneousMatrix wMe0 = camera.GetPosition(RobotFrame::kEndEffector).pose;
  const vpColVector v_e({0.1, 0.0, 0.05, 0.0, 0.0, 0.5});
  ASSERT_TRUE(camera.SetVelocity(RobotFrame::kEndEffector, v_e).ok());
  const vpHomogeneousMatrix expected_wMe =
      wMe0 * vpExponentialMap::direct(v_e, options.sampling_time_s);
  ExpectPoseNear(camera.GetPosition(RobotFrame::kEndEffector).pose, expected_wMe, 1e-12, 1e-12);
  ExpectPoseNear(camera.GetPosition(RobotFrame::kCamera).pose, expected_wMe * options.eMc, 1e-12,
                 1e-12);
}

TEST(SimulatedCamera, TwistAboveHardwareLimitIsRefusedNotClamped) {
  SimulatedCameraOptions options;
  options.max_translation_mps = 0.5;
  SimulatedCamera camera = ReadyCamera(options);
  const vpHomogeneousMatrix before = camera.wMc();
  const RobotResult r = camera.SetVelocity(RobotFrame::kCamera, vpColVector({0, 0, 0.6, 0, 0, 0}));
  EXPECT_EQ(r.status, RobotStatus::kLimit);
  EXPECT_NE(r.message.find("vz"), std::string::npos) << r.message;
  ExpectPoseNear(camera.wMc(), before, 0, 0);
}

TEST(SimulatedCamera, RefusesMotionUntilConnectedAndEnabled) {
  SimulatedCamera camera;
  EXPECT_EQ(camera.SetVelocity(RobotFrame::kCamera, vpColVector({0, 0, 0.1, 0, 0, 0})).status,
            RobotStatus::kNotReady);
  EXPECT_EQ(camera.GetPosition(RobotFrame::kCamera).result.status, RobotStatus::kNotReady);
  ASSERT_TRUE(camera.Connect().ok());
  EXPECT_EQ(camera.StartMove(RobotFrame::kCamera, vpHomogeneousMatrix()).status,
            RobotStatus::kNotReady);
  ASSERT_TRUE(camera.Enable().ok());
  EXPECT_TRUE(camera.SetVelocity(RobotFrame::kCamera, vpColVector({0, 0, 0.1, 0, 0, 0})).ok());
  EXPECT_TRUE(camera.Disable().ok());
  EXPECT_EQ(camera.SetVelocity(RobotFrame::kCamera, vpColVector({0, 0, 0.1, 0, 0, 0})).status,
            RobotStatus::kNotReady);
}

TEST(SimulatedCamera, WrongTwistSizeIsAProgrammerError) {
  SimulatedCamera camera = ReadyCamera(SimulatedCameraOptions());
  EXPECT_THROW(camera.SetVelocity(RobotFrame::kCamera, vpColVector(3)), std::invalid_argument);
}

TEST(SimulatedCamera, IntegratedMoveFollowsTheScrewAndLandsOnTarget) {
  SimulatedCameraOptions options;
  options.move_mode = SimulatedCameraOptions::MoveMode::kIntegrate;
  options.move_duration_s = 0.4;
  options.sampling_time_s = 0.04;
  options.wMc = vpHomogeneousMatrix(0.49, 0.015, 0.61, 0, vpMath::rad(-5), 0);
  SimulatedCamera camera = ReadyCamera(options);
  const vpHomogeneousMatrix target(0.55, -0.035, 0.55, 0, 0, 0);
  ASSERT_TRUE(camera.StartMove(RobotFrame::kCamera, target).ok());
  const vpColVector twist = vpExponentialMap::inverse(options.wMc.inverse() * target, 1.0);
  int polls = 0;
  MoveProgress p;
  do {
    p = camera.PollMove();
    ASSERT_TRUE(p.result.ok()) << p.result.message;
    ++polls;
    // Halfway along the screw after half the steps.
    if (polls == 5) {
      ExpectPoseNear(camera.wMc(), options.wMc * vpExponentialMap::direct(twist, 0.5), 1e-9, 1e-9);
    }
  } while (!p.done && polls < 100);
  EXPECT_EQ(polls, 10);
  ExpectPoseNear(camera.wMc(), target, 1e-12, 1e-12);
}

TEST(SimulatedCamera, IntegratedMoveIsLengthenedToRespectTheLimits) {
  SimulatedCameraOptions options;
  options.move_mode = SimulatedCameraOptions::MoveMode::kIntegrate;
  options.move_duration_s = 0.1;
  options.sampling_time_s = 0.1;
  options.max_translation_mps = 0.1;
  SimulatedCamera camera = ReadyCamera(options);
  ASSERT_TRUE(camera.StartMove(RobotFrame::kCamera, vpHomogeneousMatrix(0, 0, 0.5, 0, 0, 0)).ok());
  int polls = 0;
  while (!camera.PollMove().done && polls < 100) ++polls;
  EXPECT_EQ(polls + 1, 50);  // 0.5 m at 0.1 m/s, 0.1 s per poll
}

TEST(SimulatedCamera, InjectedFaultFailsTheNextCommandOnly) {
  SimulatedCamera camera = ReadyCamera(SimulatedCameraOptions());
  camera.InjectFault(RobotStatus::kError, "encoder lost");
  const RobotResult r = camera.SetVelocity(RobotFrame::kCamera, vpColVector({0, 0, 0.1, 0, 0, 0}));
  EXPECT_EQ(r.status, RobotStatus::kError);
  EXPECT_EQ(r.message, "encoder lost");
  EXPECT_TRUE(camera.SetVelocity(RobotFrame::kCamera, vpColVector({0, 0, 0.1, 0, 0, 0})).ok());
}

// A fault armed for a later command while no move is queued: the polls counting towards it
// moved the camera along the last move's twist, and the move never ended (the queue ran
// below zero).
TEST(SimulatedCamera, PollsWithAFaultArmedAndNoMoveQueuedMoveNothingAndAreDone) {
  SimulatedCameraOptions options;
  options.move_mode = SimulatedCameraOptions::MoveMode::kIntegrate;
  options.move_duration_s = 0.2;
  options.sampling_time_s = 0.04;
  SimulatedCamera camera = ReadyCamera(options);
  const vpHomogeneousMatrix target(0.05, 0.0, 0.1, 0, 0, vpMath::rad(20));
  ASSERT_TRUE(camera.StartMove(RobotFrame::kCamera, target).ok());
  int polls = 0;
  while (!camera.PollMove().done && polls < 100) ++polls;
  ASSERT_EQ(polls + 1, 5);
  ExpectPoseNear(camera.wMc(), target, kPoseTolM, kPoseTolRad);

  camera.InjectFault(RobotStatus::kError, "encoder lost", 2);
  for (int i = 0; i < 2; ++i) {  // counted towards the fault, nothing queued
    const MoveProgress p = camera.PollMove();
    EXPECT_TRUE(p.result.ok()) << p.result.message;
    EXPECT_TRUE(p.done) << "poll " << i;
    EXPECT_FALSE(camera.moving());
    ExpectPoseNear(camera.wMc(), target, kPoseTolM, kPoseTolRad);
  }
  const MoveProgress fault = camera.PollMove();
  EXPECT_EQ(fault.result.status, RobotStatus::kError);
  EXPECT_EQ(fault.result.message, "encoder lost");
  const MoveProgress after = camera.PollMove();
  EXPECT_TRUE(after.result.ok());
  EXPECT_TRUE(after.done);
  ExpectPoseNear(camera.wMc(), target, kPoseTolM, kPoseTolRad);

  // A move after them runs as usual.
  ASSERT_TRUE(camera.StartMove(RobotFrame::kCamera, options.wMc).ok());
  polls = 0;
  while (!camera.PollMove().done && polls < 100) ++polls;
  EXPECT_EQ(polls + 1, 5);
  ExpectPoseNear(camera.wMc(), options.wMc, kPoseTolM, kPoseTolRad);
}

TEST(SimulatedCamera, ThePollHookSeesEveryPollOfAMoveNumberedFromZero) {
  SimulatedCameraOptions options;
  options.move_mode = SimulatedCameraOptions::MoveMode::kIntegrate;
  options.move_duration_s = 0.2;
  options.sampling_time_s = 0.04;
  std::vector<int> polls;
  options.on_poll = [&](int poll) { polls.push_back(poll); };
  SimulatedCamera camera = ReadyCamera(options);
  for (int move = 0; move < 2; ++move) {
    ASSERT_TRUE(
        camera.StartMove(RobotFrame::kCamera, vpHomogeneousMatrix(0, 0, 0.1 * move, 0, 0, 0)).ok());
    while (!camera.PollMove().done) {
    }
  }
  EXPECT_TRUE(camera.PollMove().done);  // nothing queued: no call
  EXPECT_EQ(polls, (std::vector<int>{0, 1, 2, 3, 4, 0, 1, 2, 3, 4}));
}

TEST(SimulatedCamera, OptionsCheckNamesTheField) {
  SimulatedCameraOptions options;
  options.sampling_time_s = 0;
  try {
    options.Check();
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("sampling_time_s = 0"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace oal
