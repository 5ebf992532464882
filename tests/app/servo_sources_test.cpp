// The servo app beyond the simulated default: replayed recordings (open loop), the
// V4L2 source failing clearly, a goal taught from an image, the output files (plot, annotated
// frames, window), the per-law convergence from random starts, and the new config sections.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <sstream>
#include <string>

#include "app/config.h"
#include "app/live_window.h"
#include "app/servo_accuracy.h"
#include "app/servo_accuracy_command.h"
#include "app/servo_command.h"
#include "app/servo_output.h"
#include "app/servo_run.h"
#include "scene/scene.h"
#include "servo_test_util.h"
#include "tests/test_util.h"

namespace oal {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;

// What the configured camera sees from cMo, as the renderer draws it, written as PNG.
void WriteView(const ServoAppConfig& config, const vpHomogeneousMatrix& cMo, std::uint64_t seed,
               const std::string& path) {
  vpImage<unsigned char> image = test::CameraView(config, cMo, seed);
  cv::imwrite(path, cv::Mat(static_cast<int>(image.getHeight()), static_cast<int>(image.getWidth()),
                            CV_8UC1, image.bitmap));
}

std::string ErrorOf(const std::string& yaml) {
  return test::ConfigErrorOf(yaml, "dir/servo.yaml");
}

using test::SamePose;
using test::Small;

TEST(ServoConfigSections, SourceOutputAndGoalImageAreReadAndChecked) {
  const AppConfig config = ParseConfig(
      "source: {type: replay, path: rec/frame_%04d.png}\n"
      "output: {directory: out/x, display: off, save_frames: false}\n"
      "goal: {image: goal.png}\n",
      "dir/servo.yaml");
  EXPECT_EQ(config.source.type, SourceType::kReplay);
  EXPECT_EQ(config.source.path, "dir/rec/frame_%04d.png");  // next to the config file
  EXPECT_EQ(config.output.directory, "out/x");
  EXPECT_EQ(config.output.display, DisplayMode::kOff);
  EXPECT_FALSE(config.output.save_frames);
  EXPECT_EQ(config.goal_image, "dir/goal.png");
  EXPECT_EQ(config.goal_image_origin, "dir/servo.yaml:3");

  EXPECT_THAT(ErrorOf("source: {type: webcam}\n"),
              HasSubstr("dir/servo.yaml:1: 'source.type' is invalid"));
  // A camera's mode: format, size and rate, as `oalservo cameras` lists them.
  const AppConfig camera = ParseConfig(
      "source: {type: v4l2, device: /dev/video2, format: mjpeg, width: 1280, height: 720, "
      "fps: 30}\n",
      "dir/servo.yaml");
  EXPECT_EQ(camera.source.format, CameraFormat::kMjpeg);
  EXPECT_EQ(camera.source.width, 1280);
  EXPECT_EQ(camera.source.height, 720);
  EXPECT_EQ(camera.source.fps, 30);
  EXPECT_THAT(ErrorOf("source: {type: v4l2, fps: 2000}\n"),
              HasSubstr("'source.fps' is invalid: 2000 (needs"));
  EXPECT_THAT(ErrorOf("source:\n  type: v4l2\n  format: h264\n"),
              HasSubstr("dir/servo.yaml:3: 'source.format' is invalid: 'h264' is not one of auto, "
                        "mjpeg, yuyv, grey"));
  EXPECT_THAT(ErrorOf("source: {type: v4l2, width: 1280}\n"),
              HasSubstr("'source.width' is invalid: 1280x0 (needs"));
  EXPECT_THAT(ErrorOf("source: {type: replay}\n"),
              HasSubstr("dir/servo.yaml:1: section 'source' is invalid: source.path = '' (needs"));
  EXPECT_THAT(ErrorOf("output:\n  display: maybe\n"),
              HasSubstr("dir/servo.yaml:2: 'output.display' is invalid"));
  EXPECT_THAT(ErrorOf("goal:\n  cdMo: {translation_m: [0, 0, 0.5], rxyz_deg: [0, 0, 0]}\n"
                      "  image: g.png\n"),
              HasSubstr("dir/servo.yaml:3: 'goal.image' and 'goal.cdMo' (line 2) both set"));
  EXPECT_THAT(ErrorOf("goal: {image: ''}\n"), HasSubstr("'goal.image' must not be empty"));
}

// The small default config replaying `count` frames (frame_0000.png ...) written to `dir`,
// all seen from the robot's start pose.
ServoAppConfig ReplayOfStillFrames(const test::TestDir& dir, int count) {
  ServoAppConfig config = Small(DefaultServoConfig());
  const vpHomogeneousMatrix start_cMo = config.robot.start_wMc.inverse() * config.target_wMo;
  for (int i = 0; i < count; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "frame_%04d.png", i);
    WriteView(config, start_cMo, 7 + i, dir / name);
  }
  config.source.type = SourceType::kReplay;
  config.source.path = dir / "frame_%04d.png";
  return config;
}

