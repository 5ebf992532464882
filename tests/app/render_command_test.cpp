#include "app/render_command.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/command_line.h"
#include "io/camera_file.h"
#include "scene/scene.h"
#include "tests/app/command_test_util.h"
#include "tests/test_util.h"

namespace oal {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using ::testing::HasSubstr;

RenderCommandOptions SmallRender(const std::string& out_dir) {
  RenderCommandOptions options = test::ScaledRender(out_dir, 3, 3, 160, 120);
  options.kdu = 0.2;
  options.noise_sigma = 3.0;
  options.min_visible_px = 30.0;
  return options;
}

TEST(Render, WritesFramesTruthAndCamera) {
  test::TestDir dir;
  const RenderCommandOptions options = SmallRender(dir / "data");
  EXPECT_EQ(RenderDataset(options), 3);
  for (int i = 0; i < 3; ++i) {
    const std::string stem = options.out_dir + "/frame_000" + std::to_string(i);
    const cv::Mat image = cv::imread(stem + ".png", cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(image.empty()) << stem;
    EXPECT_EQ(image.type(), CV_8UC1);
    EXPECT_EQ(image.cols, 160);
    EXPECT_EQ(image.rows, 120);
    const json truth = json::parse(test::ReadText(stem + ".json"));
    EXPECT_EQ(truth.at("frame"), i);
    EXPECT_EQ(truth.at("image"), "frame_000" + std::to_string(i) + ".png");
    EXPECT_EQ(truth.at("cMo").at("matrix").size(), 4u);
    EXPECT_EQ(truth.at("cMo").at("matrix")[3], json::array({0.0, 0.0, 0.0, 1.0}));
    EXPECT_EQ(truth.at("cMo").at("t_m").size(), 3u);
    EXPECT_EQ(truth.at("cMo").at("thetau_rad").size(), 3u);
    EXPECT_EQ(truth.at("camera").at("kdu"), 0.2);
    EXPECT_EQ(truth.at("camera").at("u0"), 79.5);
    ASSERT_EQ(truth.at("lines").size(), 4u);  // the four-line target
    for (const json& line : truth.at("lines")) {
      EXPECT_TRUE(line.at("visible").get<bool>());
      EXPECT_GE(line.at("visible_length_px").get<double>(), 30.0);
      for (const char* key : {"index", "ideal", "distorted_fit", "end_a", "end_b", "width_px"}) {
        EXPECT_TRUE(line.contains(key)) << key;
      }
    }
  }
  const CameraFile camera = LoadCameraFile(options.out_dir + "/camera.xml");
  EXPECT_EQ(camera.name, "oal-render");
  EXPECT_EQ(camera.width, 160u);
  EXPECT_EQ(camera.height, 120u);
  EXPECT_EQ(camera.camera.model(), Lens::Model::kViSP);
  EXPECT_DOUBLE_EQ(camera.camera.kdu(), 0.2);
  EXPECT_NEAR(camera.camera.kud(), FitKud(camera.camera, 160, 120), 1e-9);
  EXPECT_LT(camera.camera.kud(), 0.0);  // barrel: the inverse of a positive kdu
  EXPECT_TRUE(test::TempFilesIn(dir.path()).empty());
}

// Through a camera file: its camera at its image size; --fx or --kdu with it is refused.
TEST(Render, ThroughACameraFile) {
  test::TestDir dir;
  ASSERT_EQ(RenderDataset(SmallRender(dir / "small")), 3);
  RenderCommandOptions again = test::ScaledRender(dir / "again", 1, 4, 640, 480);
  again.camera_path = dir / "small/camera.xml";
  ASSERT_EQ(RenderDataset(again), 1);
  const CameraFile camera = LoadCameraFile(dir / "again/camera.xml");
  EXPECT_EQ(camera.width, 160u);
  EXPECT_EQ(camera.height, 120u);
  EXPECT_DOUBLE_EQ(camera.camera.kdu(), 0.2);
  EXPECT_EQ(cv::imread(dir / "again/frame_0000.png", cv::IMREAD_UNCHANGED).cols, 160);
  const test::OalservoRun both =
      test::RunOalservo(dir, "render --count 1 --camera '" + dir / "small/camera.xml" +
                                 "' --fx 500 --out '" + dir / "refused" + "'");
  EXPECT_EQ(both.exit_code, 2);
  EXPECT_THAT(both.err, HasSubstr("--fx excludes --camera"));
  EXPECT_FALSE(fs::exists(dir / "refused"));
}

// A config's lived-in scene: each frame's conditions drawn from the seed and recorded in its
// truth with each line's occluded fraction.
TEST(Render, ALivedInSceneRecordsEachFramesConditions) {
  test::TestDir dir;
  test::WriteText(dir / "lived-in.yaml",
                  "target: {name: four-line-a3}\n"
                  "scene:\n  occluders: {fraction: 1, kinds: [pen]}\n"
                  "  jpeg: {fraction: 1, quality: [60, 60]}\n");
  RenderCommandOptions options = SmallRender(dir / "data");
  options.target.clear();
  options.config = dir / "lived-in.yaml";
  options.min_distance_m = 0.5;
  options.max_distance_m = 0.8;
  options.min_visible_px = 0.0;
  ASSERT_EQ(RenderDataset(options), 3);
  for (int i = 0; i < 3; ++i) {
    const json truth =
        json::parse(test::ReadText(options.out_dir + "/frame_000" + std::to_string(i) + ".json"));
    EXPECT_EQ(truth.at("effects").at("plane_occluders").size(), 1u);
    EXPECT_EQ(truth.at("effects").at("jpeg_quality"), 60);
    EXPECT_TRUE(truth.at("lines")[0].contains("occluded_fraction"));
  }
}

TEST(Render, SameSeedSameFiles) {
  test::TestDir dir;
  RenderCommandOptions a = SmallRender(dir / "a"), b = SmallRender(dir / "b");
  a.count = b.count = 2;
  RenderDataset(a);
  RenderDataset(b);
  for (const char* name : {"frame_0000.png", "frame_0001.png", "frame_0001.json"}) {
    EXPECT_EQ(test::ReadText(dir / (std::string("a/") + name)),
              test::ReadText(dir / (std::string("b/") + name)))
        << name;
  }
  RenderCommandOptions c = SmallRender(dir / "c");
  c.count = 1;
  c.seed = 4;
  RenderDataset(c);
  EXPECT_NE(test::ReadText(dir / "a/frame_0000.json"), test::ReadText(dir / "c/frame_0000.json"));
}

TEST(Render, CameraHasThePrincipalPointAtTheCentre) {
  const Lens camera = RenderCamera(640, 480, 600.0, 0.0);
  EXPECT_EQ(camera.u0(), 319.5);
  EXPECT_EQ(camera.v0(), 239.5);
  EXPECT_EQ(camera.px(), 600.0);
  EXPECT_EQ(camera.py(), 600.0);
  EXPECT_EQ(camera.kdu(), 0.0);
  EXPECT_EQ(camera.kud(), 0.0);
}

TEST(Render, BadOptionsNameTheField) {
  test::TestDir dir;
  RenderCommandOptions options = SmallRender(dir / "data");
  options.count = 0;
  try {
    RenderDataset(options);
    FAIL() << "no error";
  } catch (const std::invalid_argument& error) {
    EXPECT_THAT(error.what(),
                HasSubstr("--count = 0. Violated constraint: 1 <= --count <= 100000"));
  }
  options = SmallRender(dir / "data");
  options.target = "three-line";
  EXPECT_THROW(RenderDataset(options), std::invalid_argument);
  options = SmallRender(dir / "data");
  options.background_image = dir / "missing.png";
  EXPECT_THROW(RenderDataset(options), std::invalid_argument);
  EXPECT_FALSE(fs::exists(dir / "data"));
}

// --target takes every built-in (and "four-line", the 2 m board's older name); the error for
// another names them all.
TEST(Render, TargetIsAnyBuiltInByName) {
  test::TestDir dir;
  std::vector<std::string> names = TargetNames();
  names.push_back("four-line");
  for (const std::string& name : names) {
    RenderCommandOptions options = SmallRender(dir / "data");
    options.target = name;
    EXPECT_NO_THROW(options.Check()) << name;
  }
  RenderCommandOptions options = SmallRender(dir / "data");
  options.target = "four-line-a5";
  const std::string error =
      test::ErrorMessageOf<std::invalid_argument>([&] { RenderDataset(options); });
  EXPECT_THAT(error, HasSubstr("--target = four-line-a5. Violated constraint: it is one of "));
  for (const std::string& name : TargetNames()) EXPECT_THAT(error, HasSubstr(name));
  EXPECT_FALSE(fs::exists(dir / "data"));
  // A sheet target renders and names itself in the truth.
  options = SmallRender(dir / "a4");
  options.target = "four-line-a4";
  options.count = 1;
  options.min_distance_m = 0.3;
  options.max_distance_m = 0.5;
  ASSERT_EQ(RenderDataset(options), 1);
  const json truth = json::parse(test::ReadText(dir / "a4/frame_0000.json"));
  EXPECT_EQ(truth.at("target"), "four-line-a4");
  EXPECT_EQ(truth.at("lines").size(), 4u);
}

// Options errors name the command-line option, not the struct's field.
TEST(Render, BadOptionsNameTheCommandLineOption) {
  test::TestDir dir;
  const auto error = [&](auto change) {
    RenderCommandOptions options = SmallRender(dir / "data");
    change(&options);
    return test::ErrorMessageOf<std::invalid_argument>([&] { RenderDataset(options); });
  };
  EXPECT_EQ(error([](RenderCommandOptions* o) { o->fx_px = 0.0; }),
            "--fx = 0. Violated constraint: 0 < --fx <= 100000");
  EXPECT_THAT(error([](RenderCommandOptions* o) { o->kdu = 1.5; }),
              HasSubstr("--kdu = 1.5. Violated constraint: -1 < --kdu < 1"));
  EXPECT_THAT(error([](RenderCommandOptions* o) { o->max_tilt_deg = 90.0; }),
              HasSubstr("--max-tilt-deg = 90"));
  EXPECT_THAT(error([](RenderCommandOptions* o) { o->min_tilt_deg = 40.0; }),
              HasSubstr("--min-tilt-deg = 40. Violated constraint: 0 <= --min-tilt-deg <= "
                        "--max-tilt-deg"));
  EXPECT_THAT(error([](RenderCommandOptions* o) { o->min_visible_px = -1.0; }),
              HasSubstr("--min-visible-px = -1"));
  EXPECT_FALSE(fs::exists(dir / "data"));
  // A negative seed is a usage error, not 2^64 - 1.
  EXPECT_THROW(test::RunWithArgs(RunRender, {"render", "--seed", "-1", "--out", dir / "data"}),
               UsageError);
  EXPECT_FALSE(fs::exists(dir / "data"));
}

// A second render into a folder that holds a data set is refused, and the first data set is
// untouched: no frames of one camera next to another's camera.xml.
TEST(Render, ADataSetIsNotOverwrittenWithoutOverwrite) {
  test::TestDir dir;
  RenderCommandOptions first = SmallRender(dir / "reuse");
  first.count = 4;
  ASSERT_EQ(RenderDataset(first), 4);
  const std::string camera_before = test::ReadText(dir / "reuse/camera.xml");
  RenderCommandOptions second = SmallRender(dir / "reuse");
  second.count = 2;
  second.kdu = 0.0;
  const std::string message =
      test::ErrorMessageOf<std::invalid_argument>([&] { RenderDataset(second); });
  EXPECT_THAT(message,
              HasSubstr("--out '" + dir / "reuse" + "' already holds a rendered data set"));
  EXPECT_THAT(message, HasSubstr("--overwrite"));
  EXPECT_EQ(test::ReadText(dir / "reuse/camera.xml"), camera_before);
  EXPECT_TRUE(fs::exists(dir / "reuse/frame_0003.png"));
  // The same through the command line; exit by exception, as main() maps it to 1.
  EXPECT_THROW(test::RunWithArgs(RunRender, {"render", "--count", "2", "--width", "160", "--height",
                                             "120", "--out", dir / "reuse/"}),
               std::invalid_argument);
  EXPECT_TRUE(test::TempFilesIn(dir.path()).empty());
}

// --overwrite replaces every renderer file (frames of a longer run too) and keeps the rest.
TEST(Render, OverwriteReplacesTheWholeDataSetAndKeepsOtherFiles) {
  test::TestDir dir;
  RenderCommandOptions first = SmallRender(dir / "reuse");
  first.count = 4;
  RenderDataset(first);
  test::WriteText(dir / "reuse/notes.txt", "mine");
  RenderCommandOptions second = SmallRender(dir / "reuse");
  second.count = 2;
  second.kdu = 0.0;
  second.overwrite = true;
  ASSERT_EQ(RenderDataset(second), 2);
  EXPECT_TRUE(fs::exists(dir / "reuse/frame_0001.png"));
  for (const char* stale : {"frame_0002.png", "frame_0002.json", "frame_0003.png"}) {
    EXPECT_FALSE(fs::exists(dir / (std::string("reuse/") + stale))) << stale;
  }
  EXPECT_EQ(LoadCameraFile(dir / "reuse/camera.xml").camera.kdu(), 0.0);
  EXPECT_EQ(json::parse(test::ReadText(dir / "reuse/frame_0001.json")).at("camera").at("kdu"), 0.0);
  EXPECT_EQ(test::ReadText(dir / "reuse/notes.txt"), "mine");
  EXPECT_TRUE(test::TempFilesIn(dir.path()).empty());

  // A sequence over random frames: sequence.json comes; random frames over a sequence: it goes.
  RenderCommandOptions sequence = test::SequenceRender(dir / "reuse", "slow", 3, 1);
  sequence.overwrite = true;
  RenderDataset(sequence);
  EXPECT_TRUE(fs::exists(dir / "reuse/sequence.json"));
  EXPECT_TRUE(fs::exists(dir / "reuse/frame_0002.png"));
  RenderDataset(second);
  EXPECT_FALSE(fs::exists(dir / "reuse/sequence.json"));
  EXPECT_FALSE(fs::exists(dir / "reuse/frame_0002.png"));
  EXPECT_TRUE(test::TempFilesIn(dir.path()).empty());
}

// A folder with files of other tools only is not a data set: rendering into it is allowed.
TEST(Render, IntoAFolderWithOtherFilesOnly) {
  test::TestDir dir;
  fs::create_directories(dir / "mixed");
  test::WriteText(dir / "mixed/frame_notes.txt", "mine");
  const RenderCommandOptions options = SmallRender(dir / "mixed");
  ASSERT_EQ(RenderDataset(options), 3);
  EXPECT_TRUE(fs::exists(dir / "mixed/frame_0002.json"));
  EXPECT_EQ(test::ReadText(dir / "mixed/frame_notes.txt"), "mine");
  EXPECT_TRUE(test::TempFilesIn(dir.path()).empty());
}

// A render that fails (no pose meets --min-visible-px) leaves nothing: no
// camera.xml, no frame, no temporary or parent folder, and an older data set as it was.
TEST(Render, AFailedRenderLeavesNothingBehind) {
  test::TestDir dir;
  RenderCommandOptions impossible = SmallRender(dir / "new/deeper/data");
  impossible.count = 30;
  impossible.min_visible_px = 660.0;  // longer than the 160x120 image's diagonal
  EXPECT_THROW(RenderDataset(impossible), std::runtime_error);
  EXPECT_FALSE(fs::exists(dir / "new"));
  EXPECT_TRUE(fs::is_empty(dir.path()));

  RenderCommandOptions old = SmallRender(dir / "data");
  RenderDataset(old);
  const std::string frame_before = test::ReadText(dir / "data/frame_0002.json");
  impossible.out_dir = dir / "data";
  impossible.overwrite = true;
  EXPECT_THROW(RenderDataset(impossible), std::runtime_error);
  EXPECT_EQ(test::ReadText(dir / "data/frame_0002.json"), frame_before);
  EXPECT_FALSE(fs::exists(dir / "data/frame_0003.png"));
  EXPECT_TRUE(test::TempFilesIn(dir.path()).empty());
  std::vector<std::string> entries;
  for (const auto& entry : fs::directory_iterator(dir.path())) {
    entries.push_back(entry.path().filename().string());
  }
  EXPECT_EQ(entries, std::vector<std::string>{"data"});
}

TEST(RenderSequence, WritesFramesTruthAndSequenceJson) {
  test::TestDir dir;
  const RenderCommandOptions options = test::SequenceRender(dir / "occlusion", "occlusion", 10, 5);
  EXPECT_EQ(RenderDataset(options), 10);
  int frames_with_occluder = 0;
  for (int i = 0; i < 10; ++i) {
    const std::string stem = options.out_dir + "/frame_000" + std::to_string(i);
    const cv::Mat image = cv::imread(stem + ".png", cv::IMREAD_UNCHANGED);
    ASSERT_FALSE(image.empty()) << stem;
    EXPECT_EQ(image.type(), CV_8UC1);
    EXPECT_EQ(image.cols, 640);
    EXPECT_EQ(image.rows, 480);
    const json truth = json::parse(test::ReadText(stem + ".json"));
    EXPECT_EQ(truth.at("frame"), i);
    EXPECT_EQ(truth.at("sequence"), "occlusion");
    EXPECT_EQ(truth.at("seed"), 5);
    EXPECT_EQ(truth.at("cMo").at("matrix").size(), 4u);
    EXPECT_EQ(truth.at("effects").at("gain"), 1.0);
    frames_with_occluder += truth.at("effects").at("occluders").empty() ? 0 : 1;
    ASSERT_EQ(truth.at("lines").size(), 4u);
    for (const json& line : truth.at("lines")) {
      EXPECT_TRUE(line.at("visible").get<bool>());
      EXPECT_TRUE(line.contains("occluded_fraction"));
    }
  }
  EXPECT_GT(frames_with_occluder, 0);
  EXPECT_FALSE(fs::exists(options.out_dir + "/frame_0010.png"));
  const json sequence = json::parse(test::ReadText(options.out_dir + "/sequence.json"));
  EXPECT_EQ(sequence.at("kind"), "occlusion");
  EXPECT_EQ(sequence.at("seed"), 5);
  EXPECT_EQ(sequence.at("count"), 10);
  EXPECT_EQ(sequence.at("target"), "four-line-board");
  EXPECT_THAT(sequence.at("description").get<std::string>(), HasSubstr("rectangle"));
  const CameraFile camera = LoadCameraFile(options.out_dir + "/camera.xml");
  EXPECT_EQ(camera.width, 640u);
  EXPECT_EQ(camera.height, 480u);
  EXPECT_EQ(camera.camera.px(), 600.0);
  EXPECT_TRUE(test::TempFilesIn(dir.path()).empty());
}

TEST(RenderSequence, SameSeedSameFilesAndDistortionCamera) {
  test::TestDir dir;
  const RenderCommandOptions a = test::SequenceRender(dir / "a", "distortion", 2, 9);
  RenderCommandOptions b = a;
  b.out_dir = dir / "b";
  RenderDataset(a);
  RenderDataset(b);
  for (const char* name : {"frame_0001.png", "frame_0001.json", "sequence.json", "camera.xml"}) {
    EXPECT_EQ(test::ReadText(dir / (std::string("a/") + name)),
              test::ReadText(dir / (std::string("b/") + name)))
        << name;
  }
  const CameraFile camera = LoadCameraFile(a.out_dir + "/camera.xml");
  EXPECT_EQ(camera.camera.model(), Lens::Model::kViSP);
  EXPECT_NEAR(camera.camera.kdu(), 0.47, 1e-12);
}

// A sequence lies on the surface it is given (--background): the frames change only where the
// surface shows, the truth not at all.
TEST(RenderSequence, TakesTheSurfaceFromBackground) {
  test::TestDir dir;
  const std::string photo = dir / "bench.png";
  cv::Mat bench(200, 300, CV_8UC1);
  cv::randu(bench, 0, 255);
  ASSERT_TRUE(cv::imwrite(photo, bench));
  RenderCommandOptions plain = test::SequenceRender(dir / "plain", "slow", 1, 3);
  plain.target = "four-line-a3";
  RenderCommandOptions textured = plain;
  textured.out_dir = dir / "textured";
  textured.background_image = photo;
  RenderDataset(plain);
  RenderDataset(textured);
  const cv::Mat a = cv::imread(plain.out_dir + "/frame_0000.png", cv::IMREAD_UNCHANGED);
  const cv::Mat b = cv::imread(textured.out_dir + "/frame_0000.png", cv::IMREAD_UNCHANGED);
  ASSERT_FALSE(a.empty());
  ASSERT_FALSE(b.empty());
  EXPECT_GT(cv::countNonZero(a != b), a.total() / 10) << "the surface around the sheet";
  EXPECT_LT(cv::countNonZero(a != b), a.total() * 9 / 10) << "the sheet itself";
  const json truth_a = json::parse(test::ReadText(plain.out_dir + "/frame_0000.json"));
  const json truth_b = json::parse(test::ReadText(textured.out_dir + "/frame_0000.json"));
  EXPECT_EQ(truth_a.at("lines"), truth_b.at("lines"));
}

TEST(RenderSequence, UnknownSequenceNamesTheValidOnes) {
  test::TestDir dir;
  RenderCommandOptions options;
  options.out_dir = dir / "data";
  options.sequence = "wobbly";
  try {
    RenderDataset(options);
    FAIL() << "no error";
  } catch (const std::invalid_argument& error) {
    EXPECT_THAT(error.what(), HasSubstr("--sequence = wobbly"));
    EXPECT_THAT(error.what(), HasSubstr("leave-reenter"));
  }
  EXPECT_FALSE(fs::exists(dir / "data"));
}

TEST(RenderSequence, CommandLineDefaultsAndConflicts) {
  test::TestDir dir;
  const std::string out = dir / "slow";
  EXPECT_EQ(
      test::RunWithArgs(RunRender, {"render", "--sequence", "slow", "--count", "3", "--out", out}),
      0);
  EXPECT_TRUE(fs::exists(out + "/frame_0002.png"));
  EXPECT_FALSE(fs::exists(out + "/frame_0003.png"));
  EXPECT_EQ(json::parse(test::ReadText(out + "/sequence.json")).at("count"), 3);

  EXPECT_THROW(
      test::RunWithArgs(RunRender, {"render", "--sequence", "slow", "--kdu", "0.3", "--out", out}),
      UsageError);
}

}  // namespace
}  // namespace oal
