#include "app/detect_command.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cctype>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <stdexcept>
#include <string>

#include "app/render_command.h"
#include "tests/app/command_test_util.h"
#include "tests/test_util.h"

namespace oal {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using ::testing::HasSubstr;

// A small rendered data set: `count` frames of 160x120 (fx scaled from 600 at 640x480).
std::string RenderSmall(const test::TestDir& dir, int count, double kdu) {
  RenderCommandOptions render = test::ScaledRender(dir / "data", count, 7, 160, 120);
  render.kdu = kdu;
  render.min_visible_px = 30.0;
  return test::RenderChecked(render);
}

using test::ParseJsonLines;

void ExpectWellFormedFrame(const json& frame, int index, int width, int height,
                           const std::string& coordinates) {
  EXPECT_EQ(frame.at("frame").get<int>(), index);
  EXPECT_FALSE(frame.at("source").get<std::string>().empty());
  EXPECT_EQ(frame.at("width").get<int>(), width);
  EXPECT_EQ(frame.at("height").get<int>(), height);
  EXPECT_GE(frame.at("time_us").get<double>(), 0.0);
  EXPECT_EQ(frame.at("coordinates"), coordinates);
  // detect scans the whole image (the paper's borders); the JSON says so.
  EXPECT_EQ(frame.at("scan").at("mode"), "image");
  EXPECT_TRUE(frame.at("scan").at("region").empty());
  ASSERT_TRUE(frame.at("lines").is_array());
  for (const json& line : frame.at("lines")) {
    for (const char* key : {"rho", "theta", "votes", "count", "borders", "support", "width"}) {
      EXPECT_TRUE(line.at(key).is_number()) << key;
    }
    EXPECT_EQ(line.at("end_a").size(), 2u);
    EXPECT_EQ(line.at("end_b").size(), 2u);
    const double theta = line.at("theta").get<double>();
    EXPECT_GE(theta, 0.0);
    EXPECT_LT(theta, 3.15);
  }
}

// The message DetectImages throws with, or "" if it succeeds.
std::string DetectError(const DetectCommandOptions& options) {
  std::ostringstream out;
  return test::ErrorMessageOf([&] { DetectImages(options, out); });
}

TEST(Detect, RenderedDirectoryGivesOneJsonLinePerFrame) {
  test::TestDir dir;
  DetectCommandOptions options;
  options.inputs = {RenderSmall(dir, 3, 0.0)};
  options.out_path = dir / "lines.jsonl";
  std::ostringstream stdout_text;
  const DetectSummary summary = DetectImages(options, stdout_text);
  EXPECT_EQ(summary.frames, 3);
  EXPECT_TRUE(stdout_text.str().empty());
  // camera.xml and the frame_NNNN.json files are the renderer's: skipped without a warning.
  EXPECT_TRUE(summary.warnings.empty()) << summary.warnings.front();
  const std::vector<json> frames = ParseJsonLines(test::ReadText(options.out_path));
  ASSERT_EQ(frames.size(), 3u);
  for (int i = 0; i < 3; ++i) ExpectWellFormedFrame(frames[i], i, 160, 120, "image");
  EXPECT_THAT(frames[2].at("source").get<std::string>(), HasSubstr("frame_0002.png"));
  EXPECT_GT(summary.lines, 0);
  EXPECT_TRUE(test::TempFilesIn(dir.path()).empty());
}

TEST(Detect, WithoutOutWritesToTheStream) {
  test::TestDir dir;
  DetectCommandOptions options;
  options.inputs = {RenderSmall(dir, 2, 0.0) + "/frame_%04d.png"};
  options.paper = true;
  std::ostringstream out;
  EXPECT_EQ(DetectImages(options, out).frames, 2);
  const std::vector<json> frames = ParseJsonLines(out.str());
  ASSERT_EQ(frames.size(), 2u);
  ExpectWellFormedFrame(frames[1], 1, 160, 120, "image");
}

TEST(Detect, SeveralInputsAreNumberedOneAfterTheOther) {
  test::TestDir dir;
  const std::string data = RenderSmall(dir, 2, 0.0);
  DetectCommandOptions options;
  options.inputs = {data + "/frame_0001.png", data, data + "/frame_0000.png"};
  std::ostringstream out;
  EXPECT_EQ(DetectImages(options, out).frames, 4);
  const std::vector<json> frames = ParseJsonLines(out.str());
  ASSERT_EQ(frames.size(), 4u);
  EXPECT_EQ(frames[3].at("frame"), 3);
  options.max_frames = 3;
  std::ostringstream limited;
  EXPECT_EQ(DetectImages(options, limited).frames, 3);
}

TEST(Detect, CameraWithDistortionGivesUndistortedLinesAndCurvedAnnotations) {
  test::TestDir dir;
  const std::string data = RenderSmall(dir, 2, 0.25);
  DetectCommandOptions options;
  options.inputs = {data};
  options.camera_path = data + "/camera.xml";
  options.out_path = dir / "lines.jsonl";
  options.annotate_dir = dir / "annotated/deeper";
  std::ostringstream out;
  DetectImages(options, out);
  const std::vector<json> frames = ParseJsonLines(test::ReadText(options.out_path));
  ASSERT_EQ(frames.size(), 2u);
  for (int i = 0; i < 2; ++i) ExpectWellFormedFrame(frames[i], i, 160, 120, "undistorted");
  for (const char* name : {"lines_0000.png", "lines_0001.png"}) {
    const cv::Mat image = cv::imread((fs::path(options.annotate_dir) / name).string());
    ASSERT_FALSE(image.empty()) << name;
    EXPECT_EQ(image.channels(), 3);
    EXPECT_EQ(image.cols, 160);
  }
  EXPECT_TRUE(test::TempFilesIn(dir.path()).empty());
}

TEST(Detect, CameraWithoutDistortionKeepsImageCoordinates) {
  test::TestDir dir;
  DetectCommandOptions options;
  const std::string data = RenderSmall(dir, 1, 0.0);  // kdu = 0 in camera.xml
  options.inputs = {data};
  options.camera_path = data + "/camera.xml";
  std::ostringstream out;
  DetectImages(options, out);
  EXPECT_EQ(ParseJsonLines(out.str()).at(0).at("coordinates"), "image");
}

// Each frame says how much its four strongest lines bend: on the 2 m board (lines across the
// image) under 0.2 px with the camera file of the lens, more without its distortion.
TEST(Detect, EachFrameSaysHowMuchItsStrongestLinesBend) {
  test::TestDir dir;
  RenderCommandOptions render = test::ScaledRender(dir / "wide", 5, 7, 640, 480);
  render.kdu = 0.3;
  const std::string wide = test::RenderChecked(render);
  render.out_dir = dir / "pinhole";
  render.kdu = 0.0;
  const std::string pinhole = test::RenderChecked(render);  // its camera.xml: no distortion
  DetectCommandOptions options;
  options.inputs = {wide};
  options.camera_path = wide + "/camera.xml";
  std::ostringstream right;
  EXPECT_EQ(DetectImages(options, right).straightness_px.size(), 5u);
  for (const json& frame : ParseJsonLines(right.str())) {
    EXPECT_LT(frame.at("straightness_px").get<double>(), 0.2) << frame.at("source");
  }
  options.camera_path = pinhole + "/camera.xml";
  std::ostringstream wrong;
  DetectImages(options, wrong);
  for (const json& frame : ParseJsonLines(wrong.str())) {
    EXPECT_GT(frame.at("straightness_px").get<double>(), 0.5) << frame.at("source");
  }
}

TEST(Detect, WarnsWhenTheCameraIsForAnotherImageSize) {
  test::TestDir dir;
  const std::string data = RenderSmall(dir, 1, 0.0);  // camera.xml for 160x120
  ASSERT_TRUE(cv::imwrite(dir / "big.png", cv::Mat(100, 200, CV_8UC1, cv::Scalar(128))));
  DetectCommandOptions options;
  options.inputs = {dir / "big.png"};
  options.camera_path = data + "/camera.xml";
  std::ostringstream out;
  const DetectSummary summary = DetectImages(options, out);
  ASSERT_EQ(summary.warnings.size(), 1u);
  EXPECT_THAT(summary.warnings[0], HasSubstr("calibrated for 160x120"));
  EXPECT_THAT(summary.warnings[0], HasSubstr("is 200x100"));
}

TEST(Detect, VispLineSequenceWithEdgePolarity) {
  const std::string dir = std::string(OAL_VISP_IMAGES_DIR) + "/line";
  if (!fs::is_directory(dir))
    GTEST_SKIP() << dir << " is missing (apt-get install visp-images-data)";
  int files = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    files += entry.path().extension() == ".pgm" ? 1 : 0;
  }
  test::TestDir tmp;
  test::WriteText(tmp / "edges.yaml", "detector:\n  polarity: edges\n");
  DetectCommandOptions options;
  options.inputs = {dir + "/image.%04d.pgm"};
  options.config_path = tmp / "edges.yaml";
  options.out_path = tmp / "line.jsonl";
  std::ostringstream out;
  const DetectSummary summary = DetectImages(options, out);
  EXPECT_EQ(summary.frames, files);
  const std::vector<json> frames = ParseJsonLines(test::ReadText(options.out_path));
  ASSERT_EQ(static_cast<int>(frames.size()), files);
  ExpectWellFormedFrame(frames[0], 0, frames[0].at("width").get<int>(),
                        frames[0].at("height").get<int>(), "image");
  EXPECT_GT(summary.lines, 0) << "no line in the whole sequence";
}