TEST(ServoSources, ReplayRunsOpenLoopToTheEndWithoutMovingTheRobot) {
  const test::TestDir dir;
  const ServoAppConfig config = ReplayOfStillFrames(dir, 3);
  std::ostringstream log;
  const ServoRunReport report = RunServo(config, log);
  EXPECT_EQ(report.status, ServoRunStatus::kEndOfInput) << report.message;
  EXPECT_THAT(report.message, HasSubstr("after 3 frames"));
  EXPECT_THAT(log.str(), HasSubstr("open loop, the robot is not moved"));
  EXPECT_EQ(report.moves, 0);
  EXPECT_TRUE(SamePose(report.final_wMc, config.robot.start_wMc));
  ASSERT_EQ(report.iterations.size(), 3u);
  for (const ServoIteration& row : report.iterations) {
    // The law still sees the ~135 mm to the goal in every frame; there is no truth.
    EXPECT_NEAR(row.translation_error_mm, report.iterations[0].translation_error_mm, 2.0);
    EXPECT_GT(row.translation_error_mm, 100.0);
    EXPECT_TRUE(std::isnan(row.true_translation_error_mm));
  }
  EXPECT_TRUE(report.robot_stopped);

  // A frame missing in the middle of the recording ends the replay there, with a warning.
  fs::rename(dir / "frame_0001.png", dir / "moved.png");
  std::ostringstream gap_log;
  EXPECT_EQ(RunServo(config, gap_log).iterations.size(), 1u);
  EXPECT_THAT(gap_log.str(), HasSubstr("warning: pattern '" + config.source.path +
                                       "': the sequence ends at the missing file"));
}

// With the default config (no servo.max_iterations) a replay is played to its end, however
// long: end-of-input, exit 0, as the README says.
TEST(ServoSources, AReplayLongerThanTheLawsLimitRunsToItsEnd) {
  const test::TestDir dir;
  const ServoAppConfig config = ReplayOfStillFrames(dir, 35);
  ASSERT_EQ(config.servo.max_iterations, 0);
  std::ostringstream log;
  const ServoRunReport report = RunServo(config, log);
  EXPECT_EQ(report.status, ServoRunStatus::kEndOfInput) << report.message;
  EXPECT_EQ(report.iterations.size(), 35u);
}

