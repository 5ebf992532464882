// `oalservo detect-accuracy` and `oalservo pose-accuracy` (and `demo`'s stdout): what they read
// from --config, when they check --out, their report, and a failed stdout. A few small
// evaluations through the real binary; the measures themselves are the benchmarks' business.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/command_line.h"
#include "app/detector_accuracy_command.h"
#include "app/pose_accuracy_command.h"
#include "eval/rendered/pose_accuracy.h"
#include "io/camera_file.h"
#include "tests/app/command_test_util.h"
#include "tests/test_util.h"

namespace oal {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using ::testing::HasSubstr;

// Few small frames: each evaluation takes well under a second.
const std::string kFewFrames = " --frames 3 --seed 2";

// pose: is applied: a residual bound no pose can meet leaves every frame without a pose.
TEST(PoseAccuracy, ConfigPoseSectionIsApplied) {
  test::TestDir dir;
  PoseAccuracyOptions options;
  options.frames = 3;
  EXPECT_EQ(EvaluatePoseAccuracy(options).posed(), 3);
  options.pose.max_residual_px = 1e-4;
  EXPECT_EQ(EvaluatePoseAccuracy(options).posed(), 0);

  test::WriteText(dir / "strict.yaml",
                  "detector:\n  step_px: 5\npose:\n  max_residual_px: 0.0001\n");
  const test::OalservoRun strict =
      test::RunOalservo(dir, "pose-accuracy" + kFewFrames + " --config '" + dir / "strict.yaml" +
                                 "' --out '" + dir / "strict.json" + "'");
  ASSERT_EQ(strict.exit_code, 0) << strict.err;
  const json report = json::parse(test::ReadText(dir / "strict.json"));
  EXPECT_EQ(report.at("posed"), 0);
  EXPECT_EQ(report.at("options").at("max_residual_px"), 1e-4);
  EXPECT_EQ(report.at("options").at("config"), dir / "strict.yaml");
}

// --save-missed keeps each frame without a pose (here all three, under a residual bound no pose
// meets) as `render` writes frames, with what the tracker said; `pose` replays the folder; a
// folder holding a data set is refused before the work unless --overwrite.
TEST(PoseAccuracy, MissedFramesAreSavedForAReplay) {
  test::TestDir dir;
  test::WriteText(dir / "strict.yaml", "pose:\n  max_residual_px: 0.0001\n");
  const std::string evaluate = "pose-accuracy" + kFewFrames + " --config '" + dir / "strict.yaml" +
                               "' --save-missed '" + dir / "missed" + "'";
  const test::OalservoRun run =
      test::RunOalservo(dir, evaluate + " --out '" + dir / "report.json" + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_THAT(run.err, HasSubstr("3 frame(s) without a pose or with a wrong one written to"));
  const json report = json::parse(test::ReadText(dir / "report.json"));
  EXPECT_EQ(report.at("frames_without_pose"), json({0, 1, 2}));
  EXPECT_TRUE(fs::exists(dir / "missed/camera.xml"));
  EXPECT_TRUE(fs::exists(dir / "missed/target.yaml"));
  for (const char* frame : {"frame_0000", "frame_0001", "frame_0002"}) {
    EXPECT_TRUE(fs::exists(dir / ("missed/" + std::string(frame) + ".png"))) << frame;
    const json truth =
        json::parse(test::ReadText(dir / ("missed/" + std::string(frame) + ".json")));
    EXPECT_EQ(truth.at("pose_accuracy").at("status"), "not-found") << frame;
    EXPECT_FALSE(truth.at("pose_accuracy").at("message").get<std::string>().empty()) << frame;
    EXPECT_EQ(truth.at("pose_accuracy").at("wrong"), false);
    EXPECT_EQ(truth.at("lines").size(), 4u) << frame;
  }

  // The default pose options find the target in each of them again.
  const test::OalservoRun replay = test::RunOalservo(dir, "pose '" + dir / "missed" + "'");
  ASSERT_EQ(replay.exit_code, 0) << replay.err;
  EXPECT_EQ(std::count(replay.out.begin(), replay.out.end(), '\n'), 3) << replay.out;
  EXPECT_THAT(replay.out, HasSubstr("\"status\":\"ok\""));

  const std::string before = test::ReadText(dir / "missed/frame_0001.json");
  const test::OalservoRun again = test::RunOalservo(dir, evaluate);
  EXPECT_EQ(again.exit_code, 1);  // as `render --out` on a data set
  EXPECT_THAT(again.err, HasSubstr("--save-missed"));
  EXPECT_THAT(again.err, HasSubstr("--overwrite"));
  EXPECT_TRUE(again.out.empty()) << again.out;
  EXPECT_EQ(test::ReadText(dir / "missed/frame_0001.json"), before);
  const test::OalservoRun replaced = test::RunOalservo(dir, evaluate + " --overwrite");
  EXPECT_EQ(replaced.exit_code, 0) << replaced.err;
}

// --first-frame N: frame N of the seed's sequence on its own, exactly as in the longer run (its
// pose, bench, effects and noise), the report's frame numbers those of the sequence.
TEST(PoseAccuracy, AFrameOfALongerRunIsReplayedOnItsOwn) {
  PoseAccuracyOptions options;
  options.frames = 4;
  options.seed = 5;
  const PoseAccuracyReport run = EvaluatePoseAccuracy(options);
  ASSERT_EQ(run.posed(), 4);
  options.first_frame = 2;
  options.frames = 1;
  const PoseAccuracyReport replay = EvaluatePoseAccuracy(options);
  ASSERT_EQ(replay.frames, 1);
  ASSERT_EQ(replay.translation_error_pct.size(), 1u);
  EXPECT_DOUBLE_EQ(replay.translation_error_pct[0], run.translation_error_pct[2]);
  EXPECT_DOUBLE_EQ(replay.rotation_error_deg[0], run.rotation_error_deg[2]);

  test::TestDir dir;
  test::WriteText(dir / "strict.yaml", "pose:\n  max_residual_px: 0.0001\n");
  const test::OalservoRun strict =
      test::RunOalservo(dir, "pose-accuracy --frames 2 --first-frame 7 --config '" +
                                 dir / "strict.yaml" + "' --out '" + dir / "report.json" + "'");
  ASSERT_EQ(strict.exit_code, 0) << strict.err;
  const json report = json::parse(test::ReadText(dir / "report.json"));
  EXPECT_EQ(report.at("frames_without_pose"), json({7, 8}));
  EXPECT_EQ(report.at("options").at("first_frame"), 7);
  EXPECT_THAT(strict.out, HasSubstr("| frames | 2 (from frame 7) |"));
}

// opencv-doc's photographs as the scene's backgrounds (the benchmarks' sets of seven and of
// twelve), or nothing when they are not installed.
std::optional<std::string> OpenCvPhotographs(const std::vector<std::string>& names) {
  const std::string photos = "/usr/share/doc/opencv-doc/examples/data/";
  std::string backgrounds = " --background";
  for (const std::string& name : names) {
    if (!fs::exists(photos + name)) return std::nullopt;
    backgrounds += " '" + photos + name + "'";
  }
  return backgrounds;
}
const std::vector<std::string> kSevenPhotographs{"building.jpg", "home.jpg",   "box_in_scene.png",
                                                 "board.jpg",    "fruits.jpg", "messi5.jpg",
                                                 "aero1.jpg"};
const std::vector<std::string> kTwelvePhotographs{
    "baboon.jpg",       "apple.jpg",        "orange.jpg",       "butterfly.jpg",
    "graf1.png",        "leuvenA.jpg",      "starry_night.jpg", "stuff.jpg",
    "rubberwhale1.png", "squirrel_cls.jpg", "smarties.png",     "sudoku.png"};

// A frame of the lived-in evaluation (config/scene-lived-in.yaml) replayed on its own, and what
// is expected of it: a right pose, or (posed false) no wrong one.
struct LivedInFrame {
  int seed = 0, frame = 0;
  std::string options;  // added to the command line: the camera
  bool posed = false;
  /// opencv-doc's photographs as the backgrounds (the bench's own when null).
  const std::vector<std::string>* photographs = nullptr;
};

// Replays each frame through the binary: its report holds no wrong pose, and a pose where one
// is expected. Frames on opencv-doc's photographs are left out when those are not installed,
// and the test is then marked skipped.
void ExpectRightPosesOrNone(const std::vector<LivedInFrame>& frames) {
  test::TestDir dir;
  const std::string config = std::string(OAL_SOURCE_DIR) + "/config/scene-lived-in.yaml";
  int left_out = 0;
  for (const LivedInFrame& replayed : frames) {
    SCOPED_TRACE("seed " + std::to_string(replayed.seed) + ", frame " +
                 std::to_string(replayed.frame));
    std::string options = replayed.options;
    if (replayed.photographs != nullptr) {
      const std::optional<std::string> backgrounds = OpenCvPhotographs(*replayed.photographs);
      if (!backgrounds) {
        ++left_out;
        continue;
      }
      options += *backgrounds;
    }
    const test::OalservoRun run = test::RunOalservo(
        dir, "pose-accuracy --config '" + config + "' --seed " + std::to_string(replayed.seed) +
                 " --first-frame " + std::to_string(replayed.frame) + " --frames 1" + options +
                 " --out '" + dir / "report.json" + "'");
    ASSERT_EQ(run.exit_code, 0) << run.err;
    const json report = json::parse(test::ReadText(dir / "report.json"));
    EXPECT_EQ(report.at("wrong_poses"), json::array());
    if (replayed.posed) {
      EXPECT_EQ(report.at("posed"), 1);
    }
  }
  if (left_out > 0) {
    GTEST_SKIP() << left_out
                 << " frame(s) not replayed: opencv-doc's photographs are not installed";
  }
}
const std::string kAt720p = " --width 1280 --height 720 --focal 914";
const std::string kAt1080p = " --width 1920 --height 1080 --focal 1371";
const std::string kAt800x600 = " --width 800 --height 600 --focal 750";

// Frames of the lived-in evaluation that once got a wrong pose give a right one or none: a hand
// over the crossing of a blurred stripe, no light cell found, the whole image's pose 3.7
// degrees off (seed 91, frame 730); a hand's edge across a short stripe (seed 41, frame 931).
TEST(PoseAccuracy, TheLivedInFramesThatOnceGaveWrongPosesGiveARightOneOrNone) {
  ExpectRightPosesOrNone({{91, 730, "", false}, {41, 931, "", false}});
}

// Dim frames of the lived-in evaluation give a pose: exposed at 0.43 of the right level,
// the sheet finder's classes differ by less than min_contrast (seed 131, frame 713, on
// opencv-doc's photographs); a dim frame with a hand over a crossing, whose middle cell is
// closed in on four sides only at the finder's last pass (seed 91, frame 259); frames exposed at
// a third whose borders on the target's plane have classes 36-38 grey levels apart, under the
// detector's min_contrast, one with a tool over a crossing (seed 196, frame 518, on opencv-doc's
// photographs), one smeared by 11 px (frame 220).
TEST(PoseAccuracy, DimLivedInFramesGiveAPose) {
  ExpectRightPosesOrNone({{91, 259, "", true},
                          {131, 713, "", true, &kSevenPhotographs},
                          {196, 518, "", true, &kTwelvePhotographs},
                          {196, 220, "", true, &kTwelvePhotographs}});
}

// Lived-in frames whose glare washes out a stripe over several of the finder's cells give a
// pose: over-exposed, the middle cell joined through the glare to paper running out of view
// (seed 1, frame 554), and a glare over a crossing (frame 775); the finder splits them at the
// neck. And a frame over-exposed at 720p with a white hand over a crossing and its shadow where
// a hidden stripe should be (seed 42, frame 966) gives no wrong pose: that stripe's few points,
// the shadow's, pulled the fit 2.3 degrees from where the other three stripes put it. Nor does
// an over-exposed far sheet with a white cable lying over one side of a stripe for most of its
// length (seed 185, frame 588): its runs' middles, all off the same way, tilted the pose 2.7
// degrees. Nor does a dim 800x600 frame with a pale cable lying along a stripe and across it
// at a shallow angle (seed 201, frame 22): the stripe's runs kept span 6 % of it, and a cell
// beyond it scanned across the stripes' middles gave a pose 5 degrees off. Nor a dim 720p frame
// through a stronger lens with a cable along line 1 under a motion blur (seed 207, frame 365):
// line 1 kept as many points as the others, every stripe 0.3-0.5 px off the fit, the pose 2.6
// degrees off. Nor an 800x600 frame whose sheet runs out of view, a pale cable along its wide
// stripe (seed 252, frame 668): the whole image's lines gave a pose 2 degrees off, the stripe in
// view and none of its runs as wide as it.
TEST(PoseAccuracy, WashedOutCrossingsGiveAPoseAndAShadowOrACableAlongAStripeNoWrongOne) {
  ExpectRightPosesOrNone({{1, 554, "", true},
                          {1, 775, "", true},
                          {42, 966, kAt720p, false},
                          {185, 588, "", false},
                          {201, 22, kAt800x600, false},
                          {252, 668, kAt800x600, false},
                          {207, 365, kAt720p + " --kdu 0.25", false}});
}

// Over-exposed lived-in frames, the paper clipped among pages and photographs that are not, a
// glare washing out a crossing, give a pose: the clipped paper is not taken for a glare's core
// (seed 21, frame 109, on the bench's photographs; seed 196, frame 441, on opencv-doc's).
TEST(PoseAccuracy, AClippedSheetWithAGlareOverACrossingGivesAPose) {
  ExpectRightPosesOrNone({{21, 109, "", true}, {196, 441, "", true, &kTwelvePhotographs}});
}

// Frames whose stripe's runs are wider or narrower than the others': a dark cable crossing a
// stripe at a shallow angle under a vertical motion blur at 1920x1080 (seed 190, frame 109),
// its wide runs turning the pose by 2.1 degrees, gives no wrong pose; a dim frame smeared across
// one pair of stripes, the other pair's runs narrower than the median (seed 161, frame 58, on
// opencv-doc's photographs), keeps its right pose (fitted from a band about the smeared pair's
// widths, it was 2.5 degrees off).
TEST(PoseAccuracy, AStripesRunsWiderThanItsParallelsGiveNoWrongPose) {
  ExpectRightPosesOrNone({{190, 109, kAt1080p, false}, {161, 58, "", true, &kTwelvePhotographs}});
}

// A lived-in frame whose stripes disagree in reading after reading gives no wrong pose: a pale
// sheet's blurred edge lying across a stripe seen over a sixth of its length (seed 171, frame
// 214, on opencv-doc's photographs). Each scan of its borders gave a pose 0.1-2.9 degrees off,
// each refused for its stripes' disagreement or a short stripe holding the rotation, until the
// sixteenth, 2.9 degrees off, passed.
// A stripe the model check sees nothing of, the pose resting on the other three, which agree:
// a hand over the lower stripe under a motion blur (seed 194, frame 270); a sheet running out of
// view at the bottom, its lowest stripe along the image's edge, a hand over the left (frame
// 640); a glare on the top stripe along the image's top edge (seed 91, frame 235); a pale cable
// lying over a stripe (frame 795). And a line left too few feature points, the other three
// holding the pose: a hand over a crossing of an over-exposed sheet running out of view (seed
// 185, frame 725); a glare and a pen over a crossing of a dim frame (seed 21, frame 615).
TEST(PoseAccuracy, AStripeHiddenOrAlongTheImagesEdgeLeavesThePoseOfTheOtherThree) {
  ExpectRightPosesOrNone({{194, 270, "", true},
                          {194, 640, "", true},
                          {91, 235, "", true},
                          {91, 795, "", true},
                          {185, 725, "", true},
                          {21, 615, "", true}});
}

TEST(PoseAccuracy, AFrameWhoseStripesDisagreeInEveryReadingGivesNoWrongPose) {
  ExpectRightPosesOrNone({{171, 214, "", false, &kTwelvePhotographs}});
}

// Frames smeared across one pair of thin stripes, both pairs' runs wider than their stripes by
// as many pixels (1.3 times a stripe 10 px wide under a blur of a few pixels), give a pose: the
// widening both parallel stripes share is not taken for something merged with one of them
// (seed 196 on opencv-doc's photographs, frames 33 and 523).
TEST(PoseAccuracy, APairOfStripesSmearedAcrossGivesAPose) {
  ExpectRightPosesOrNone(
      {{196, 33, "", true, &kTwelvePhotographs}, {196, 523, "", true, &kTwelvePhotographs}});
}

// The 2 m board seen from near (seed 1, frame 665): the whole image's lines give its pose, and
// the borders on the board's plane leave too few stripe points for a fit to tell anything
// against it (its steps cannot fix the pose): the whole image's pose stands, a right one.
TEST(PoseAccuracy, TheBoardSeenFromNearKeepsTheWholeImagesPose) {
  test::TestDir dir;
  const test::OalservoRun run =
      test::RunOalservo(dir,
                        "pose-accuracy --target four-line-board --seed 1 --first-frame 665 "
                        "--frames 1 --out '" +
                            dir / "report.json" + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const json report = json::parse(test::ReadText(dir / "report.json"));
  EXPECT_EQ(report.at("posed"), 1);
  EXPECT_EQ(report.at("wrong_poses"), json::array());
}

// The report: status_counts keyed by status name, and the roll median the table shows.
TEST(PoseAccuracy, ReportJsonNamesTheStatusCountsAndHasTheRollMedian) {
  test::TestDir dir;
  const test::OalservoRun run =
      test::RunOalservo(dir, "pose-accuracy" + kFewFrames + " --out '" + dir / "report.json" + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const json report = json::parse(test::ReadText(dir / "report.json"));
  EXPECT_EQ(report.at("status_counts"),
            json({{"ok", 3}, {"not-found", 0}, {"model-mismatch", 0}, {"jump", 0}}));
  EXPECT_EQ(report.at("posed"), 3);
  ASSERT_TRUE(report.contains("roll_error_deg_median"));
  EXPECT_LE(report.at("roll_error_deg_median").get<double>(),
            report.at("roll_error_deg_max").get<double>());
  EXPECT_THAT(run.out, HasSubstr("| roll error median / max (deg) |"));
  EXPECT_TRUE(test::TempFilesIn(dir.path()).empty());
}

// --camera renders through a lens in OpenCV's model, --pose-camera poses with another file
// (here ViSP's one-term approximation of it): the report names both lenses; a --pose-camera that
// is missing, or given with --estimate-distortion, is refused before any work.
TEST(PoseAccuracy, TheRenderedAndThePosingLensesAreBothReported) {
  test::TestDir dir;
  const std::string lens = std::string(OAL_SOURCE_DIR) + "/config/lenses/opencv-sample.yaml";
  SaveCameraFile(dir / "one-term.xml", LoadCameraFile(lens).camera, "Camera", 640, 480);
  const test::OalservoRun run = test::RunOalservo(
      dir, "pose-accuracy" + kFewFrames + " --camera '" + lens + "' --pose-camera '" +
               dir / "one-term.xml" + "' --out '" + dir / "report.json" + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const json options = json::parse(test::ReadText(dir / "report.json")).at("options");
  EXPECT_EQ(options.at("camera").at("model"), "plumb_bob");
  EXPECT_EQ(options.at("pose_camera").at("model"), "perspectiveProjWithDistortion");
  const test::OalservoRun missing =
      test::RunOalservo(dir, "pose-accuracy --frames 1 --pose-camera '" + dir / "none.yaml" + "'");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_THAT(missing.err, HasSubstr("--pose-camera"));
  const test::OalservoRun both =
      test::RunOalservo(dir, "pose-accuracy --frames 1 --estimate-distortion --pose-camera '" +
                                 dir / "one-term.xml" + "'");
  EXPECT_EQ(both.exit_code, 2);
  EXPECT_THAT(both.err, HasSubstr("excludes"));
}

// --marker apriltag: the AprilTag printed on the sheet instead of the stripes, on the same three
// frames, in the same report (the frames, the poses, the times) with the marker named.
TEST(PoseAccuracy, AMarkerIsReportedOnTheSameFrames) {
  test::TestDir dir;
  const test::OalservoRun run = test::RunOalservo(
      dir, "pose-accuracy --marker apriltag --frames 3 --out '" + dir / "tag.json" + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const json report = json::parse(test::ReadText(dir / "tag.json"));
  EXPECT_EQ(report.at("frames"), 3);
  EXPECT_EQ(report.at("options").at("marker"), "apriltag");
  EXPECT_EQ(report.at("options").at("target"), "four-line-a3");
  EXPECT_EQ(report.at("status_counts").size(), 3u);
  for (const char* key :
       {"posed", "wrong_poses", "translation_error_pct_median", "rotation_error_deg_p95",
        "time_us_median", "time_us_p95", "marker_in_view", "posed_in_view"}) {
    EXPECT_TRUE(report.contains(key)) << key;
  }
  EXPECT_THAT(report.at("marker").get<std::string>(), HasSubstr("AprilTag 36h11 id 0"));
  EXPECT_THAT(run.out, HasSubstr("| frames | 3 |"));
  EXPECT_THAT(run.out, HasSubstr("| marker | apriltag: AprilTag 36h11 id 0, black square 0.250 m"));
  EXPECT_THAT(run.out, HasSubstr("| time median / p95 (us): detect + pose |"));
}

// A --marker that is none of the markers is refused before any work, naming the option and the
// accepted values; so are the options that only our target has.
TEST(AccuracyCommands, ABadMarkerIsRefused) {
  test::TestDir dir;
  const test::OalservoRun bad = test::RunOalservo(dir, "pose-accuracy --frames 1 --marker qr");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_THAT(bad.err,
              HasSubstr("--marker: unknown marker 'qr' (accepted: oal, apriltag, charuco)"));
  EXPECT_TRUE(bad.out.empty()) << bad.out;
  const test::OalservoRun missed = test::RunOalservo(
      dir, "pose-accuracy --frames 1 --marker charuco --save-missed '" + dir / "missed" + "'");
  EXPECT_EQ(missed.exit_code, 2);
  EXPECT_THAT(missed.err, HasSubstr("only with --marker oal"));
  const test::OalservoRun lens =
      test::RunOalservo(dir, "pose-accuracy --frames 1 --marker charuco --estimate-distortion");
  EXPECT_EQ(lens.exit_code, 2);
  EXPECT_THAT(lens.err, HasSubstr("--estimate-distortion"));
  EXPECT_FALSE(fs::exists(dir / "missed"));
}

// A section the command would ignore is an error naming the file, the line and the section.
TEST(AccuracyCommands, ConfigSectionsTheyDoNotReadAreRejected) {
  test::TestDir dir;
  const std::string config = dir / "with-camera.yaml";
  test::WriteText(config, "detector:\n  step_px: 5\ncamera: {px: 500, py: 500}\n");
  const test::OalservoRun pose =
      test::RunOalservo(dir, "pose-accuracy --frames 1 --config '" + config + "'");
  EXPECT_EQ(pose.exit_code, 1);
  EXPECT_THAT(pose.err, HasSubstr(config + ":3: section 'camera' is not used by oalservo "
                                           "pose-accuracy (it reads: target, detector, pose, "
                                           "tracking, scene)"));
  EXPECT_TRUE(pose.out.empty());
  const test::OalservoRun detect =
      test::RunOalservo(dir, "detect-accuracy --frames 1 --config '" + config + "'");
  EXPECT_EQ(detect.exit_code, 1);
  EXPECT_THAT(detect.err,
              HasSubstr(config + ":3: section 'camera' is not used by oalservo "
                                 "detect-accuracy (it reads: detector, target, tracking, scene); "
                                 "it renders the target with the camera of its command-line "
                                 "options"));
  test::WriteText(config, "pose:\n  max_residual_px: 1.0\n");
  EXPECT_THAT(test::RunOalservo(dir, "detect-accuracy --frames 1 --config '" + config + "'").err,
              HasSubstr(":1: section 'pose' is not used by oalservo detect-accuracy"));
  // A section they read is still checked by the config reader.
  test::WriteText(config, "pose:\n  max_residual: 1.0\n");
  EXPECT_THAT(test::RunOalservo(dir, "pose-accuracy --frames 1 --config '" + config + "'").err,
              HasSubstr(config + ":2:"));
  // The target: a two-line one has no pose; the config's and --target together are refused.
  test::WriteText(config, "target: {name: two-line}\n");
  EXPECT_THAT(test::RunOalservo(dir, "pose-accuracy --frames 1 --config '" + config + "'").err,
              HasSubstr("'two-line': 2 lines, a '#' target needs 4"));
  const test::OalservoRun both = test::RunOalservo(
      dir, "pose-accuracy --frames 1 --target four-line-a4 --config '" + config + "'");
  EXPECT_EQ(both.exit_code, 2);
  EXPECT_THAT(both.err, HasSubstr("--target four-line-a4 and the target: section of"));
}

// --estimate-frames out of range or not a number: the option named, exit 2, nothing evaluated.
TEST(AccuracyCommands, ABadEstimateFramesIsRefused) {
  test::TestDir dir;
  for (const std::string value : {"0", "101", "abc"}) {
    const test::OalservoRun run =
        test::RunOalservo(dir, "pose-accuracy --estimate-distortion --estimate-frames " + value);
    EXPECT_EQ(run.exit_code, 2) << value;
    EXPECT_THAT(run.err, HasSubstr("--estimate-frames: Value " + value + " not in range 1 to 100"));
    EXPECT_TRUE(run.out.empty()) << run.out;
  }
}

// --out is checked before the evaluation: an error, and no table printed (it used to come
// after the whole evaluation, with the table already on stdout).
TEST(AccuracyCommands, OutputIsCheckedBeforeTheWork) {
  test::TestDir dir;
  for (const std::string command : {"pose-accuracy", "detect-accuracy"}) {
    for (const std::string& out :
         {dir / "missing/report.json", dir.path().string(), std::string("/proc/report.json")}) {
      const test::OalservoRun run =
          test::RunOalservo(dir, command + " --frames 1 --out '" + out + "'");
      EXPECT_EQ(run.exit_code, 1) << command << " " << out;
      EXPECT_THAT(run.err, HasSubstr("cannot write --out '" + out + "'")) << command;
      EXPECT_TRUE(run.out.empty()) << command << " " << out << ": " << run.out;
    }
  }
  EXPECT_FALSE(fs::exists(dir / "missing"));
}

// The same ranges as `oalservo render`: -1 < kdu < 1; and a seed is never negative.
TEST(AccuracyCommands, OptionRanges) {
  for (auto run : {&RunPoseAccuracy, &RunDetectAccuracy}) {
    EXPECT_THAT(test::ErrorMessageOf<std::invalid_argument>([&] {
                  test::RunWithArgs(run, {"x", "--frames", "1", "--kdu", "1.5"});
                }),
                HasSubstr("--kdu = 1.5. Violated constraint: -1 < --kdu < 1"));
    EXPECT_THAT(test::ErrorMessageOf<std::invalid_argument>([&] {
                  test::RunWithArgs(run, {"x", "--frames", "1", "--noise", "200"});
                }),
                HasSubstr("--noise = 200"));
    EXPECT_THROW(test::RunWithArgs(run, {"x", "--frames", "1", "--seed", "-1"}), UsageError);
    EXPECT_THAT(test::ErrorMessageOf<std::invalid_argument>([&] {
                  test::RunWithArgs(run, {"x", "--frames", "1", "--first-frame", "-3"});
                }),
                HasSubstr("--first-frame = -3"));
  }
}

// The rendered camera: --width/--height (the focal length in proportion unless --focal), or a
// camera file's camera at its image size; what cannot go together is refused before the work.
TEST(AccuracyCommands, TheRenderedCameraFollowsItsOptionsOrACameraFile) {
  test::TestDir dir;
  const test::OalservoRun wide = test::RunOalservo(
      dir, "pose-accuracy --frames 1 --width 1280 --height 720 --out '" + dir / "wide.json" + "'");
  ASSERT_EQ(wide.exit_code, 0) << wide.err;
  const json options = json::parse(test::ReadText(dir / "wide.json")).at("options");
  EXPECT_EQ(options.at("width"), 1280);
  EXPECT_EQ(options.at("height"), 720);
  EXPECT_EQ(options.at("focal_px"), 1200.0);

  test::RenderChecked(test::ScaledRender(dir / "small", 1, 3, 320, 240));
  const std::string camera = dir / "small/camera.xml";
  const test::OalservoRun small =
      test::RunOalservo(dir, "detect-accuracy --frames 1 --camera '" + camera + "' --out '" +
                                 dir / "small.json" + "'");
  ASSERT_EQ(small.exit_code, 0) << small.err;
  const json small_options = json::parse(test::ReadText(dir / "small.json")).at("options");
  EXPECT_EQ(small_options.at("width"), 320);
  EXPECT_EQ(small_options.at("height"), 240);
  EXPECT_TRUE(small_options.contains("camera"));

  const test::OalservoRun focal =
      test::RunOalservo(dir, "pose-accuracy --frames 1 --camera '" + camera + "' --focal 500");
  EXPECT_EQ(focal.exit_code, 1);
  EXPECT_THAT(focal.err, HasSubstr("--focal cannot be given with --camera " + camera));
  const test::OalservoRun size = test::RunOalservo(
      dir, "pose-accuracy --frames 1 --camera '" + camera + "' --width 640 --height 480");
  EXPECT_EQ(size.exit_code, 1);
  EXPECT_THAT(size.err, HasSubstr("disagree with --camera " + camera + ", calibrated at 320x240"));
  EXPECT_TRUE(size.out.empty());
  EXPECT_THAT(test::RunOalservo(dir, "pose-accuracy --frames 1 --width 9000").err,
              HasSubstr("both <= 8192"));
}

// stdout on a full disk: exit 1 with a message, as `detect` and `pose` do (`compare` too).
TEST(AccuracyCommands, AFullStdoutIsAnError) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  test::TestDir dir;
  const std::string frames = dir / "frames";
  test::RenderChecked(test::ScaledRender(frames, 1, 3, 320, 240));
  for (const std::string& command :
       {std::string("pose-accuracy --frames 1"), std::string("detect-accuracy --frames 1"),
        "demo --out '" + dir / "demo" + "'", "compare '" + frames + "'"}) {
    const test::OalservoRun run = test::RunOalservo(dir, command, "/dev/full");
    EXPECT_EQ(run.exit_code, 1) << command;
    EXPECT_THAT(run.err, HasSubstr("cannot write the output")) << command;
  }
}

}  // namespace
}  // namespace oal