// Each bad input fails with its reason and leaves neither the output nor a temporary file.
struct BadInput {
  const char* name;
  const char* expected_message;
};

void PrintTo(const BadInput& input, std::ostream* out) {
  *out << input.name;
}

class DetectBadInput : public ::testing::TestWithParam<BadInput> {};

TEST_P(DetectBadInput, FailsClearlyAndLeavesNoOutput) {
  test::TestDir dir;
  test::WriteText(dir / "text.png", "hello, I am text\n");
  ASSERT_TRUE(cv::imwrite(dir / "good.png", cv::Mat(120, 160, CV_8UC1, cv::Scalar(128))));
  const std::string png = test::ReadText(dir / "good.png");
  test::WriteText(dir / "truncated.png", png.substr(0, png.size() / 2));
  test::WriteText(dir / "garbage.avi", std::string(10000, '\x13'));
  fs::create_directory(dir.path() / "mixed");
  fs::copy_file(dir / "good.png", dir / "mixed/a.png");
  fs::copy_file(dir / "truncated.png", dir / "mixed/b.png");  // fails after a.png was written
  ASSERT_TRUE(cv::imwrite(dir / "good.jpg", cv::Mat(120, 160, CV_8UC1, cv::Scalar(128))));
  const std::string jpeg = test::ReadText(dir / "good.jpg");
  test::WriteText(dir / "truncated.jpg", jpeg.substr(0, jpeg.size() * 3 / 4));
  fs::create_directory(dir.path() / "mixed_jpg");
  fs::copy_file(dir / "good.jpg", dir / "mixed_jpg/a.jpg");
  fs::copy_file(dir / "truncated.jpg", dir / "mixed_jpg/b.jpg");
  test::WriteText(dir / "bad.yaml", "detector:\n  step_px: -1\n");

  DetectCommandOptions options;
  const std::string name = GetParam().name;
  options.inputs = {name.rfind("/dev/", 0) == 0 ? name : dir / name};
  if (name == "bad-config") {
    options.inputs = {dir / "good.png"};
    options.config_path = dir / "bad.yaml";
  }
  if (name == "missing-camera") {
    options.inputs = {dir / "good.png"};
    options.camera_path = dir / "camera.xml";
  }
  options.out_path = dir / "out/lines.jsonl";
  fs::create_directory(dir.path() / "out");
  EXPECT_THAT(DetectError(options), HasSubstr(GetParam().expected_message));
  EXPECT_FALSE(fs::exists(options.out_path));
  EXPECT_TRUE(fs::is_empty(dir.path() / "out"));
  EXPECT_TRUE(test::TempFilesIn(dir.path()).empty());
}

