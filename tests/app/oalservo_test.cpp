// Smoke tests of the real `oalservo` binary: the command table, --help, exit codes and the
// error format of main(). Everything else is tested through the plain functions.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "tests/app/command_test_util.h"
#include "tests/test_util.h"

namespace oal {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;

// The command names listed by `oalservo --help`, so new commands are covered automatically.
std::vector<std::string> ListedCommands(const std::string& help) {
  std::vector<std::string> names;
  std::istringstream in(help.substr(help.find("Commands:")));
  std::string line;
  std::getline(in, line);
  while (std::getline(in, line) && line.rfind("  ", 0) == 0) {
    std::istringstream words(line);
    std::string name;
    words >> name;
    names.push_back(name);
  }
  return names;
}

TEST(Oalservo, HelpListsTheCommandsAndEachHasItsOwnHelp) {
  test::TestDir dir;
  const test::OalservoRun help = test::RunOalservo(dir, "--help");
  ASSERT_EQ(help.exit_code, 0) << help.err;
  const std::vector<std::string> commands = ListedCommands(help.out);
  EXPECT_THAT(commands, ::testing::IsSupersetOf({"detect", "render", "demo"}));
  for (const std::string& command : commands) {
    const test::OalservoRun sub = test::RunOalservo(dir, command + " --help");
    EXPECT_EQ(sub.exit_code, 0) << command << ": " << sub.err;
    EXPECT_THAT(sub.out, HasSubstr("oalservo " + command)) << command;
    EXPECT_THAT(sub.out, HasSubstr("--help")) << command;
    // A runnable example, so that nobody has to guess the first command line.
    EXPECT_THAT(sub.out, ::testing::ContainsRegex("Examples?:\n")) << command;
    EXPECT_THAT(sub.out, HasSubstr("\n  oalservo " + command + " ")) << command;
    // One type for --config in every command that has it: a file that must exist.
    if (sub.out.find("  --config ") != std::string::npos) {
      EXPECT_THAT(sub.out, HasSubstr("--config TEXT:FILE")) << command;
    }
  }
}

// evaluate's warnings (here: nearly nothing detected) reach the console, not only summary.json.
TEST(Oalservo, EvaluateSaysOnTheConsoleWhatItsSummaryWarnsAbout) {
  const std::string pattern = "/usr/share/visp-images-data/ViSP-images/line/image.%04d.pgm";
  if (!std::filesystem::exists("/usr/share/visp-images-data/ViSP-images/line/image.0001.pgm")) {
    GTEST_SKIP() << "Debian's visp-images-data is not installed";
  }
  test::TestDir dir;
  const test::OalservoRun run = test::RunOalservo(
      dir, "evaluate '" + pattern + "' --no-video --max-frames 3 --out '" + dir / "out" + "'");
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_THAT(run.err, ::testing::ContainsRegex("oalservo evaluate: warning: [^:]+: the target's "
                                                "[0-9]+ lines were found in only 0 of 3 frames"));
  EXPECT_THAT(run.err, HasSubstr("config/visp_line_edges.yaml"));

  // With the edge polarity already given, the hint does not advise it again: the sequence's
  // one edge is held in most frames, and the hint says so and how to ask for one line.
  const test::OalservoRun edges =
      test::RunOalservo(dir, "evaluate '" + pattern + "' --no-video --config '" + OAL_SOURCE_DIR +
                                 "/config/visp_line_edges.yaml' --out '" + dir / "edges" + "'");
  EXPECT_EQ(edges.exit_code, 0) << edges.err;
  EXPECT_THAT(edges.err, HasSubstr("lines were found in only 0 of 33 frames"));
  EXPECT_THAT(edges.err, Not(HasSubstr("visp_line_edges.yaml")));
  EXPECT_THAT(edges.err, Not(HasSubstr("polarity: edges")));
  EXPECT_THAT(edges.err, ::testing::ContainsRegex("1 line was held in [0-9]+ of 33 frames: if the "
                                                  "scene has 1, evaluate with --lines 1"));
}

TEST(Oalservo, CamerasSaysPlainlyWhenThereIsNone) {
  test::TestDir dir;
  const test::OalservoRun run =
      test::RunOalservo(dir, "cameras --dev '" + dir.path().string() + "'");
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_THAT(run.out,
              HasSubstr("no V4L2 camera: " + dir.path().string() + " has no video capture device"));
  // A bad camera mode is refused before any device is opened, saying what is wrong.
  const test::OalservoRun bad = test::RunOalservo(dir, "pose /dev/video0 --camera-mode mjpeg:1280");
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_THAT(bad.err, HasSubstr("--camera-mode 'mjpeg:1280': the size is WIDTHxHEIGHT"));
}

TEST(Oalservo, Version) {
  test::TestDir dir;
  const test::OalservoRun version = test::RunOalservo(dir, "--version");
  EXPECT_EQ(version.exit_code, 0);
  EXPECT_THAT(version.out, HasSubstr("oalservo "));
}

TEST(Oalservo, UsageErrorsExitWithTwo) {
  test::TestDir dir;
  EXPECT_EQ(test::RunOalservo(dir, "").exit_code, 2);
  const test::OalservoRun unknown = test::RunOalservo(dir, "frobnicate");
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_THAT(unknown.err, HasSubstr("unknown command 'frobnicate'"));
  const test::OalservoRun missing = test::RunOalservo(dir, "detect");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_THAT(missing.err, HasSubstr("oalservo detect: error: "));
  const test::OalservoRun bad_option = test::RunOalservo(dir, "render --out x --count many");
  EXPECT_EQ(bad_option.exit_code, 2);
  EXPECT_THAT(bad_option.err, HasSubstr("oalservo render: error: "));
}

TEST(Oalservo, BadInputExitsWithOneAndSaysWhy) {
  test::TestDir dir;
  const test::OalservoRun result = test::RunOalservo(
      dir, "detect '" + dir / "missing.png" + "' --out '" + dir / "lines.jsonl" + "'");
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.err, HasSubstr("oalservo detect: error: no such file or directory '"));
  EXPECT_TRUE(result.out.empty());
  EXPECT_FALSE(std::filesystem::exists(dir / "lines.jsonl"));
}