// A recording exactly servo.max_iterations frames long was played to its end: end-of-input
// (exit 0), as a longer one would be cut by the limit and a shorter one end on its own.
TEST(ServoSources, ReplayAsLongAsTheIterationLimitEndsWithEndOfInput) {
  const test::TestDir dir;
  ServoAppConfig config = ReplayOfStillFrames(dir, 4);
  config.servo.max_iterations = 4;
  std::ostringstream log;
  ServoRunReport report = RunServo(config, log);
  EXPECT_EQ(report.status, ServoRunStatus::kEndOfInput) << report.message;
  EXPECT_THAT(report.message, HasSubstr("after 4 frames (servo.max_iterations = 4)"));
  EXPECT_EQ(report.iterations.size(), 4u);
  EXPECT_EQ(report.iterations.back().status, "end-of-input");

  config.servo.max_iterations = 3;  // a frame left: the limit
  report = RunServo(config, log);
  EXPECT_EQ(report.status, ServoRunStatus::kIterationLimit) << report.message;
  EXPECT_EQ(report.iterations.size(), 3u);

  config.servo.max_iterations = 5;  // shorter than the limit
  report = RunServo(config, log);
  EXPECT_EQ(report.status, ServoRunStatus::kEndOfInput) << report.message;
  EXPECT_EQ(report.iterations.size(), 4u);
}

TEST(ServoSources, AMissingRecordingNamesSourcePathAndWhereItWasSet) {
  const test::TestDir dir;
  test::WriteText(dir / "replay.yaml",
                  "camera: {px: 300, py: 300, u0: 159.5, v0: 119.5, width: 320, height: 240}\n"
                  "source:\n  type: replay\n  path: missing.avi\n");
  ServoCommandOptions options;
  options.config_path = dir / "replay.yaml";
  std::ostringstream log;
  const std::string error =
      test::ErrorMessageOf<std::runtime_error>([&] { RunServo(LoadServoConfig(options), log); });
  EXPECT_THAT(error, HasSubstr(options.config_path + ":4: source.path '" +
                               (dir.path() / "missing.avi").string() + "' cannot be opened: "));
}

TEST(ServoSources, ReplayOfAWrongSizeOrMissingRecordingFailsClearly) {
  const test::TestDir dir;
  ServoAppConfig config = Small(DefaultServoConfig());
  config.source.type = SourceType::kReplay;
  config.source.path = dir / "missing.avi";
  std::ostringstream log;
  EXPECT_THROW(
      {
        try {
          RunServo(config, log);
        } catch (const std::runtime_error& error) {
          EXPECT_THAT(error.what(), HasSubstr("missing.avi"));
          throw;
        }
      },
      std::runtime_error);

  cv::imwrite(dir / "big.png", cv::Mat(480, 640, CV_8UC1, cv::Scalar(128)));
  config.source.path = dir / "big.png";
  const ServoRunReport report = RunServo(config, log);
  EXPECT_EQ(report.status, ServoRunStatus::kError);
  EXPECT_THAT(report.message, HasSubstr("gives 640x480 frames but camera.width x camera.height "
                                        "is 320x240"));
  EXPECT_TRUE(report.robot_stopped);
}

// A recording with a frame that cannot be decoded: the run stops there and says which, rather
// than skip it unseen when the frame was read ahead to tell the end.
TEST(ServoSources, AnUnreadableFrameInAReplayStopsTheRunNamingIt) {
  const test::TestDir dir;
  const ServoAppConfig config = ReplayOfStillFrames(dir, 4);
  test::WriteText(dir / "frame_0002.png", "not a png");
  std::ostringstream log;
  const ServoRunReport report = RunServo(config, log);
  EXPECT_EQ(report.status, ServoRunStatus::kError) << report.message;
  EXPECT_THAT(report.message, HasSubstr("cannot read the next frame at iteration 2"));
  EXPECT_THAT(report.message, HasSubstr("frame_0002.png"));
  EXPECT_EQ(report.iterations.size(), 2u);
}

