// The servo loop with the simulated robot and camera in the loop (loop/servo_loop.h, run from a
// configuration by app/servo_run.h), its configuration sections and the built-in default
// (app/servo_command.h).
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <visp3/core/vpMath.h>
#include <visp3/core/vpRzyxVector.h>

#include <atomic>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/command_line.h"
#include "app/config.h"
#include "app/servo_command.h"
#include "app/servo_default_config.h"
#include "app/servo_run.h"
#include "loop/lens_estimate.h"  // kLensFrames
#include "robots/simulated_camera.h"
#include "scene/scene.h"
#include "servo_test_util.h"

namespace oal {
namespace {

using ::testing::HasSubstr;

constexpr double kTolTranslationMm = 1.0;  // Table 3's target accuracy
constexpr double kTolRotationDeg = 0.1;

std::string SourcePath(const std::string& relative) {
  return std::string(OAL_SOURCE_DIR) + "/" + relative;
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string ServoConfigErrorOf(const std::string& yaml) {
  return test::ConfigErrorOf(yaml, "servo.yaml");
}

using test::SamePose;
using test::ShippedServoConfig;
using test::Small;

TEST(ServoConfig, BuiltInDefaultIsConfigServoSimYaml) {
  EXPECT_EQ(std::string(kDefaultServoConfigYaml), ReadText(SourcePath("config/servo-sim.yaml")));
  const ServoAppConfig built_in = DefaultServoConfig();
  const ServoAppConfig file = LoadConfig(SourcePath("config/servo-sim.yaml"));
  EXPECT_EQ(built_in.servo.law.mode, ServoMode::kExponential);
  EXPECT_DOUBLE_EQ(built_in.servo.law.delta, 0.8);
  EXPECT_EQ(built_in.camera.width, 640);
  EXPECT_EQ(built_in.camera.height, 480);
  EXPECT_TRUE(SamePose(built_in.robot.start_wMc, file.robot.start_wMc));
  EXPECT_TRUE(SamePose(built_in.goal_cdMo, file.goal_cdMo));
  EXPECT_TRUE(SamePose(built_in.target_wMo, file.target_wMo));
  EXPECT_NEAR(built_in.goal_cdMo[2][3], 0.5, 1e-12);
  // Start ~0.6 m from the target.
  const vpHomogeneousMatrix cMo = built_in.robot.start_wMc.inverse() * built_in.target_wMo;
  EXPECT_NEAR(cMo.getTranslationVector().frobeniusNorm(), 0.6, 0.05);
}

// The lived-in bench for the servo: the default run with episodes of hands, tools, glares and
// exposure changes, and the camera's own smear; every law converges on it.
TEST(ServoConfig, ShippedLivedInConfigConvergesWithEveryLaw) {
  const ServoAppConfig shipped = ShippedServoConfig("servo-lived-in.yaml");
  EXPECT_DOUBLE_EQ(shipped.camera.exposure_s, 0.01);
  EXPECT_DOUBLE_EQ(shipped.camera.latency_s, 0.06);
  EXPECT_DOUBLE_EQ(shipped.scene.lived_in.occluders.fraction, 0.3);
  EXPECT_DOUBLE_EQ(shipped.scene.episode_s.lo, 0.2);
  EXPECT_DOUBLE_EQ(shipped.scene.episode_s.hi, 1.0);
  for (const ServoMode mode : {ServoMode::kExponential, ServoMode::kVelocity}) {
    ServoAppConfig config = Small(shipped);
    config.servo.law.mode = mode;
    std::ostringstream log;
    const ServoRunReport report = RunServo(config, log);
    EXPECT_EQ(report.status, ServoRunStatus::kConverged)
        << ToString(mode) << ": " << report.message;
    EXPECT_LT(report.iterations.back().true_translation_error_mm, 2.0) << ToString(mode);
  }
}

TEST(ServoConfig, ShippedTable3UsesThePaperConvention) {
  const ServoAppConfig config = ShippedServoConfig("table3-sim.yaml");
  double x, y, z, pitch, roll, yaw;
  Table3Columns(config.robot.start_wMc, &x, &y, &z, &pitch, &roll, &yaw);
  EXPECT_NEAR(x, 490, 1e-9);
  EXPECT_NEAR(y, 15, 1e-9);
  EXPECT_NEAR(z, 610, 1e-9);
  EXPECT_NEAR(pitch, -5, 1e-9);
  EXPECT_NEAR(roll, 0, 1e-9);
  EXPECT_NEAR(yaw, 0, 1e-9);
  const vpHomogeneousMatrix wMcd = config.target_wMo * config.goal_cdMo.inverse();
  Table3Columns(wMcd, &x, &y, &z, &pitch, &roll, &yaw);
  EXPECT_NEAR(x, 550, 1e-9);
  EXPECT_NEAR(y, -35, 1e-9);
  EXPECT_NEAR(z, 550, 1e-9);
  EXPECT_NEAR(pitch, 0, 1e-9);
  EXPECT_NEAR(roll, 0, 1e-9);
  EXPECT_NEAR(yaw, 0, 1e-9);
}

// The columns are the config's rxyz_deg [180 + pitch, yaw, roll]: the default start, turned
// 10 deg about the camera's y axis, shows yaw -10 (it printed as pitch -0.00 with no yaw).
TEST(ServoConfig, Table3ColumnsReadBackTheConfigsAngles) {
  const ServoAppConfig config = DefaultServoConfig();  // start rxyz_deg [180, -10, 5]
  double x, y, z, pitch, roll, yaw;
  Table3Columns(config.robot.start_wMc, &x, &y, &z, &pitch, &roll, &yaw);
  EXPECT_NEAR(pitch, 0, 1e-9);
  EXPECT_NEAR(yaw, -10, 1e-9);
  EXPECT_NEAR(roll, 5, 1e-9);
  const ServoAppConfig tilted =
      ParseConfig("robot:\n  start: {translation_m: [0.5, 0, 0.6], rxyz_deg: [172, 7, -20]}\n",
                  "t.yaml", config);
  Table3Columns(tilted.robot.start_wMc, &x, &y, &z, &pitch, &roll, &yaw);
  EXPECT_NEAR(pitch, -8, 1e-9);
  EXPECT_NEAR(yaw, 7, 1e-9);
  EXPECT_NEAR(roll, -20, 1e-9);
}

TEST(ServoConfig, ErrorsNameFileLineAndKey) {
  EXPECT_EQ(ServoConfigErrorOf("servo:\n  delta: 0.5\n  deltaa: 0.3\n").substr(0, 43),
            "servo.yaml:3: key 'servo.deltaa' is unknown");
  EXPECT_THAT(ServoConfigErrorOf("servo:\n  mode: exponential\n  delta: 1.5\n"),
              HasSubstr("servo.yaml:3: 'servo.delta' is invalid"));
  // The camera's kdu: the range every command line's --kdu has.
  EXPECT_THAT(ServoConfigErrorOf("camera:\n  kdu: 1.5\n"),
              HasSubstr("servo.yaml:2: 'camera.kdu' is invalid: 1.5 (needs -1 < kdu < 1)"));
  EXPECT_THAT(ServoConfigErrorOf("servo:\n  max_iterations: -1\n"),
              HasSubstr("servo.yaml:2: 'servo.max_iterations' is invalid"));
  EXPECT_THAT(ServoConfigErrorOf("servo:\n  delta: 0.5\n  max_step_m: 0\n"),
              HasSubstr("servo.yaml:3: 'servo.max_step_m' is invalid: 0 (needs max_step_m > 0)"));
  EXPECT_THAT(ServoConfigErrorOf("servo:\n  max_step_deg: 200\n"),
              HasSubstr("servo.yaml:2: 'servo.max_step_deg' is invalid"));
  EXPECT_THAT(ServoConfigErrorOf("servo:\n  max_step_m: fast\n"),
              HasSubstr("servo.yaml:2: 'servo.max_step_m'"));
  EXPECT_THAT(ServoConfigErrorOf("servo:\n  delta: 0.5\n  max_lost_s: -2\n"),
              HasSubstr("servo.yaml:3: 'servo.max_lost_s' is invalid: -2 (needs 0 <= max_lost_s "
                        "<= 3600)"));
  EXPECT_THAT(ServoConfigErrorOf("servo:\n  max_lost_frames: 1.5\n"),
              HasSubstr("servo.yaml:2: 'servo.max_lost_frames'"));
  EXPECT_THAT(ServoConfigErrorOf("camera:\n  latency_s: -0.1\n"),
              HasSubstr("servo.yaml:2: 'camera.latency_s' is invalid: -0.1"));
  EXPECT_THAT(ServoConfigErrorOf("scene:\n  episode_s: [0.5, 0.2]\n"),
              HasSubstr("servo.yaml:2: 'scene.episode_s' is invalid"));
  EXPECT_THAT(ServoConfigErrorOf("scene:\n  episode_seed: -3\n"),
              HasSubstr("servo.yaml:2: 'scene.episode_seed' is invalid: -3"));
  EXPECT_THAT(ServoConfigErrorOf("camera:\n  px: 600\n  exposure_s: 2\n"),
              HasSubstr("servo.yaml:3: 'camera.exposure_s' is invalid: 2 (needs 0 <= exposure_s "
                        "<= 1)"));
  EXPECT_THAT(ServoConfigErrorOf("servo:\n  mode: sideways\n"),
              HasSubstr("servo.yaml:2: 'servo.mode' must be one of point-and-go, exponential"));
  EXPECT_THAT(ServoConfigErrorOf("camera:\n  px: 600\n  width: 8\n"),
              HasSubstr("servo.yaml:3: 'camera.width' is invalid"));
  EXPECT_THAT(ServoConfigErrorOf("camera:\n  noise: -1\n"),
              HasSubstr("servo.yaml:2: 'camera.noise' is invalid"));
  EXPECT_THAT(ServoConfigErrorOf("robot:\n  max_translation_mps: -0.1\n"),
              HasSubstr("servo.yaml:2: 'robot.max_translation_mps' is invalid"));
  EXPECT_THAT(ServoConfigErrorOf("robot:\n  start: {translation_m: [0, 0], rxyz_deg: [0, 0, 0]}\n"),
              HasSubstr("servo.yaml:2: 'robot.start.translation_m' must be [x, y, z]"));
  EXPECT_THAT(ServoConfigErrorOf("goal:\n  cdMo:\n    translation: [0, 0, 1]\n"),
              HasSubstr("servo.yaml:3: key 'goal.cdMo.translation' is unknown"));
  EXPECT_THAT(
      ServoConfigErrorOf("goal:\n  taught_from_pose: x.png\n"),
      HasSubstr("servo.yaml:2: key 'goal.taught_from_pose' is unknown (known: cdMo, image)"));
  EXPECT_THAT(
      ServoConfigErrorOf("goal:\n  cdMo: {translation_m: [0, 0, -0.5], rxyz_deg: [0, 0, 0]}\n"),
      HasSubstr("servo.yaml:2: 'goal.cdMo' puts the target at z = -0.5"));
  EXPECT_THAT(ServoConfigErrorOf("target_pose: {translation_m: [0, 0, 0], rxyz: [0, 0, 0]}\n"),
              HasSubstr("servo.yaml:1: key 'target_pose.rxyz' is unknown"));
}

// Half a pose was read as zeros for the other half: the robot would start (or servo to)
// somewhere else than the user wrote.
TEST(ServoConfig, APoseWithOnlyOneOfItsKeysIsAnErrorNamingTheMissingKey) {
  EXPECT_THAT(ServoConfigErrorOf("robot:\n  start: {translation_m: [0.5, 0, 0.6]}\n"),
              HasSubstr("servo.yaml:2: 'robot.start' has no 'rxyz_deg'"));
  EXPECT_THAT(ServoConfigErrorOf("goal:\n  cdMo:\n    rxyz_deg: [0, 0, 10]\n"),
              HasSubstr("servo.yaml:3: 'goal.cdMo' has no 'translation_m'"));
  EXPECT_THAT(ServoConfigErrorOf("target_pose: {rxyz_deg: [180, 0, 0]}\n"),
              HasSubstr("servo.yaml:1: 'target_pose' has no 'translation_m'"));
  EXPECT_THAT(ServoConfigErrorOf("camera:\n  eMc: {rxyz_deg: [0, 0, 90]}\n"),
              HasSubstr("servo.yaml:2: 'camera.eMc' has no 'translation_m'"));
  EXPECT_EQ(
      ServoConfigErrorOf("goal:\n  cdMo: {translation_m: [0, 0, 0.4], rxyz_deg: [0, 0, 0]}\n"), "");
}

TEST(ServoConfig, AWorkspaceBoxWithMinAboveMaxNamesTheKeyAndLine) {
  EXPECT_THAT(
      ServoConfigErrorOf("robot:\n  workspace_enabled: true\n  workspace_min_m: [1, -1, -1]\n"
                         "  workspace_max_m: [0, 1, 1]\n"),
      HasSubstr("servo.yaml:3: 'robot.workspace_min_m' is invalid: "
                "robot.workspace_min_m/workspace_max_m [x] = 1 / 0 (needs finite and min < "
                "max)"));
  // Only the max in this file: its line.
  EXPECT_THAT(ServoConfigErrorOf("robot:\n  workspace_max_m: [1, 1, -2]\n"),
              HasSubstr("servo.yaml:2: 'robot.workspace_max_m' is invalid"));
}

// A configured start outside the box would begin where no move is allowed.
TEST(ServoConfig, AStartOutsideTheWorkspaceIsAnErrorNamingTheKey) {
  const ServoAppConfig base = DefaultServoConfig();  // box [0, 1] x [-0.5, 0.5] x [0.1, 1] m
  const std::string error = test::ErrorMessageOf<std::runtime_error>([&] {
    ParseConfig("robot:\n  start: {translation_m: [0.5, 0, 1.5], rxyz_deg: [180, 0, 0]}\n",
                "start.yaml", base);
  });
  EXPECT_THAT(error, HasSubstr("start.yaml:2: 'robot.start' puts the camera outside the "
                               "workspace box: z = 1.5 m is outside [0.1, 1] m"));
  // The box moved away from the built-in start: this file's line of the box, and where the
  // start was set.
  const std::string moved = test::ErrorMessageOf<std::runtime_error>(
      [&] { ParseConfig("robot:\n  workspace_min_m: [0.7, -0.5, 0.1]\n", "box.yaml", base); });
  EXPECT_THAT(moved, HasSubstr("box.yaml:2: 'robot.start' (config/servo-sim.yaml (built in):"));
  EXPECT_THAT(moved, HasSubstr("x = 0.6 m is outside [0.7, 1] m"));
  // No box, no check; a real arm starts where it stands.
  EXPECT_EQ(test::ErrorMessageOf<std::runtime_error>([&] {
              ParseConfig(
                  "robot:\n  workspace_enabled: false\n  start: {translation_m: [0.5, 0, "
                  "1.5], rxyz_deg: [180, 0, 0]}\n",
                  "off.yaml", base);
            }),
            "");
  EXPECT_EQ(test::ErrorMessageOf<std::runtime_error>([&] {
              ParseConfig(
                  "robot:\n  type: scorbot\n  scorbot: {port: /dev/ttyS0}\n  start: "
                  "{translation_m: [0.5, 0, 1.5], rxyz_deg: [180, 0, 0]}\n",
                  "arm.yaml", base);
            }),
            "");
  // Where each key was set is kept for later messages.
  const ServoAppConfig config = ParseConfig("source:\n  type: replay\n  path: v.avi\n", "s.yaml");
  EXPECT_EQ(config.Origin("source.path"), "s.yaml:3");
  EXPECT_EQ(config.Origin("robot.start"), "");
}

TEST(ServoLoop, DefaultConfigConvergesWithTheImageInTheLoop) {
  const ServoAppConfig config = Small(DefaultServoConfig());
  std::ostringstream log;
  const ServoRunReport report = RunServo(config, log);
  std::cout << log.str() << report.message << '\n';
  EXPECT_EQ(report.status, ServoRunStatus::kConverged) << report.message;
  EXPECT_TRUE(report.robot_stopped);
  ASSERT_FALSE(report.iterations.empty());
  EXPECT_EQ(report.iterations.back().status, "converged");
  // Truth, not the estimate: a few mm on 320x240 noisy images.
  EXPECT_LT(report.iterations.back().true_translation_error_mm, 5.0);
  EXPECT_LT(report.iterations.back().true_rotation_error_deg, 0.5);
  EXPECT_THAT(log.str(), ::testing::Not(HasSubstr("Calibrate the camera")));
}

TEST(ServoLoop, Table3ConvergesWithin10IterationsWithDelta08) {
  const ServoAppConfig config = ShippedServoConfig("table3-sim.yaml");
  std::ostringstream log;
  const ServoRunReport report = RunServo(config, log);
  std::cout << "Table 3, image in the loop, exponential, delta 0.8:\n"
            << log.str() << report.message << '\n';
  ASSERT_EQ(report.status, ServoRunStatus::kConverged) << report.message;
  EXPECT_LE(report.moves, 10);
  const ServoIteration& last = report.iterations.back();
  EXPECT_LE(last.true_translation_error_mm, kTolTranslationMm);
  EXPECT_LE(last.true_rotation_error_deg, kTolRotationDeg);
  EXPECT_TRUE(report.robot_stopped);
}

// Through a cheap wide lens with noise: corrected on the feature points the loop converges
// as on a perfect camera; uncorrected (the paper's condition) it never reaches the goal and
// the loop stops itself, with the robot stopped, rather than servo on a flipping pose.
TEST(ServoLoop, Table3WithDistortionCorrectedConverges) {
  const ServoAppConfig config = ShippedServoConfig("table3-sim-distorted.yaml");
  ASSERT_TRUE(config.camera.correct_distortion);
  std::ostringstream log;
  const ServoRunReport report = RunServo(config, log);
  EXPECT_THAT(log.str(), ::testing::Not(HasSubstr("Calibrate the camera")));
  ASSERT_EQ(report.status, ServoRunStatus::kConverged) << report.message;
  EXPECT_LE(report.moves, 10);
  EXPECT_LE(report.iterations.back().true_translation_error_mm, kTolTranslationMm);
  EXPECT_LE(report.iterations.back().true_rotation_error_deg, kTolRotationDeg);
}

// A camera nobody calibrated: the loop tells the lens from the sheet's stripes before it
// moves, and reaches the true goal as with the lens given.
TEST(ServoLoop, ALensToldFromTheStripesConvergesAsTheLensGiven) {
  const ServoAppConfig config = ParseConfig("camera:\n  kdu: 0.15\n  estimate_distortion: true\n",
                                            "lens.yaml", DefaultServoConfig());
  std::ostringstream log;
  const ServoRunReport report = RunServo(config, log);
  EXPECT_THAT(log.str(), HasSubstr("lens told from the stripes of " + std::to_string(kLensFrames) +
                                   " frames: kdu 0.15"));
  EXPECT_THAT(log.str(), ::testing::Not(HasSubstr("Calibrate the camera")));
  ASSERT_EQ(report.status, ServoRunStatus::kConverged) << report.message;
  EXPECT_LE(report.iterations.back().true_translation_error_mm, 1.0);
  EXPECT_LE(report.iterations.back().true_rotation_error_deg, 0.1);
}

TEST(ServoConfig, TellingTheLensConflictsWithIgnoringItOrGivingIt) {
  std::ostringstream log;
  const std::string ignored = test::ErrorMessageOf([&] {
    RunServo(ParseConfig("camera:\n  estimate_distortion: true\n  correct_distortion: false\n",
                         "lens.yaml", DefaultServoConfig()),
             log);
  });
  EXPECT_THAT(ignored, HasSubstr("lens.yaml:2: camera.estimate_distortion"));
  EXPECT_THAT(ignored, HasSubstr("camera.correct_distortion is false"));
  const std::string given = test::ErrorMessageOf([&] {
    RunServo(ParseConfig("camera:\n  kdu: 0.2\n  estimate_distortion: true\nsource: {type: "
                         "replay, path: x.avi}\n",
                         "lens.yaml", DefaultServoConfig()),
             log);
  });
  EXPECT_THAT(given, HasSubstr("but the camera gives kdu 0.2 (lens.yaml:2: camera.kdu)"));
}

// Uncorrected, the curved lines bias the pose: the loop ends (it stops itself, or believes it
// has arrived) far from the true goal, with the robot stopped.
TEST(ServoLoop, Table3WithDistortionUncorrectedMissesTheTrueGoal) {
  const ServoAppConfig config = ShippedServoConfig("table3-sim-paper.yaml");
  ASSERT_FALSE(config.camera.correct_distortion);
  std::ostringstream log;
  const ServoRunReport report = RunServo(config, log);
  EXPECT_TRUE(report.robot_stopped);
  EXPECT_FALSE(report.message.empty());
  ASSERT_FALSE(report.iterations.empty());
  EXPECT_GT(report.iterations.back().true_translation_error_mm, 5.0) << report.message;
  EXPECT_THAT(log.str(), HasSubstr("Calibrate the camera")) << "the lens check says why";
}

// ... and the console says so when the estimate claims convergence far from the true goal.
TEST(ServoCommand, AConvergedEstimateFarFromTheTruthIsAWarning) {
  ServoRunReport report;
  report.status = ServoRunStatus::kConverged;
  ServoIteration row;
  row.true_translation_error_mm = 21.6;
  row.true_rotation_error_deg = 0.78;
  report.iterations.push_back(row);
  const ServoOptions law;
  std::optional<std::string> line = TrueErrorLine(report, law);
  ASSERT_TRUE(line.has_value());
  EXPECT_THAT(*line, HasSubstr("true error (simulation): 21.600 mm"));
  EXPECT_THAT(*line, HasSubstr("WARNING: the estimate says converged"));
  report.iterations.back().true_translation_error_mm = 0.6;
  report.iterations.back().true_rotation_error_deg = 0.05;
  EXPECT_THAT(*TrueErrorLine(report, law), ::testing::Not(HasSubstr("WARNING")));
  report.iterations.back().true_translation_error_mm = std::nan("");
  EXPECT_FALSE(TrueErrorLine(report, law).has_value());  // not a simulation
}

TEST(ServoLoop, TargetOutOfViewStopsWithTargetLost) {
  ServoAppConfig config = Small(DefaultServoConfig());
  // Looking up, away from the table.
  config.robot.start_wMc =
      vpHomogeneousMatrix(vpTranslationVector(0.5, 0.0, 0.6), vpRotationMatrix());
  config.servo.max_lost_frames = 4;
  std::ostringstream log;
  const ServoRunReport report = RunServo(config, log);
  EXPECT_EQ(report.status, ServoRunStatus::kTargetLost);
  EXPECT_THAT(report.message, HasSubstr("target lost: held 5 frames"));
  EXPECT_THAT(report.message, HasSubstr("since iteration 0 without a confirmed pose"));
  EXPECT_THAT(report.message, HasSubstr("robot stopped"));
  EXPECT_EQ(report.iterations.size(), 5u);
  EXPECT_TRUE(report.robot_stopped);
  EXPECT_EQ(report.moves, 0);
  EXPECT_TRUE(SamePose(report.final_wMc, config.robot.start_wMc));
}

TEST(ServoLoop, GoalBeyondTheWorkspaceStopsWithLimit) {
  ServoAppConfig config = Small(DefaultServoConfig());
  config.goal_cdMo = vpHomogeneousMatrix(0.0, 0.0, 3.0, 0.0, 0.0, 0.0);  // 3 m above the table
  config.servo.max_step_m = 5.0;  // a step the loop allows, a target the workspace does not
  std::ostringstream log;
  const ServoRunReport report = RunServo(config, log);
  EXPECT_EQ(report.status, ServoRunStatus::kLimit) << report.message;
  // Frame 0 commands nothing (the first pose is confirmed on frame 1).
  EXPECT_THAT(report.message,
              HasSubstr("limit at iteration 1: move refused, the robot did not move: the move "
                        "target"));
  EXPECT_THAT(report.message, HasSubstr("outside the workspace box"));
  EXPECT_TRUE(report.robot_stopped);
  EXPECT_TRUE(SamePose(report.final_wMc, config.robot.start_wMc));  // refused, not moved
  EXPECT_EQ(report.moves, 0);  // a refused command is not a move
}

// Every law converges on the default config within its own iteration limit (the velocity law
// takes about 140 periods, beyond the position laws' 30 frames).
TEST(ServoLoop, PointAndGoAndVelocityLawsConvergeToo) {
  for (const ServoMode mode : {ServoMode::kPointAndGo, ServoMode::kVelocity}) {
    ServoAppConfig config = Small(DefaultServoConfig());
    config.servo.law.mode = mode;
    ASSERT_EQ(config.servo.max_iterations, 0) << "the default config leaves the limit to the law";
    std::ostringstream log;
    const ServoRunReport report = RunServo(config, log);
    EXPECT_EQ(report.status, ServoRunStatus::kConverged)
        << ToString(mode) << ": " << report.message;
    EXPECT_TRUE(report.robot_stopped);
    if (mode == ServoMode::kPointAndGo) {
      EXPECT_LE(report.moves, 3);
    }
    EXPECT_LT(report.iterations.back().true_translation_error_mm, 5.0) << ToString(mode);
  }
}

// A frame after a move disagrees with the odometry (the image slid by 40 px, ~65 mm at
// 0.5 m): the loop holds, finds the target again, confirms it, and carries on.
TEST(ServoLoop, AOneFramePoseJumpIsHeldAndTheRunCarriesOn) {
  const ServoAppConfig config = Small(DefaultServoConfig());
  ServoRunHooks hooks;
  hooks.on_grab = [](int iteration, cv::Mat* gray) {
    if (iteration != 2) return;
    const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, 40, 0, 1, 0);
    cv::Mat moved;
    cv::warpAffine(*gray, moved, shift, gray->size(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    moved.copyTo(*gray);
  };
  std::vector<int> moved_at;
  hooks.on_move = [&](int iteration) { moved_at.push_back(iteration); };
  std::ostringstream log;
  const ServoRunReport report = RunServo(config, log, hooks);
  EXPECT_EQ(report.status, ServoRunStatus::kConverged) << report.message;
  ASSERT_GE(report.iterations.size(), 5u);
  EXPECT_EQ(report.iterations[2].status, "held");
  EXPECT_THAT(report.iterations[2].held, HasSubstr("pose jump: the estimate is "));
  EXPECT_EQ(report.iterations[3].status, "held");  // found again, to be confirmed
  EXPECT_THAT(report.iterations[3].held, HasSubstr("found again"));
  // Frame 1 moved; 2 and 3 held; 4 confirmed frame 3 and moved.
  ASSERT_GE(moved_at.size(), 2u);
  EXPECT_EQ(moved_at[0], 1);
  EXPECT_EQ(moved_at[1], 4);
  EXPECT_EQ(report.holds, 1);
  EXPECT_EQ(report.held_frames, 2);
  EXPECT_THAT(report.message, HasSubstr("held 1 time on the way (2 frames in all"));
  EXPECT_THAT(log.str(), HasSubstr("holding at frame 2, nothing commanded: pose jump"));
  EXPECT_THAT(log.str(), HasSubstr("carrying on at frame 4 after holding 2 frames since frame 2"));
  EXPECT_LT(report.iterations.back().true_translation_error_mm, 2.0);
}

// The target slides for good (someone moved the sheet): the pose found again, confirmed by
// two frames, disagrees with the robot's motion, and the run stops without another move.
TEST(ServoLoop, ATargetMovedWhileTheLoopHeldStopsTheRun) {
  const ServoAppConfig config = Small(DefaultServoConfig());
  ServoRunHooks hooks;
  hooks.on_grab = [](int iteration, cv::Mat* gray) {
    if (iteration < 2) return;
    const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, 40, 0, 1, 0);
    cv::Mat moved;
    cv::warpAffine(*gray, moved, shift, gray->size(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    moved.copyTo(*gray);
  };
  std::ostringstream log;
  const ServoRunReport report = RunServo(config, log, hooks);
  EXPECT_EQ(report.status, ServoRunStatus::kPoseJump) << report.message;
  EXPECT_THAT(report.message, HasSubstr("pose jump at iteration 4: found again and confirmed"));
  EXPECT_THAT(report.message, HasSubstr("the target or the robot was moved while the loop held"));
  EXPECT_THAT(report.message, HasSubstr("robot stopped"));
  EXPECT_TRUE(report.robot_stopped);
  EXPECT_EQ(report.moves, 1);
}

// Any disagreement between two frames (image noise) exceeds this bound: no pose is ever
// confirmed, the robot never moves, and the run stops once it has held servo.max_lost_frames.
TEST(ServoLoop, AnUnconfirmedFirstPoseStopsBeforeTheRobotMoves) {
  ServoAppConfig config = Small(DefaultServoConfig());
  config.servo.max_pose_jump_m = 1e-7;
  config.servo.max_lost_frames = 3;
  std::ostringstream log;
  const ServoRunReport report = RunServo(config, log);
  EXPECT_EQ(report.status, ServoRunStatus::kPoseJump) << report.message;
  EXPECT_THAT(report.message, HasSubstr("no pose confirmed: held 4 frames (")) << report.message;
  EXPECT_THAT(report.message, HasSubstr("since iteration 1"));
  EXPECT_THAT(report.message, HasSubstr("pose not confirmed: estimated on its own"));
  EXPECT_THAT(report.message, HasSubstr("robot stopped"));
  EXPECT_EQ(report.moves, 0);
  ASSERT_EQ(report.iterations.size(), 5u);  // no "stopped" row: nothing moved
  EXPECT_EQ(report.iterations[0].status, "found");
  EXPECT_TRUE(SamePose(report.final_wMc, config.robot.start_wMc));
}

// servo.max_lost_frames 0: the first frame the loop would hold at stops the run.
TEST(ServoLoop, NoFramesToHoldStopsAtTheFirstPoseJump) {
  ServoAppConfig config = Small(DefaultServoConfig());
  config.servo.max_lost_frames = 0;
  ServoRunHooks hooks;
  hooks.on_grab = [](int iteration, cv::Mat* gray) {
    if (iteration == 2) gray->setTo(cv::Scalar(200));
  };
  std::ostringstream log;
  const ServoRunReport report = RunServo(config, log, hooks);
  EXPECT_EQ(report.status, ServoRunStatus::kTargetLost) << report.message;
  EXPECT_THAT(report.message, HasSubstr("target lost: held 1 frame ("));
  EXPECT_THAT(report.message, HasSubstr("since iteration 2"));
  EXPECT_EQ(report.moves, 1);
}

// The planar pose ambiguity: frame 0 shows the target as the other solution would (its tilt
// mirrored about the optical axis, the same image to first order), a pose estimated with
// status ok. Point-and-go would send the robot the whole wrong way in one move; the second
// frame, estimated on its own, contradicts it and nothing moves until a third confirms it.
TEST(ServoLoop, AFlippedFirstPoseIsNotConfirmedAndTheRobotDoesNotMove) {
  ServoAppConfig config = Small(DefaultServoConfig());
  config.servo.law.mode = ServoMode::kPointAndGo;
  const vpHomogeneousMatrix true_cMo = config.robot.start_wMc.inverse() * config.target_wMo;
  // R' = S·R·S, S = diag(1, 1, -1): the same first two rows of the first two columns.
  vpRotationMatrix S;
  S[2][2] = -1;
  const vpHomogeneousMatrix flipped_cMo(true_cMo.getTranslationVector(),
                                        vpRotationMatrix(S * true_cMo.getRotationMatrix() * S));
  ASSERT_GT(vpMath::deg(Distance(true_cMo, flipped_cMo).rotation_rad), 15.0);
  const vpImage<unsigned char> flipped = test::CameraView(config, flipped_cMo, 7);
  ServoRunHooks hooks;
  hooks.on_grab = [&](int iteration, cv::Mat* gray) {
    if (iteration != 0) return;
    const cv::Mat view(static_cast<int>(flipped.getHeight()), static_cast<int>(flipped.getWidth()),
                       CV_8UC1, flipped.bitmap);
    view.copyTo(*gray);
  };
  std::vector<vpHomogeneousMatrix> estimates;
  hooks.on_frame = [&](const ServoFrame& frame) { estimates.push_back(frame.pose.cMo); };
  std::vector<int> moved_at;
  hooks.on_move = [&](int iteration) { moved_at.push_back(iteration); };
  std::ostringstream log;
  const ServoRunReport report = RunServo(config, log, hooks);
  // Frame 0's estimate is the flipped pose (status ok), frame 1's the true one: not
  // confirmed, nothing moves; frame 2 confirms frame 1 and moves the robot.
  ASSERT_GE(estimates.size(), 3u) << log.str() << report.message;
  EXPECT_LT(vpMath::deg(Distance(estimates[0], flipped_cMo).rotation_rad), 2.0);
  EXPECT_LT(vpMath::deg(Distance(estimates[1], true_cMo).rotation_rad), 2.0);
  EXPECT_EQ(report.iterations[1].status, "held");
  EXPECT_THAT(report.iterations[1].held, HasSubstr("pose not confirmed"));
  ASSERT_FALSE(moved_at.empty());
  EXPECT_EQ(moved_at.front(), 2);
  EXPECT_EQ(report.status, ServoRunStatus::kConverged) << report.message;
  EXPECT_LT(report.iterations.back().true_translation_error_mm, 2.0);
}

// A position step above servo.max_step_m / max_step_deg stops the run before the robot moves.
TEST(ServoLoop, AStepAboveTheMaximumStopsBeforeTheRobotMoves) {
  // The default start is 135 mm and 11.2 deg from the goal: point-and-go's one move.
  struct Limits {
    double m, deg;
    const char* text;
  };
  for (const Limits& limits :
       {Limits{0.1, 60.0, "servo.max_step_m = 0.1 m or servo.max_step_deg = 60 deg"},
        Limits{0.5, 10.0, "servo.max_step_m = 0.5 m or servo.max_step_deg = 10 deg"}}) {
    ServoAppConfig config = Small(DefaultServoConfig());
    config.servo.law.mode = ServoMode::kPointAndGo;
    config.servo.max_step_m = limits.m;
    config.servo.max_step_deg = limits.deg;
    std::ostringstream log;
    const ServoRunReport report = RunServo(config, log);
    EXPECT_EQ(report.status, ServoRunStatus::kLimit) << report.message;
    EXPECT_THAT(report.message, HasSubstr("limit at iteration 1: the move of 13"));
    EXPECT_THAT(report.message,
                HasSubstr(std::string("exceeds ") + limits.text + ", the robot did not move"));
    EXPECT_EQ(report.moves, 0);
    EXPECT_TRUE(report.robot_stopped);
    EXPECT_TRUE(SamePose(report.final_wMc, config.robot.start_wMc));
  }
  // The shipped limits let it go.
  ServoAppConfig config = Small(DefaultServoConfig());
  config.servo.law.mode = ServoMode::kPointAndGo;
  std::ostringstream log;
  EXPECT_EQ(RunServo(config, log).status, ServoRunStatus::kConverged) << log.str();
}

// A move that rolls the camera by more than PoseOptions::previous_max_deg (45 deg): the next
// frame's estimate must be seeded by the pose predicted from the robot's motion, not by the pose
// before the move. On a near-square '#' (16 x 16 cm, widths 28, 26, 21, 23 mm: the line
// assignment turned by 90 deg costs ~20, under max_identification_cost) the pose before a
// 60-deg roll is closer to that wrong assignment (30 deg) than to the right one (60 deg): it
// was taken, and the run stopped on a 90-deg pose jump.
TEST(ServoLoop, ALargeRollInOneMoveConvergesWithoutAPoseJump) {
  for (const double roll_deg : {60.0, -70.0}) {
    ServoAppConfig config = Small(DefaultServoConfig());
    config.target.name = "near-square-board";
    config.target.board_width_m = config.target.board_height_m = 2.0;
    config.target.lines = {
        TargetLine{-0.08, -1.0, -0.08, 1.0, 0.028}, TargetLine{-1.0, -0.08, 1.0, -0.08, 0.026},
        TargetLine{0.08, -1.0, 0.08, 1.0, 0.021}, TargetLine{-1.0, 0.08, 1.0, 0.08, 0.023}};
    config.servo.law.mode = ServoMode::kPointAndGo;
    config.servo.max_step_deg = 90.0;
    config.goal_cdMo =
        vpHomogeneousMatrix(vpTranslationVector(0.0, 0.0, 0.5),
                            vpRotationMatrix(vpRzyxVector(vpMath::rad(roll_deg), 0, 0)));
    std::ostringstream log;
    const ServoRunReport report = RunServo(config, log);
    EXPECT_EQ(report.status, ServoRunStatus::kConverged) << roll_deg << "\n"
                                                         << log.str() << report.message;
    ASSERT_GE(report.iterations.size(), 3u) << log.str();
    // The first move rolled the camera by more than 45 deg.
    EXPECT_GT(std::abs(report.iterations[2].roll_deg - report.iterations[1].roll_deg), 50.0);
    EXPECT_LE(report.moves, 3) << roll_deg;
    EXPECT_LT(report.iterations.back().true_rotation_error_deg, 0.5) << roll_deg;
  }
}

TEST(ServoLoop, IterationLimitStopsTheRobotAndRecordsWhereItStopped) {
  ServoAppConfig config = Small(DefaultServoConfig());
  config.servo.max_iterations = 2;
  std::ostringstream log;
  const ServoRunReport report = RunServo(config, log);
  EXPECT_EQ(report.status, ServoRunStatus::kIterationLimit) << report.message;
  EXPECT_THAT(report.message, HasSubstr("iteration limit reached: servo.max_iterations = 2"));
  EXPECT_THAT(report.message, HasSubstr("; robot stopped"));
  EXPECT_EQ(report.moves, 1);  // frame 0 confirmed on frame 1, which moved
  EXPECT_TRUE(report.robot_stopped);
  // Two frames, then the row of where the move of frame 1 left the camera.
  ASSERT_EQ(report.iterations.size(), 3u);
  EXPECT_EQ(report.iterations[1].status, "iteration-limit");
  const ServoIteration& stopped = report.iterations[2];
  EXPECT_EQ(stopped.status, "stopped");
  EXPECT_EQ(stopped.iteration, 2);
  double x, y, z, pitch, roll, yaw;
  Table3Columns(report.final_wMc, &x, &y, &z, &pitch, &roll, &yaw);
  EXPECT_DOUBLE_EQ(stopped.x_mm, x);
  EXPECT_DOUBLE_EQ(stopped.z_mm, z);
  EXPECT_GT(std::abs(stopped.x_mm - report.iterations[1].x_mm), 1.0);  // it moved
  EXPECT_TRUE(std::isnan(stopped.translation_error_mm));               // no frame there
  EXPECT_LT(stopped.true_translation_error_mm, report.iterations[1].true_translation_error_mm);
  EXPECT_THAT(log.str(), HasSubstr("  stopped\n"));
}

TEST(ServoLoop, TimeLimitSaysItWasReached) {
  ServoAppConfig config = Small(DefaultServoConfig());
  config.servo.max_time_s = 1e-6;  // over before the second frame
  std::ostringstream log;
  const ServoRunReport report = RunServo(config, log);
  EXPECT_EQ(report.status, ServoRunStatus::kTimeLimit) << report.message;
  EXPECT_THAT(report.message, HasSubstr("time limit reached: servo.max_time_s = 1e-06 s ("));
  EXPECT_THAT(report.message, HasSubstr(" s elapsed) without converging; robot stopped"));
}

// A robot standing outside the box (a real arm stands where it stands): a warning at the start.
TEST(ServoLoop, ARobotStartingOutsideTheWorkspaceIsWarnedAbout) {
  ServoAppConfig config = Small(DefaultServoConfig());
  config.robot.start_wMc[2][3] = 1.02;  // above the box's z <= 1 m
  std::ostringstream log;
  const ServoRunReport report = RunServo(config, log);
  EXPECT_THAT(log.str(), HasSubstr("warning: the robot starts outside the workspace box: the "
                                   "camera's z = 1.02 m is outside [0.1, 1] m"));
  EXPECT_TRUE(report.robot_stopped);
  std::ostringstream inside;
  RunServo(Small(DefaultServoConfig()), inside);
  EXPECT_THAT(inside.str(), ::testing::Not(HasSubstr("warning")));
}

TEST(ServoLoop, InterruptFlagStopsBeforeMoving) {
  const ServoAppConfig config = Small(DefaultServoConfig());
  std::atomic<bool> interrupt{true};
  SafeRobot* seen = nullptr;
  int calls = 0;
  ServoRunHooks hooks;
  hooks.interrupt = &interrupt;
  hooks.on_robot = [&](SafeRobot* robot) {
    ++calls;
    if (robot != nullptr) seen = robot;
  };
  std::ostringstream log;
  const ServoRunReport report = RunServo(config, log, hooks);
  EXPECT_EQ(report.status, ServoRunStatus::kInterrupted);
  EXPECT_THAT(report.message, HasSubstr("interrupted by Ctrl-C or a stop from the window after 0 "
                                        "iterations; robot stopped"));
  EXPECT_TRUE(report.robot_stopped);
  EXPECT_EQ(report.moves, 0);
  EXPECT_NE(seen, nullptr);
  EXPECT_EQ(calls, 2);  // registered, then unregistered
}

std::atomic<int> g_stop_signal_callbacks{0};

TEST(StopSignalScope, EveryStopSignalSetsTheFlagCallsBackAndTheHandlersComeBack) {
  for (const int number : {SIGINT, SIGTERM, SIGHUP}) {
    const auto previous = std::signal(number, SIG_IGN);
    g_stop_signal_callbacks = 0;
    {
      const StopSignalScope signals([] { g_stop_signal_callbacks.fetch_add(1); });
      EXPECT_FALSE(signals.interrupted()->load());
      EXPECT_EQ(signals.signal_number(), 0);
      std::raise(number);  // handled: the test process goes on
      EXPECT_TRUE(signals.interrupted()->load());
      EXPECT_EQ(signals.signal_number(), number);
      std::raise(SIGINT);  // a second signal does not change which came first
      EXPECT_EQ(signals.signal_number(), number);
      EXPECT_EQ(g_stop_signal_callbacks.load(), 2);
    }
    EXPECT_EQ(std::signal(number, previous), SIG_IGN) << number;  // put back
  }
  EXPECT_EQ(StopSignalName(SIGTERM), "SIGTERM (a request to terminate)");
  EXPECT_EQ(StopSignalName(SIGINT), "Ctrl-C (SIGINT)");
}

// SIGTERM (systemd, timeout) and SIGHUP (SSH hang-up) end a run exactly as Ctrl-C does: the
// robot stopped at once, mid-move, the outputs written, the signal named as the reason. The
// signal arrives at the 6th poll of the move of iteration 2 (of 25: the simulated robot's moves
// take a second at 0.04 s a poll).
TEST(ServoCommand, SigtermAndSighupStopTheRobotDuringAMoveAndWriteTheOutputsLikeCtrlC) {
  const std::filesystem::path dir =
      std::filesystem::path(::testing::TempDir()) / "oal_servo_signal_test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string config_path = (dir / "small.yaml").string();
  {
    std::ofstream out(config_path);
    out << "camera: {px: 300, py: 300, u0: 159.5, v0: 119.5, width: 320, height: 240}\n"
        << "output: {display: off, save_frames: false}\n";
  }
  // Where the move of iteration 2 goes: the row of iteration 3 of a run left alone.
  ServoCommandOptions plain;
  plain.config_path = config_path;
  std::ostringstream plain_log;
  const ServoRunReport whole = RunServo(LoadServoConfig(plain), plain_log);
  ASSERT_GE(whole.iterations.size(), 4u) << plain_log.str();
  const ServoIteration& target = whole.iterations[3];

  std::vector<std::string> csvs;
  for (const int number : {SIGINT, SIGTERM, SIGHUP}) {
    ServoCommandOptions options;
    options.config_path = config_path;
    options.out_dir = (dir / std::to_string(number)).string();
    const StopSignalScope signals(&StopRobotOnSignal);
    ServoRunHooks hooks = StopSignalHooks(signals);
    bool raised = false;
    int polls_after = 0;
    hooks.on_move_poll = [&](int iteration, int poll) {
      if (raised) ++polls_after;
      if (iteration == 2 && poll == 5) {
        std::raise(number);  // the robot is on its way
        raised = true;
      }
    };
    std::ostringstream out;
    const ServoRunReport report = RunServoCommand(options, out, hooks);
    ASSERT_TRUE(raised) << out.str();
    EXPECT_EQ(report.status, ServoRunStatus::kInterrupted) << out.str();
    EXPECT_THAT(report.message, HasSubstr("interrupted by " + StopSignalName(number) +
                                          " during the move of iteration 2; robot stopped"));
    EXPECT_TRUE(report.robot_stopped);
    EXPECT_EQ(polls_after, 0);   // the next cycle stopped it: no poll after the signal
    EXPECT_EQ(report.moves, 2);  // iteration 1's, and iteration 2's, begun and stopped
    // The last row is where it stopped: on its way, neither where the move began nor its
    // target.
    ASSERT_EQ(report.iterations.size(), 4u) << out.str();
    const ServoIteration& began = report.iterations[2];
    const ServoIteration& stopped = report.iterations[3];
    EXPECT_EQ(began.status, "interrupted");
    EXPECT_EQ(stopped.status, "stopped");
    const auto mm_between = [](const ServoIteration& a, const ServoIteration& b) {
      return std::hypot(a.x_mm - b.x_mm, a.y_mm - b.y_mm, a.z_mm - b.z_mm);
    };
    EXPECT_GT(mm_between(stopped, began), 1.0) << out.str();
    EXPECT_GT(mm_between(stopped, target), 1.0) << out.str();
    EXPECT_GT(mm_between(began, target), mm_between(stopped, target));  // it was getting there
    double x, y, z, pitch, roll, yaw;
    Table3Columns(report.final_wMc, &x, &y, &z, &pitch, &roll, &yaw);
    EXPECT_DOUBLE_EQ(stopped.x_mm, x);
    EXPECT_DOUBLE_EQ(stopped.z_mm, z);
    csvs.push_back(ReadText(options.out_dir + "/servo.csv"));
    EXPECT_THAT(csvs.back(), HasSubstr(",interrupted\n")) << number;
    EXPECT_THAT(csvs.back(), HasSubstr(",stopped\n")) << number;
  }
  EXPECT_EQ(csvs[1], csvs[0]);  // SIGTERM: the same outputs as Ctrl-C
  EXPECT_EQ(csvs[2], csvs[0]);  // SIGHUP too
  std::filesystem::remove_all(dir);
}

// The signal handler reaches the robot only while it is registered: the loop unregisters it
// before the SafeRobot is destroyed, on every path out of the run, an exception too.
TEST(ServoCommand, TheSignalHandlerReachesTheRobotOnlyWhileItIsRegistered) {
  const StopSignalScope signals(&StopRobotOnSignal);
  const ServoRunHooks command_hooks = StopSignalHooks(signals);
  SimulatedCamera driver;
  SafeRobot robot(driver, SafetyOptions());
  ASSERT_TRUE(robot.Connect().ok());
  ASSERT_TRUE(robot.Enable().ok());
  command_hooks.on_robot(&robot);
  StopRobotOnSignal();
  EXPECT_TRUE(robot.EmergencyStopRequested());
  ASSERT_TRUE(robot.Enable().ok());  // clears the flag
  command_hooks.on_robot(nullptr);
  StopRobotOnSignal();
  EXPECT_FALSE(robot.EmergencyStopRequested());

  // An exception out of the loop: unregistered while the SafeRobot still lives.
  const ServoAppConfig config = Small(DefaultServoConfig());
  std::vector<SafeRobot*> calls;
  bool alive_at_unregister = false;
  ServoRunHooks hooks;
  hooks.on_robot = [&](SafeRobot* running) {
    if (running == nullptr && !calls.empty() && calls.back() != nullptr) {
      // Still the live robot: stopped by the guard after this returns, state readable.
      alive_at_unregister = calls.back()->state() != SafeRobotState::kDisconnected;
    }
    calls.push_back(running);
    command_hooks.on_robot(running);
  };
  hooks.on_grab = [](int iteration, cv::Mat*) {
    if (iteration == 1) throw std::runtime_error("frame grabber fell over");
  };
  std::ostringstream log;
  EXPECT_THROW(RunServo(config, log, hooks), std::runtime_error);
  ASSERT_EQ(calls.size(), 2u);
  EXPECT_NE(calls[0], nullptr);
  EXPECT_EQ(calls[1], nullptr);
  EXPECT_TRUE(alive_at_unregister);
  StopRobotOnSignal();  // nothing registered: a no-op
}

TEST(ServoCommand, WritesTheCsvAtomically) {
  const std::filesystem::path dir =
      std::filesystem::path(::testing::TempDir()) / "oal_servo_command_test";
  std::filesystem::remove_all(dir);
  const std::string config_path = (dir / "cfg.yaml").string();
  std::filesystem::create_directories(dir);
  {
    std::ofstream out(config_path);
    out << ReadText(SourcePath("config/servo-sim.yaml")) << "\n# small\n";  // the same, from a file
  }
  ServoCommandOptions options;
  options.config_path = config_path;
  options.out_dir = (dir / "out").string();
  std::ostringstream out;
  const ServoRunReport report = RunServoCommand(options, out);
  EXPECT_EQ(report.status, ServoRunStatus::kConverged) << out.str();
  const std::string csv = ReadText((dir / "out" / "servo.csv").string());
  EXPECT_THAT(csv, HasSubstr("iteration,x_mm,y_mm,z_mm,pitch_deg,roll_deg"));
  EXPECT_THAT(csv, HasSubstr(",converged\n"));
  std::filesystem::remove_all(dir);
}

// The console table explains its first frames once, names its units, shows the simulation's
// true error beside the estimate, and its last line says where the camera truly ended.
TEST(ServoCommand, TheTableShowsUnitsAndTheTrueErrorBesideTheEstimate) {
  const std::filesystem::path dir =
      std::filesystem::path(::testing::TempDir()) / "oal_servo_table_test";
  std::filesystem::remove_all(dir);
  ServoCommandOptions options;
  options.out_dir = (dir / "out").string();
  options.display = "off";
  std::ostringstream out;
  const ServoRunReport report = RunServoCommand(options, out);
  EXPECT_EQ(report.status, ServoRunStatus::kConverged) << out.str();
  EXPECT_THAT(out.str(), HasSubstr("frame 1, the robot still, confirms it"));
  EXPECT_THAT(out.str(), HasSubstr("pitch deg  roll deg   yaw deg    est mm   est deg   true mm"));
  EXPECT_THAT(out.str(), HasSubstr("within the tolerances after "));
  EXPECT_THAT(out.str(), HasSubstr("oalservo servo: true error (simulation): "));
  EXPECT_THAT(out.str(), ::testing::Not(HasSubstr("WARNING")));
  EXPECT_THAT(out.str(), ::testing::Not(HasSubstr("nan")));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace oal