// A number out of its range is bad input, not a bad command line, in every command alike: exit
// 1, "--option = value. Violated constraint: <the range>", nothing run.
TEST(Oalservo, ANumberOutOfRangeGetsOneStyleOfError) {
  test::TestDir dir;
  const std::pair<std::string, std::string> cases[] = {
      {"render --out '" + dir / "r" + "' --count 0",
       "--count = 0. Violated constraint: 1 <= --count"},
      {"servo-accuracy --starts 0", "--starts = 0. Violated constraint: 1 <= --starts <= 1000000"},
      {"servo-accuracy --max-off-deg 90", "--max-off-deg = 90. Violated constraint: 0 <="},
      {"servo-accuracy --faults 0", "--faults = 0. Violated constraint: 1 <= --faults <= 1000000"},
      {"servo-accuracy --faults 3 --jobs 0", "--jobs = 0. Violated constraint: 1 <= --jobs <= 64"},
      {"pose-accuracy --frames 0", "--frames = 0. Violated constraint: 1 <= --frames"},
      {"pose-accuracy --frames 1 --min-distance -1",
       "--min-distance = -1. Violated constraint: --min-distance > 0"},
      {"detect-accuracy --frames 1 --max-tilt-deg 100",
       "--max-tilt-deg = 100. Violated constraint: 0 <= --max-tilt-deg <= 80"},
      {"detect x.png --max-frames -1", "--max-frames = -1. Violated constraint: --max-frames >= 0"},
      {"evaluate x.avi --out '" + dir / "e" + "' --jobs 0",
       "--jobs = 0. Violated constraint: 1 <= --jobs <= 64"},
      {"scorbot-sim --speed 0", "--speed = 0. Violated constraint: 1 <= --speed <= 100"},
      {"scorbot-sim --time-scale 0", "--time-scale = 0. Violated constraint: 0.01 <="},
      {"compare '" + dir.path().string() + "' --me-range 0",
       "--me-range = 0. Violated constraint: 1 <= --me-range <= 100"},
      {"compare '" + dir.path().string() + "' --lines 200",
       "--lines = 200. Violated constraint: 0 <= --lines <= 100"},
  };
  for (const auto& [command, message] : cases) {
    const test::OalservoRun run = test::RunOalservo(dir, command);
    EXPECT_EQ(run.exit_code, 1) << command << ": " << run.err;
    EXPECT_THAT(run.err, HasSubstr("error: " + message)) << command;
    EXPECT_THAT(run.err, Not(HasSubstr("---"))) << command;
    EXPECT_THAT(run.err, Not(HasSubstr("Options::"))) << command;
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "r"));
}