TEST(ServoSources, V4l2WithoutADeviceOrWithTheSimulatedRobotFailsBeforeMoving) {
  ServoAppConfig config = Small(DefaultServoConfig());
  config.source.type = SourceType::kV4l2;
  config.source.device = "/dev/video97";
  std::ostringstream log;
  try {
    RunServo(config, log);
    FAIL() << "v4l2 with the simulated robot must be refused";
  } catch (const std::invalid_argument& error) {
    EXPECT_THAT(error.what(), HasSubstr("needs a real robot carrying the camera"));
    EXPECT_THAT(error.what(), HasSubstr("type: replay, path: /dev/video97"));
  }
  config.source.type = SourceType::kReplay;
  config.source.path = "/dev/video97";
  try {
    RunServo(config, log);
    FAIL() << "a missing device must be an error";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), HasSubstr("no V4L2 device at /dev/video97"));
  }
}

TEST(ServoGoal, TaughtFromAnImageTheLoopReachesThePoseOfThatImage) {
  const test::TestDir dir;
  ServoAppConfig config = Small(DefaultServoConfig());
  // The goal shown to the robot: 0.45 m from the target, turned 8 deg about y and 20 about z.
  const vpHomogeneousMatrix shown_cdMo(0.02, -0.01, 0.45, 0.0, vpMath::rad(8), vpMath::rad(20));
  WriteView(config, shown_cdMo, 99, dir / "goal.png");
  config.goal_image = dir / "goal.png";
  config.goal_image_origin = "servo.yaml:7";
  const vpHomogeneousMatrix taught = TeachGoal(config);
  EXPECT_LT(Distance(taught, shown_cdMo).translation_m, 0.002);

  std::ostringstream log;
  const ServoRunReport report = RunServo(config, log);
  ASSERT_EQ(report.status, ServoRunStatus::kConverged) << log.str() << report.message;
  EXPECT_THAT(log.str(), HasSubstr("goal taught from"));
  const vpHomogeneousMatrix final_cMo = report.final_wMc.inverse() * config.target_wMo;
  const PoseDistance off = Distance(final_cMo * shown_cdMo.inverse(), vpHomogeneousMatrix());
  EXPECT_LT(off.translation_m, 0.005);  // 320x240 images: a few mm
  EXPECT_LT(vpMath::deg(off.rotation_rad), 0.5);
}

TEST(ServoGoal, AGoalImageWithoutTheTargetOrUnreadableIsAnErrorNamingIt) {
  const test::TestDir dir;
  ServoAppConfig config = Small(DefaultServoConfig());
  cv::imwrite(dir / "blank.png", cv::Mat(240, 320, CV_8UC1, cv::Scalar(200)));
  config.goal_image = dir / "blank.png";
  config.goal_image_origin = "servo.yaml:7";
  try {
    TeachGoal(config);
    FAIL();
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), HasSubstr("servo.yaml:7: goal.image '"));
    EXPECT_THAT(error.what(), HasSubstr("blank.png': no pose of target 'four-line-a3'"));
  }
  test::WriteText(dir / "bad.png", "not a png");
  config.goal_image = dir / "bad.png";
  try {
    TeachGoal(config);
    FAIL();
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), HasSubstr("bad.png': cannot read or decode the image"));
  }
}

TEST(ServoOutput, CommandWritesCsvPlotAndAnnotatedFrames) {
  const test::TestDir dir;
  const std::string config_path = dir / "small.yaml";
  test::WriteText(config_path,
                  "camera: {px: 300, py: 300, u0: 159.5, v0: 119.5, width: 320, height: 240}\n");
  ServoCommandOptions options;
  options.config_path = config_path;
  options.out_dir = dir / "out";
  options.display = "off";
  options.mode = "point-and-go";
  // A frame an earlier, longer run left behind is removed.
  fs::create_directories(dir.path() / "out" / "frames");
  test::WriteText(dir.path() / "out" / "frames" / "iter_0099.png", "stale");
  std::ostringstream out;
  const ServoRunReport report = RunServoCommand(options, out);
  ASSERT_EQ(report.status, ServoRunStatus::kConverged) << out.str();
  EXPECT_THAT(out.str(), HasSubstr("point-and-go law"));
  EXPECT_THAT(test::ReadText(dir.path() / "out" / "servo.csv"), HasSubstr(",converged\n"));
  const std::string png = test::ReadText(dir.path() / "out" / "servo-error.png");
  ASSERT_GT(png.size(), 8u) << out.str();
  EXPECT_EQ(png.substr(1, 3), "PNG");
  for (std::size_t i = 0; i < report.iterations.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "iter_%04zu.png", i);
    const cv::Mat frame = cv::imread((dir.path() / "out" / "frames" / name).string());
    ASSERT_FALSE(frame.empty()) << name;
    EXPECT_EQ(frame.cols, 320);
    EXPECT_EQ(frame.channels(), 3);
  }
  EXPECT_FALSE(fs::exists(dir.path() / "out" / "frames" / "iter_0099.png"));
  // Nothing temporary is left behind.
  for (const auto& entry : fs::directory_iterator(dir.path() / "out")) {
    EXPECT_EQ(entry.path().string().find(".tmp"), std::string::npos) << entry.path();
  }
}

