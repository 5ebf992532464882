#include "app/pose_command.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/config.h"
#include "app/render_command.h"
#include "io/camera_file.h"
#include "tests/app/command_test_util.h"
#include "tests/test_util.h"

namespace oal {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using ::testing::Contains;
using ::testing::HasSubstr;
using ::testing::Not;

constexpr double kTranslationTolerance = 0.02;  // of the true translation's norm

// A small rendered data set of the four-line target: `count` frames of 320x240 (fx scaled
// from 600 at 640x480), with camera.xml.
std::string RenderSmall(const test::TestDir& dir, const std::string& name, int count, double kdu,
                        const std::string& target = "four-line") {
  RenderCommandOptions render = test::ScaledRender(dir / name, count, 11, 320, 240);
  render.target = target;
  render.kdu = kdu;
  render.min_visible_px = 60.0;
  return test::RenderChecked(render);
}

using test::ParseJsonLines;

std::string FrameFile(const std::string& dir, int index, const char* extension) {
  std::string number = std::to_string(index);
  number.insert(0, 4 - number.size(), '0');
  return dir + "/frame_" + number + extension;
}

// The frame's pose is ok and its translation within kTranslationTolerance of the truth's.
void ExpectPoseNearTruth(const json& frame, const std::string& truth_path) {
  ASSERT_EQ(frame.at("status"), "ok") << frame.at("message");
  EXPECT_EQ(frame.at("message"), "");
  const json truth = json::parse(test::ReadText(truth_path));
  const std::vector<double> t_true = truth.at("cMo").at("t_m");
  const std::vector<double> t = frame.at("cMo").at("t_m");
  ASSERT_EQ(t.size(), 3u);
  const double norm = std::hypot(t_true[0], t_true[1], t_true[2]);
  const double error = std::hypot(t[0] - t_true[0], t[1] - t_true[1], t[2] - t_true[2]);
  EXPECT_LT(error, kTranslationTolerance * norm) << truth_path;
  EXPECT_EQ(frame.at("cMo").at("thetau_rad").size(), 3u);
  EXPECT_EQ(frame.at("cMo").at("matrix").size(), 4u);  // the same form as render's truth
  for (const char* key : {"roll_deg", "pitch_deg", "yaw_deg", "line1_roll_deg", "residual_px"}) {
    EXPECT_TRUE(frame.at(key).is_number()) << key;
  }
  EXPECT_EQ(frame.at("plane_angles_deg").size(), 2u);
  const json& covariance = frame.at("covariance");
  ASSERT_EQ(covariance.size(), 6u);
  for (int i = 0; i < 6; ++i) {
    EXPECT_GE(covariance[i][i].get<double>(), 0.0);  // variances
    for (int j = 0; j < 6; ++j) {
      const double a = covariance[i][j], b = covariance[j][i];
      EXPECT_NEAR(a, b, 1e-9 * (std::fabs(a) + std::fabs(b)) + 1e-30);  // symmetric
    }
  }
  EXPECT_TRUE(frame.at("method") == "dementhon" || frame.at("method") == "lagrange" ||
              frame.at("method") == "previous" || frame.at("method") == "homography");
  EXPECT_TRUE(frame.at("from_previous").is_boolean());
  EXPECT_EQ(frame.at("lines").size(), 4u);
  for (const json& index : frame.at("lines")) EXPECT_GE(index.get<int>(), 0);
  EXPECT_EQ(frame.at("corners_px").size(), 4u);
  EXPECT_GE(frame.at("time_us").at("detect").get<double>(), 0.0);
  EXPECT_GE(frame.at("time_us").at("pose").get<double>(), 0.0);
}

// The message EstimatePoses throws with, or "" if it succeeds.
std::string PoseError(const PoseCommandOptions& options) {
  std::ostringstream out;
  return test::ErrorMessageOf([&] { EstimatePoses(options, out); });
}

TEST(Pose, RenderedDirectoryGivesThePoseOfEveryFrame) {
  test::TestDir dir;
  const std::string data = RenderSmall(dir, "data", 3, 0.0);
  PoseCommandOptions options;
  options.inputs = {data};     // no --camera: data/camera.xml is used, with a warning
  options.independent = true;  // rendered at random poses, not a sequence
  options.out_path = dir / "poses.jsonl";
  std::ostringstream stdout_text;
  const PoseSummary summary = EstimatePoses(options, stdout_text);
  EXPECT_EQ(summary.frames, 3);
  EXPECT_EQ(summary.ok, 3);
  EXPECT_EQ(summary.camera_path, data + "/camera.xml");
  EXPECT_THAT(summary.warnings, Contains(HasSubstr("using the camera in")));
  EXPECT_THAT(summary.warnings, Contains(HasSubstr("using the target in")));
  EXPECT_TRUE(stdout_text.str().empty());
  const std::vector<json> frames = ParseJsonLines(test::ReadText(options.out_path));
  ASSERT_EQ(frames.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(frames[i].at("frame"), i);
    EXPECT_EQ(frames[i].at("coordinates"), "image");
    EXPECT_THAT(frames[i].at("source").get<std::string>(), HasSubstr(FrameFile("", i, ".png")));
    ExpectPoseNearTruth(frames[i], FrameFile(data, i, ".json"));
  }
  EXPECT_TRUE(test::TempFilesIn(dir.path()).empty());
}

TEST(Pose, DistortedFramesWithCameraAndAnnotations) {
  test::TestDir dir;
  const std::string data = RenderSmall(dir, "data", 2, 0.25);
  PoseCommandOptions options;
  options.inputs = {data};
  options.independent = true;
  options.camera_path = data + "/camera.xml";
  options.annotate_dir = dir / "annotated";
  std::ostringstream out;
  const PoseSummary summary = EstimatePoses(options, out);
  EXPECT_EQ(summary.ok, 2);
  const std::vector<json> frames = ParseJsonLines(out.str());
  ASSERT_EQ(frames.size(), 2u);
  for (int i = 0; i < 2; ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(frames[i].at("coordinates"), "undistorted");
    ExpectPoseNearTruth(frames[i], FrameFile(data, i, ".json"));
  }
  for (const char* name : {"pose_0000.png", "pose_0001.png"}) {
    const cv::Mat image = cv::imread((fs::path(options.annotate_dir) / name).string());
    ASSERT_FALSE(image.empty()) << name;
    EXPECT_EQ(image.channels(), 3);
    EXPECT_EQ(image.cols, 320);
    EXPECT_EQ(image.rows, 240);
  }
}

// Each frame says how straight its lines came out; a camera file that leaves them bent (here
// one without the lens's distortion) gets one warning that says what to do.
TEST(Pose, ACameraFileThatMissesTheLensIsToldOnce) {
  test::TestDir dir;
  const std::string data = RenderSmall(dir, "data", 6, 0.25);
  PoseCommandOptions options;
  options.inputs = {data};
  options.independent = true;
  options.camera_path = data + "/camera.xml";
  std::ostringstream out;
  PoseSummary summary = EstimatePoses(options, out);
  ASSERT_EQ(summary.ok, 6);
  for (const json& frame : ParseJsonLines(out.str())) {
    EXPECT_LT(frame.at("straightness_px").get<double>(), 0.2);
    EXPECT_FALSE(frame.at("lens").at("contradicts_camera").get<bool>()) << frame.dump();
  }
  auto lens_warnings = [](const PoseSummary& run) {
    int count = 0;
    for (const std::string& warning : run.warnings) {
      count += warning.find("Calibrate the camera") != std::string::npos;
    }
    return count;
  };
  EXPECT_EQ(lens_warnings(summary), 0);

  const CameraFile right = LoadCameraFile(options.camera_path);
  Lens pinhole;
  pinhole =
      Lens::Pinhole(right.camera.px(), right.camera.py(), right.camera.u0(), right.camera.v0());
  options.camera_path = dir / "pinhole.xml";
  SaveCameraFile(options.camera_path, pinhole, "Camera", right.width, right.height);
  out.str("");
  summary = EstimatePoses(options, out);
  EXPECT_EQ(lens_warnings(summary), 1);
  // The lens's kdu (0.25) less the pinhole's (0), as the stripes tell it, frame by frame.
  for (const json& frame : ParseJsonLines(out.str())) {
    EXPECT_NEAR(-frame.at("lens").at("kdu_error").get<double>(), 0.25, 0.06) << frame.dump();
  }
}

// Frames without the four lines (two lines, a blank image) are rows with their status; the
// run goes on and the frames after them get their pose.
TEST(Pose, FramesWithoutTheFourLinesGetAStatusNotAnError) {
  test::TestDir dir;
  const std::string data = RenderSmall(dir, "data", 2, 0.0);
  const std::string two = RenderSmall(dir, "two", 1, 0.0, "two-line");
  fs::copy_file(FrameFile(two, 0, ".png"), FrameFile(data, 0, "_a_two_lines.png"));
  ASSERT_TRUE(
      cv::imwrite(FrameFile(data, 0, "_b_blank.png"), cv::Mat(240, 320, CV_8UC1, cv::Scalar(200))));
  PoseCommandOptions options;
  options.inputs = {data};
  options.independent = true;
  options.camera_path = data + "/camera.xml";
  options.out_path = dir / "poses.jsonl";
  std::ostringstream out;
  const PoseSummary summary = EstimatePoses(options, out);
  EXPECT_EQ(summary.frames, 4);
  EXPECT_EQ(summary.ok, 2);
  const std::vector<json> frames = ParseJsonLines(test::ReadText(options.out_path));
  ASSERT_EQ(frames.size(), 4u);  // frame_0000, frame_0000_a_two_lines, _b_blank, frame_0001
  ExpectPoseNearTruth(frames[0], FrameFile(data, 0, ".json"));
  for (int i : {1, 2}) {
    SCOPED_TRACE(i);
    EXPECT_EQ(frames[i].at("status"), "not-found");
    // The last attempt's pose (the whole image: two stripes' lines, or none) says why.
    EXPECT_THAT(frames[i].at("pose_status").get<std::string>(),
                ::testing::AnyOf("not-enough-lines", "degenerate"));
    EXPECT_FALSE(frames[i].at("message").get<std::string>().empty());
    EXPECT_TRUE(frames[i].at("cMo").is_null());
    EXPECT_TRUE(frames[i].at("roll_deg").is_null());
    EXPECT_TRUE(frames[i].at("corners_px").is_null());
    EXPECT_EQ(frames[i].at("lines"), json::array({-1, -1, -1, -1}));
  }
  EXPECT_THAT(frames[1].at("source").get<std::string>(), HasSubstr("two_lines"));
  ExpectPoseNearTruth(frames[3], FrameFile(data, 1, ".json"));
  EXPECT_EQ(frames[3].at("from_previous"), false);  // the frame before had no pose
}

TEST(Pose, WithoutACameraFailsClearlyAndLeavesNoOutput) {
  test::TestDir dir;
  const std::string data = RenderSmall(dir, "data", 1, 0.0);
  fs::create_directory(dir.path() / "frames");
  fs::copy_file(FrameFile(data, 0, ".png"), dir / "frames/a.png");
  PoseCommandOptions options;
  options.inputs = {dir / "frames"};
  options.out_path = dir / "out.jsonl";
  options.annotate_dir = dir / "annotated";
  EXPECT_THAT(PoseError(options),
              HasSubstr("pose needs the camera intrinsics: give --camera FILE"));
  options.inputs = {dir / "frames/a.png"};
  EXPECT_THAT(PoseError(options), HasSubstr("give --camera FILE"));
  options.camera_path = dir / "frames/camera.xml";
  EXPECT_THAT(PoseError(options), HasSubstr("camera.xml' does not exist"));
  EXPECT_FALSE(fs::exists(options.out_path));
  EXPECT_FALSE(fs::exists(options.annotate_dir));
  EXPECT_TRUE(test::TempFilesIn(dir.path()).empty());
}

TEST(Pose, TruncatedJpegFailsNamingTheFileAndLeavesNoOutput) {
  test::TestDir dir;
  const std::string data = RenderSmall(dir, "data", 1, 0.0);
  const std::string jpg = data + "/frame_0001.jpg";
  ASSERT_TRUE(cv::imwrite(jpg, cv::imread(FrameFile(data, 0, ".png"))));
  const std::string jpeg = test::ReadText(jpg);
  test::WriteText(jpg, jpeg.substr(0, jpeg.size() / 2));
  PoseCommandOptions options;
  options.inputs = {data};
  options.out_path = dir / "out.jsonl";
  EXPECT_THAT(PoseError(options), HasSubstr("cannot decode image '" + jpg + "': truncated JPEG"));
  EXPECT_FALSE(fs::exists(options.out_path));
  EXPECT_TRUE(test::TempFilesIn(dir.path()).empty());
}

TEST(Pose, BadPoseConfigNamesFileAndLineAndLeavesNoOutput) {
  test::TestDir dir;
  const std::string data = RenderSmall(dir, "data", 1, 0.0);
  const std::string config = dir / "pose.yaml";
  test::WriteText(config, "pose:\n  max_residual_px: 1.5\n  min_group_angle_deg: 95\n");
  PoseCommandOptions options;
  options.inputs = {data};
  options.config_path = config;
  options.out_path = dir / "out.jsonl";
  EXPECT_THAT(PoseError(options),
              HasSubstr(config + ":3: 'pose.min_group_angle_deg' is invalid: 95 (needs"));
  EXPECT_FALSE(fs::exists(options.out_path));
  EXPECT_TRUE(test::TempFilesIn(dir.path()).empty());
}

// The message of the std::runtime_error `yaml` raises, or "" if it loads.
std::string ConfigError(const std::string& yaml) {
  return test::ConfigErrorOf(yaml, "cfg.yaml");
}

TEST(ConfigPose, ErrorsNameFileLineAndKey) {
  EXPECT_THAT(ConfigError("pose:\n  max_residual_px: 2\n  max_residul_px: 1\n"),
              HasSubstr("cfg.yaml:3: key 'pose.max_residul_px' is unknown (known: "
                        "max_candidate_lines, "));
  EXPECT_EQ(ConfigError("pose:\n  correct_stripe_centres: maybe\n"),
            "cfg.yaml:2: 'pose.correct_stripe_centres' must be true or false, got 'maybe'");
  EXPECT_EQ(ConfigError("pose:\n  max_candidate_lines: 4.5\n"),
            "cfg.yaml:2: 'pose.max_candidate_lines' must be an integer, got '4.5'");
  EXPECT_EQ(ConfigError("pose:\n  max_residual_px: far\n"),
            "cfg.yaml:2: 'pose.max_residual_px' must be a number, got 'far'");
  EXPECT_THAT(ConfigError("pose:\n\n  max_residual_px: 0\n"),
              HasSubstr("cfg.yaml:3: 'pose.max_residual_px' is invalid: 0 (needs"));
  EXPECT_EQ(ConfigError("pose:\n  vvs_max_iterations: 5\n  vvs_max_iterations: 6\n"),
            "cfg.yaml:3: key 'pose.vvs_max_iterations' is repeated (first at line 2)");
  // The camera comes from --camera, not from the configuration.
  EXPECT_THAT(ConfigError("pose:\n  camera: 600\n"),
              HasSubstr("cfg.yaml:2: key 'pose.camera' is unknown"));
  EXPECT_THAT(ConfigError("pose: 3\n"), HasSubstr("cfg.yaml:1: section 'pose' must be a map"));
}

TEST(ConfigPose, ReadsTheTunables) {
  const PoseOptions pose = ParseConfig(
                               "pose:\n"
                               "  max_candidate_lines: 8\n"
                               "  min_group_angle_deg: 20\n"
                               "  max_identification_cost: 30\n"
                               "  min_identification_margin: 4.5\n"
                               "  max_residual_px: 1.5\n"
                               "  correct_stripe_centres: false\n"
                               "  dementhon_above_px: 0\n",
                               "cfg.yaml")
                               .pose;
  EXPECT_EQ(pose.max_candidate_lines, 8);
  EXPECT_EQ(pose.min_group_angle_deg, 20.0);
  EXPECT_EQ(pose.max_identification_cost, 30.0);
  EXPECT_EQ(pose.min_identification_margin, 4.5);
  EXPECT_EQ(pose.max_residual_px, 1.5);
  EXPECT_FALSE(pose.correct_stripe_centres);
  EXPECT_EQ(pose.dementhon_above_px, 0.0);
  EXPECT_EQ(pose.vvs_max_iterations, PoseOptions().vvs_max_iterations);  // untouched
}

TEST(ConfigPose, ShippedFileIsTheDefaults) {
  const PoseOptions shipped = LoadConfig(std::string(OAL_SOURCE_DIR) + "/config/pose.yaml").pose;
  const PoseOptions defaults;
  EXPECT_EQ(shipped.max_candidate_lines, defaults.max_candidate_lines);
  EXPECT_EQ(shipped.min_group_angle_deg, defaults.min_group_angle_deg);
  EXPECT_EQ(shipped.max_outside_px, defaults.max_outside_px);
  EXPECT_EQ(shipped.max_intersection_radius, defaults.max_intersection_radius);
  EXPECT_EQ(shipped.min_side_px, defaults.min_side_px);
  EXPECT_EQ(shipped.dementhon_above_px, defaults.dementhon_above_px);
  EXPECT_EQ(shipped.ortho_sigma, defaults.ortho_sigma);
  EXPECT_EQ(shipped.width_sigma, defaults.width_sigma);
  EXPECT_EQ(shipped.max_identification_cost, defaults.max_identification_cost);
  EXPECT_EQ(shipped.min_identification_margin, defaults.min_identification_margin);
  EXPECT_EQ(shipped.max_residual_px, defaults.max_residual_px);
  EXPECT_EQ(shipped.previous_tolerance_px, defaults.previous_tolerance_px);
  EXPECT_EQ(shipped.min_depth_m, defaults.min_depth_m);
  EXPECT_EQ(shipped.correct_stripe_centres, defaults.correct_stripe_centres);
  EXPECT_EQ(shipped.vvs_max_iterations, defaults.vvs_max_iterations);
}

}  // namespace
}  // namespace oal