INSTANTIATE_TEST_SUITE_P(
    Inputs, DetectBadInput,
    ::testing::Values(BadInput{"missing.png", "no such file or directory"},
                      BadInput{"text.png", "cannot decode image"},
                      BadInput{"truncated.png", "cannot decode image"},
                      BadInput{"truncated.jpg", "truncated.jpg': truncated JPEG"},
                      BadInput{"mixed_jpg", "b.jpg': truncated JPEG"},
                      BadInput{"garbage.avi", "garbage.avi'"},
                      BadInput{"/dev/video99", "no V4L2 device at /dev/video99"},
                      BadInput{"mixed", "cannot decode image"},
                      BadInput{"bad-config", "bad.yaml:2: 'detector.step_px' is invalid"},
                      BadInput{"missing-camera", "camera.xml' does not exist"}),
    [](const ::testing::TestParamInfo<BadInput>& param_info) {
      std::string name;
      for (const char* c = param_info.param.name; *c != '\0'; ++c) {
        name += std::isalnum(static_cast<unsigned char>(*c)) ? *c : '_';
      }
      return name;
    });

TEST(Detect, OptionsAreChecked) {
  test::TestDir dir;
  DetectCommandOptions options;
  EXPECT_THAT(DetectError(options), HasSubstr("no input: give an image"));
  options.inputs = {"x.png"};
  options.max_frames = -1;
  EXPECT_THAT(DetectError(options), HasSubstr("--max-frames = -1. Violated constraint"));
  options.max_frames = 0;
  options.out_path = dir / "no/such/dir/lines.jsonl";
  EXPECT_THAT(DetectError(options), HasSubstr("does not exist"));
  options.out_path.clear();
  options.camera_name = "left";  // without a camera file it would be ignored
  EXPECT_THAT(DetectError(options), HasSubstr("camera_name 'left' needs camera_path"));
}

}  // namespace
}  // namespace oal