// $DISPLAY as in an SSH session whose X forwarding is gone: set, but no server answers.
class UnreachableDisplay {
 public:
  UnreachableDisplay() {
    if (const char* saved = std::getenv("DISPLAY")) saved_ = saved;
    ::setenv("DISPLAY", ":987", 1);
  }
  ~UnreachableDisplay() {
    if (saved_) {
      ::setenv("DISPLAY", saved_->c_str(), 1);
    } else {
      ::unsetenv("DISPLAY");
    }
  }

 private:
  std::optional<std::string> saved_;
};

TEST(ServoOutput, AnUnreachableDisplayFallsBackToFramesInAutoAndFailsBeforeMovingInOn) {
  const test::TestDir dir;
  const std::string config_path = dir / "small.yaml";
  test::WriteText(config_path,
                  "camera: {px: 300, py: 300, u0: 159.5, v0: 119.5, width: 320, height: 240}\n");
  const UnreachableDisplay display;
  if (!CanOpenLiveWindow()) GTEST_SKIP() << "this ViSP has no X11";
  ServoCommandOptions options;
  options.config_path = config_path;
  options.out_dir = dir / "auto";
  options.display = "auto";
  options.mode = "point-and-go";
  std::ostringstream out;
  const ServoRunReport report = RunServoCommand(options, out);
  EXPECT_EQ(report.status, ServoRunStatus::kConverged) << out.str();
  EXPECT_THAT(out.str(), ::testing::Not(HasSubstr("live window")));
  EXPECT_TRUE(fs::exists(dir.path() / "auto" / "frames" / "iter_0000.png"));  // frames instead

  options.out_dir = dir / "on";
  options.display = "on";
  int robots = 0;
  ServoRunHooks hooks;
  hooks.on_robot = [&](SafeRobot* robot) { robots += robot != nullptr; };
  const std::string error =
      test::ErrorMessageOf<std::runtime_error>([&] { RunServoCommand(options, out, hooks); });
  EXPECT_THAT(error, HasSubstr("output.display is on but cannot open a window on the X display "
                               "':987'"));
  EXPECT_EQ(robots, 0);  // before the robot was connected
  EXPECT_FALSE(fs::exists(dir.path() / "on" / "servo.csv"));
}