namespace oal {
namespace {

// A camera file that knows nothing of the lens: kdu is told from the sheet's stripes.
TEST(PoseCommand, EstimatesTheLensFromTheStripesAndUsesIt) {
  const test::TestDir dir;
  RenderCommandOptions render = test::ScaledRender(dir / "data", 14, 5, 640, 480);
  render.target = "four-line-a3";
  render.kdu = 0.15;
  test::RenderChecked(render);
  Lens pinhole = Lens::Pinhole(600.0, 600.0, 319.5, 239.5);
  SaveCameraFile(dir / "pinhole.xml", pinhole, "Camera", 640, 480);
  PoseCommandOptions options;
  options.inputs = {dir / "data"};
  options.camera_path = dir / "pinhole.xml";
  options.independent = true;
  options.estimate_distortion = true;
  options.estimate_frames = 10;  // of the 14 frames
  std::ostringstream out;
  const PoseSummary summary = EstimatePoses(options, out);
  ASSERT_TRUE(summary.estimated_kdu.has_value());
  EXPECT_NEAR(*summary.estimated_kdu, 0.15, 0.05 * 0.15);
  ASSERT_EQ(summary.notes.size(), 1u);
  EXPECT_THAT(summary.notes[0], HasSubstr("from the stripes of 10 frames"));
  // Every frame, the ten read ahead too, once and in order, undistorted by the estimate.
  const std::vector<json> frames = ParseJsonLines(out.str());
  ASSERT_EQ(frames.size(), 14u);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(frames[i].at("frame"), static_cast<int>(i));
    EXPECT_EQ(frames[i].at("source"), FrameFile(dir / "data", static_cast<int>(i), ".png"));
    EXPECT_EQ(frames[i].at("coordinates"), "undistorted");
    ExpectPoseNearTruth(frames[i], FrameFile(dir / "data", static_cast<int>(i), ".json"));
  }
  // No lens warning: the estimate straightens the stripes.
  for (const std::string& warning : summary.warnings) EXPECT_THAT(warning, Not(HasSubstr("bend")));
}

TEST(PoseCommand, EstimatingALensTheCameraFileAlreadyHasIsRefused) {
  const test::TestDir dir;
  const std::string data = RenderSmall(dir, "data", 2, 0.15);
  PoseCommandOptions options;
  options.inputs = {data};
  options.estimate_distortion = true;
  std::ostringstream out;
  const std::string error = test::ErrorMessageOf([&] { EstimatePoses(options, out); });
  EXPECT_THAT(error, HasSubstr("--estimate-distortion is for a camera file without distortion"));

  options.estimate_frames = 0;
  EXPECT_THAT(test::ErrorMessageOf([&] { EstimatePoses(options, out); }),
              HasSubstr("--estimate-frames = 0: give 1 to 100 frames"));
  EXPECT_TRUE(out.str().empty()) << "nothing is written before the options are checked";
}

}  // namespace
}  // namespace oal