// evaluate's own message names its option, and leaves plain words plain.
TEST(Oalservo, ATruthForTwoInputsNamesTheOption) {
  test::TestDir dir;
  const test::OalservoRun run =
      test::RunOalservo(dir, "evaluate a.avi b.avi --truth t.csv --out '" + dir / "e" + "'");
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_THAT(run.err, HasSubstr("error: --truth applies to one input, but there are 2"));
  EXPECT_FALSE(std::filesystem::exists(dir / "e"));
}

TEST(Oalservo, CameraNameWithoutCameraIsAUsageError) {
  test::TestDir dir;
  const test::OalservoRun result = test::RunOalservo(dir, "detect x.png --camera-name left");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_THAT(result.err, HasSubstr("oalservo detect: error: --camera-name requires --camera"));
}

// Each bad input gives our one-line error, without OpenCV's or libpng's own messages.
TEST(Oalservo, BadFramesGiveOneClearLineOnStderr) {
  test::TestDir dir;
  test::WriteText(dir / "empty.avi", "");
  test::WriteText(dir / "empty.mp4", "");
  const test::OalservoRun render =
      test::RunOalservo(dir,
                        "render --count 1 --width 160 --height 120 --fx 150 "
                        "--min-visible-px 30 --out '" +
                            dir / "data" + "'");
  ASSERT_EQ(render.exit_code, 0) << render.err;
  const std::string png = test::ReadText(dir / "data/frame_0000.png");
  test::WriteText(dir / "truncated.png", png.substr(0, png.size() / 2));
  ASSERT_TRUE(cv::imwrite(dir / "whole.jpg", cv::imread(dir / "data/frame_0000.png")));
  const std::string jpeg = test::ReadText(dir / "whole.jpg");
  test::WriteText(dir / "truncated.jpg", jpeg.substr(0, jpeg.size() / 2));
  for (const char* name : {"empty.avi", "empty.mp4", "truncated.png", "truncated.jpg"}) {
    const test::OalservoRun result = test::RunOalservo(dir, "detect '" + dir / name + "'");
    EXPECT_EQ(result.exit_code, 1) << name;
    EXPECT_THAT(result.err, HasSubstr("oalservo detect: error: ")) << name;
    EXPECT_THAT(result.err, HasSubstr(name)) << name;
    EXPECT_EQ(std::count(result.err.begin(), result.err.end(), '\n'), 1) << result.err;
    EXPECT_TRUE(result.out.empty()) << name;
  }
}

TEST(Oalservo, EvaluateWithoutInputsFailsAndWritesNothing) {
  test::TestDir dir;
  std::filesystem::create_directory(dir / "empty");
  const test::OalservoRun result =
      test::RunOalservo(dir, "evaluate '" + dir / "empty" + "' --out '" + dir / "out" + "'");
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.err,
              HasSubstr("oalservo evaluate: error: no inputs found in '" + dir / "empty" + "'"));
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

TEST(Oalservo, RenderThenDetectWithTheRenderedCamera) {
  test::TestDir dir;
  const std::string data = dir / "data";
  const test::OalservoRun render =
      test::RunOalservo(dir,
                        "render --count 2 --width 160 --height 120 --fx 150 --kdu 0.2 "
                        "--min-visible-px 30 --out '" +
                            data + "'");
  ASSERT_EQ(render.exit_code, 0) << render.err;
  const test::OalservoRun detect =
      test::RunOalservo(dir, "detect '" + data + "' --camera '" + data + "/camera.xml'");
  ASSERT_EQ(detect.exit_code, 0) << detect.err;
  std::istringstream lines(detect.out);
  int count = 0;
  for (std::string line; std::getline(lines, line); ++count) {
    EXPECT_THAT(line, HasSubstr("\"coordinates\":\"undistorted\""));
  }
  EXPECT_EQ(count, 2);
  // ViSP's parser chatter must not reach stdout, which holds only JSON lines.
  EXPECT_THAT(detect.out, ::testing::Not(HasSubstr("Found camera")));
}

}  // namespace
}  // namespace oal