// A run that cannot begin (bad port, missing recording) leaves an earlier run's results as
// they were; a directory that cannot take the results fails before the robot is touched.
TEST(ServoOutput, ARunThatCannotBeginKeepsTheEarlierResults) {
  const test::TestDir dir;
  const fs::path out = dir.path() / "out";
  fs::create_directories(out / "frames");
  test::WriteText(out / "servo.csv", "earlier run");
  test::WriteText(out / "servo-error.png", "earlier plot");
  test::WriteText(out / "frames" / "iter_0000.png", "earlier frame");
  const std::string small =
      "camera: {px: 300, py: 300, u0: 159.5, v0: 119.5, width: 320, height: 240}\n"
      "output: {display: off}\n";
  test::WriteText(dir / "port.yaml", small +
                                         "robot:\n  type: scorbot\n  scorbot:\n"
                                         "    port: /dev/ttyOAL-missing\n");
  test::WriteText(dir / "replay.yaml", small + "source: {type: replay, path: missing.avi}\n");
  ServoCommandOptions options;
  options.out_dir = out;
  options.config_path = dir / "port.yaml";
  std::ostringstream log;
  const ServoRunReport report = RunServoCommand(options, log);
  EXPECT_EQ(report.status, ServoRunStatus::kError);
  EXPECT_FALSE(report.started);
  EXPECT_THAT(report.message, HasSubstr("cannot connect the robot: scorbot: "));
  EXPECT_THAT(report.message, HasSubstr("(check " + options.config_path +
                                        ":6: robot.scorbot.port = '/dev/ttyOAL-missing')"));
  EXPECT_THAT(log.str(), HasSubstr("nothing written"));

  options.config_path = dir / "replay.yaml";
  EXPECT_THAT(test::ErrorMessageOf<std::runtime_error>([&] { RunServoCommand(options, log); }),
              HasSubstr("source.path"));

  EXPECT_EQ(test::ReadText(out / "servo.csv"), "earlier run");
  EXPECT_EQ(test::ReadText(out / "servo-error.png"), "earlier plot");
  EXPECT_EQ(test::ReadText(out / "frames" / "iter_0000.png"), "earlier frame");
}

// A run that cannot start in a fresh --out leaves no folder behind (it says nothing was written).
TEST(ServoOutput, ARunThatCannotStartLeavesNoFolder) {
  const test::TestDir dir;
  test::WriteText(dir / "port.yaml",
                  "camera: {px: 300, py: 300, u0: 159.5, v0: 119.5, width: 320, height: 240}\n"
                  "output: {display: off}\n"
                  "robot:\n  type: scorbot\n  scorbot:\n    port: /dev/ttyOAL-missing\n");
  test::WriteText(dir / "replay.yaml",
                  "output: {display: off}\n"
                  "source: {type: replay, path: missing.avi}\n");
  for (const char* config : {"port.yaml", "replay.yaml"}) {
    ServoCommandOptions options;
    options.out_dir = dir / "fresh";
    options.config_path = dir / config;
    std::ostringstream log;
    try {
      const ServoRunReport report = RunServoCommand(options, log);
      EXPECT_FALSE(report.started) << config;
      EXPECT_THAT(log.str(), HasSubstr("nothing written")) << config;
    } catch (const std::runtime_error&) {
      // a bad source is an error before the run: the folder goes too
    }
    EXPECT_FALSE(fs::exists(dir / "fresh")) << config;
  }
}

TEST(ServoOutput, AnOutputDirectoryThatCannotBeWrittenFailsBeforeTheRobotMoves) {
  const test::TestDir dir;
  test::WriteText(dir / "file", "a file, not a directory");
  ServoCommandOptions options;
  options.out_dir = (dir.path() / "file" / "out").string();
  options.display = "off";
  int robots = 0;
  ServoRunHooks hooks;
  hooks.on_robot = [&](SafeRobot* robot) { robots += robot != nullptr; };
  std::ostringstream log;
  const std::string error =
      test::ErrorMessageOf<std::runtime_error>([&] { RunServoCommand(options, log, hooks); });
  EXPECT_THAT(error,
              HasSubstr("cannot create the output directory (--out) '" + options.out_dir + "'"));
  EXPECT_EQ(robots, 0);

  // servo-accuracy --out: checked before the first run (whose recording is missing here).
  if (!fs::is_directory("/proc")) GTEST_SKIP() << "no /proc: a directory nobody may write";
  test::WriteText(dir / "replay.yaml", "source: {type: replay, path: missing.avi}\n");
  const std::string accuracy = test::ErrorMessageOf<std::runtime_error>([&] {
    test::RunWithArgs(RunServoAccuracy, {"servo-accuracy", "--config", dir / "replay.yaml",
                                         "--starts", "1", "--out", "/proc/oal-accuracy.json"});
  });
  EXPECT_THAT(accuracy, HasSubstr("cannot write into the directory of --out '/proc'"));
}

TEST(ServoOutput, DisplayOnWithoutAnXServerIsAClearErrorBeforeMoving) {
  const char* saved = std::getenv("DISPLAY");
  const std::string saved_display = saved != nullptr ? saved : "";
  ::unsetenv("DISPLAY");
  ServoCommandOptions options;
  options.out_dir = "";
  options.display = "on";
  std::ostringstream out;
  try {
    RunServoCommand(options, out);
    ADD_FAILURE() << "display on without X must fail";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), HasSubstr("output.display is on but no window can be opened"));
  }
  if (saved != nullptr) ::setenv("DISPLAY", saved_display.c_str(), 1);
}

TEST(ServoOutput, PlotScriptHasBothSeriesAndTheTolerances) {
  ServoRunReport report;
  report.status = ServoRunStatus::kConverged;
  ServoIteration row;
  row.translation_error_mm = 12.5;
  row.rotation_error_deg = 1.5;
  row.true_translation_error_mm = std::nan("");
  row.true_rotation_error_deg = std::nan("");
  report.iterations.push_back(row);
  ServoOptions law;
  law.translation_tolerance_m = 0.002;
  const std::string script = ServoPlotScript(report, law, "it's.png");
  EXPECT_THAT(script, HasSubstr("0 12.5 1.5 nan nan\n"));
  EXPECT_THAT(script, HasSubstr("set output 'it''s.png'"));
  EXPECT_THAT(script, HasSubstr(", 2 with lines dt 2"));                // the 2 mm tolerance
  EXPECT_THAT(script, ::testing::Not(HasSubstr("true (simulation)")));  // no truth: no series
  EXPECT_THAT(script, ::testing::Not(HasSubstr("held")));               // nothing held
  // A frame the loop held at is shaded, and the plot says what the shade means.
  row.iteration = 1;
  row.status = "held";
  report.iterations.push_back(row);
  const std::string held = ServoPlotScript(report, law, "held.png");
  EXPECT_THAT(held, HasSubstr("set object 1 rect from 0.5, graph 0 to 1.5, graph 1 behind"));
  EXPECT_THAT(held, HasSubstr("shaded: held, nothing commanded"));
}

// Convergence from random starts (0.3-0.8 m, up to 30 deg off), image in the loop,
// every law; a few starts on small images here, 100 at 640x480 in docs/BENCHMARKS.md.
TEST(ServoAccuracy, EveryLawConvergesFromRandomStarts) {
  const ServoAppConfig config = Small(DefaultServoConfig());
  ServoAccuracyOptions options;
  options.starts = 2;  // the 100-start figures: docs/BENCHMARKS.md
  options.seed = 3;
  const std::vector<vpHomogeneousMatrix> starts = SampleServoStarts(config, options);
  ASSERT_EQ(starts.size(), 2u);
  EXPECT_FALSE(SamePose(starts[0], starts[1]));
  EXPECT_TRUE(SamePose(SampleServoStarts(config, options)[1], starts[1]));  // deterministic
  const ServoAccuracyReport report = EvaluateServoAccuracy(config, options);
  ASSERT_EQ(report.laws.size(), 3u);
  for (const ServoAccuracyLaw& law : report.laws) {
    for (const ServoAccuracyRun& run : law.runs) {
      EXPECT_EQ(run.status, ServoRunStatus::kConverged)
          << ToString(law.mode) << " start " << run.start << ": " << run.message;
      EXPECT_GE(run.start_distance_m, 0.05);
      EXPECT_LT(run.final_translation_error_mm, 5.0) << ToString(law.mode);
    }
  }
}

TEST(ServoAccuracy, BadOptionsNameTheOption) {
  const ServoAppConfig config = Small(DefaultServoConfig());
  const auto error = [&](ServoAccuracyOptions options) {
    try {
      SampleServoStarts(config, options);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  ServoAccuracyOptions options;
  options.starts = 0;
  EXPECT_THAT(error(options),
              HasSubstr("ServoAccuracyOptions::starts = 0. Violated constraint: 1 <= starts"));
  options = ServoAccuracyOptions();
  options.max_distance_m = 0.2;  // below min_distance_m = 0.3
  EXPECT_THAT(error(options),
              HasSubstr("max_distance_m = 0.2. Violated constraint: max_distance_m >= "
                        "min_distance_m"));
  options = ServoAccuracyOptions();
  options.modes.clear();
  EXPECT_THAT(
      error(options),
      HasSubstr("ServoAccuracyOptions::modes = none. Violated constraint: at least one law"));
}

TEST(ServoLoopTable3, PointAndGoReachesTheGoalWithinThreeMoves) {
  ServoAppConfig config = test::ShippedServoConfig("table3-sim.yaml");
  config.servo.law.mode = ServoMode::kPointAndGo;
  std::ostringstream log;
  const ServoRunReport report = RunServo(config, log);
  ASSERT_EQ(report.status, ServoRunStatus::kConverged) << log.str() << report.message;
  EXPECT_LE(report.moves, 3) << log.str();
  EXPECT_LE(report.iterations.back().true_translation_error_mm, 1.0);
  EXPECT_LE(report.iterations.back().true_rotation_error_deg, 0.1);
}

}  // namespace
}  // namespace oal

namespace oal {
namespace {

// Failure injection during the run: the frame is changed before detection.
ServoRunReport RunWithFrameChange(int from_iteration, const std::function<void(cv::Mat*)>& change) {
  ServoAppConfig config = Small(DefaultServoConfig());
  config.servo.max_lost_frames = 3;
  ServoRunHooks hooks;
  hooks.on_grab = [&](int iteration, cv::Mat* gray) {
    if (iteration >= from_iteration) change(gray);
  };
  std::ostringstream log;
  return RunServo(config, log, hooks);
}

TEST(ServoFailureInjection, TargetLeavingTheViewStopsTheRobot) {
  const ServoRunReport report =
      RunWithFrameChange(3, [](cv::Mat* gray) { gray->setTo(cv::Scalar(200)); });
  EXPECT_EQ(report.status, ServoRunStatus::kTargetLost) << report.message;
  EXPECT_THAT(report.message, HasSubstr("target lost: held 4 frames"));
  EXPECT_THAT(report.message, HasSubstr("since iteration 3"));
  EXPECT_THAT(report.message, HasSubstr("the last reason: no pose: not-enough-lines"));
  EXPECT_THAT(report.message, HasSubstr("robot stopped"));
  EXPECT_EQ(report.moves, 2);  // frames 1 and 2 moved; none after the frame without the target
  EXPECT_TRUE(report.robot_stopped);
  EXPECT_EQ(report.iterations.back().status, "target-lost");
}

TEST(ServoFailureInjection, OccludedLinesStopTheRobot) {
  // A sheet of paper over the right half of the view hides two of the four lines.
  const ServoRunReport report = RunWithFrameChange(2, [](cv::Mat* gray) {
    (*gray)(cv::Rect(gray->cols / 2, 0, gray->cols / 2, gray->rows)).setTo(cv::Scalar(215));
  });
  EXPECT_EQ(report.status, ServoRunStatus::kTargetLost) << report.message;
  EXPECT_THAT(report.message, HasSubstr("since iteration 2"));
  EXPECT_EQ(report.moves, 1);
  EXPECT_TRUE(report.robot_stopped);
}

}  // namespace
}  // namespace oal
