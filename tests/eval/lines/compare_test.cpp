#include "eval/lines/compare.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <stdexcept>
#include <string>

#include "io/camera_file.h"
#include "io/truth_file.h"
#include "tests/eval/rendered_data_set.h"
#include "tests/test_util.h"

namespace oal {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using ::testing::AllOf;
using ::testing::HasSubstr;

// RunComparison with our detector's default setup, tracking `target`'s lines ("": the frames
// show no known target).
CompareReport RunOnImages(CompareOptions options, const std::string& target = "") {
  options.setup = target.empty() ? TrackerSetup() : test::SetupFor(target);
  return RunComparison(options);
}

constexpr int kFrames = 6;
const char* const kMethods[] = {"oal",
                                "oal-tracker",
                                "vpMeLine",
                                "HoughLines (Canny)",
                                "HoughLines (Otsu)",
                                "HoughLinesP (Canny)",
                                "LSD",
                                "FastLineDetector"};

// Six rendered frames of 320x240 (fx scaled from 600 at 640x480), lines long enough to find.
std::string RenderShort(const test::TestDir& dir) {
  test::RandomDataSet render;
  render.count = kFrames;
  render.seed = 3;
  render.width = 320;
  render.height = 240;
  render.noise_sigma = 2.0;
  render.blur_sigma_px = 0.7;
  render.max_tilt_deg = 20.0;
  render.min_visible_px = 100.0;
  return test::WriteDataSet(render, dir / "data");
}

bool AnyContains(const std::vector<std::string>& texts, const std::string& part) {
  return std::any_of(texts.begin(), texts.end(),
                     [&](const std::string& text) { return text.find(part) != std::string::npos; });
}

// The message RunComparison throws with, or "" if it succeeds.
std::string CompareError(const CompareOptions& options) {
  return test::ErrorMessageOf([&] { RunOnImages(options); });
}

TEST(Compare, RenderedSequenceGivesOneRowPerMethod) {
  test::TestDir dir;
  CompareOptions options;
  options.input = RenderShort(dir);
  options.out_dir = dir / "out";
  const CompareReport report = RunOnImages(options, "four-line-board");
  EXPECT_EQ(report.truth_source, "json");
  EXPECT_EQ(report.frames, kFrames);
  ASSERT_EQ(report.methods.size(), std::size(kMethods));
  for (std::size_t m = 0; m < report.methods.size(); ++m) {
    EXPECT_EQ(report.methods[m].name, kMethods[m]);
    EXPECT_EQ(report.methods[m].frames, kFrames);
    EXPECT_EQ(report.methods[m].time_us.size(), static_cast<std::size_t>(kFrames));
    EXPECT_EQ(report.methods[m].truth_lines, kFrames * 4);
  }
  // Our detector finds every line of every frame.
  EXPECT_EQ(report.methods[0].frames_all_found, kFrames);
  EXPECT_EQ(report.methods[0].found_lines, kFrames * 4);
  // Our tracker follows them too, re-detecting by itself (never re-initialised).
  EXPECT_EQ(report.methods[1].frames_all_found, kFrames);
  EXPECT_EQ(report.methods[1].reinitialisations, 0);
  // vpMeLine, initialised from the truth, finds lines (the poses are independent draws, so
  // it may well have to be re-initialised after the first frame).
  EXPECT_GE(report.methods[2].found_lines, 4);
  EXPECT_GE(report.methods[2].reinitialisations, 0);
  EXPECT_EQ(report.methods[3].reinitialisations, -1);

  // The table: a header, a rule and one row per method, each with the same columns.
  const std::string markdown = test::ReadText(fs::path(options.out_dir) / "compare.md");
  EXPECT_EQ(markdown, CompareMarkdown(report));
  std::istringstream in(markdown);
  std::vector<std::string> rows;
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line[0] == '|') rows.push_back(line);
  }
  ASSERT_EQ(rows.size(), 2 + std::size(kMethods));
  const auto columns = [](const std::string& row) {
    return std::count(row.begin(), row.end(), '|');
  };
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(columns(rows[i]), columns(rows[0])) << rows[i];
    if (i >= 2) {
      EXPECT_THAT(rows[i], HasSubstr(std::string("| ") + kMethods[i - 2] + " |"));
    }
  }

  const json parsed = json::parse(test::ReadText(fs::path(options.out_dir) / "compare.json"));
  EXPECT_EQ(parsed.at("frames"), kFrames);
  ASSERT_EQ(parsed.at("methods").size(), std::size(kMethods));
  for (const json& method : parsed.at("methods")) {
    EXPECT_TRUE(method.at("frames_all_found").is_number());
    EXPECT_TRUE(method.at("angle_error_deg").at("p95").is_number());
    EXPECT_TRUE(method.at("offset_error_px").at("mean").is_number());
    EXPECT_TRUE(method.at("spurious_per_frame").is_number());
    EXPECT_GE(method.at("time_us_per_frame_median").get<double>(), 0.0);
  }
  EXPECT_TRUE(parsed.at("methods")[1].contains("reinitialisations"));
  ASSERT_FALSE(report.figures.empty());
  for (const std::string& figure : report.figures) EXPECT_TRUE(fs::is_regular_file(figure));
  EXPECT_TRUE(test::TempFilesIn(options.out_dir).empty());
}

// A sheet on a bench moving in front of the camera: the target tracker's row comes after the
// detectors' (the target is the sheet, the camera the renderer's camera.xml) and
// holds the sheet's four lines, in the target's order, in every frame.
TEST(Compare, ASheetSequenceAddsTheTargetTrackersRow) {
  test::TestDir dir;
  const std::string bench = "/usr/share/visp-images-data/ViSP-images/Klimt/Klimt.pgm";
  if (!fs::is_regular_file(bench)) GTEST_SKIP() << "Debian's visp-images-data is not installed";
  CompareOptions options;
  options.input = test::WriteSequence("slow", 5, 2, dir / "sheet", "four-line-a3", bench);
  options.camera_path = dir / "sheet/camera.xml";
  const CompareReport report = RunOnImages(options, "four-line-a3");
  ASSERT_EQ(report.methods.size(), std::size(kMethods) + 1);
  const MethodResult& target = report.methods.back();
  EXPECT_EQ(target.name, "oal-target");
  EXPECT_EQ(target.reference, report.methods.front().reference);  // as our detector's
  EXPECT_EQ(target.failures, 0);
  EXPECT_EQ(target.frames_all_found, 5);
  EXPECT_EQ(target.spurious_lines, 0);
}

// Without the camera the target is not tracked, and a warning says what to give.
TEST(Compare, ATargetWithoutACameraIsWarnedAbout) {
  test::TestDir dir;
  CompareOptions options;
  options.input = RenderShort(dir);
  const CompareReport report = RunOnImages(options, "four-line-board");
  EXPECT_EQ(report.methods.size(), std::size(kMethods));
  EXPECT_TRUE(AnyContains(report.warnings, "give the camera file (camera_path)"))
      << ::testing::PrintToString(report.warnings);
}

TEST(Compare, CsvTruthIsReadAndScored) {
  test::TestDir dir;
  const std::string data = RenderShort(dir);
  // The CSV form of the JSON truth's distorted_fit lines (no distortion here).
  std::ostringstream csv;
  csv << "frame,line,rho,theta\n# from the rendered truth\n";
  for (int f = 0; f < kFrames; ++f) {
    char name[32];
    std::snprintf(name, sizeof(name), "frame_%04d.json", f);
    for (const TargetLineTruth& line : LoadTruthJson((fs::path(data) / name).string())) {
      csv << f << "," << line.id << "," << line.image_line.rho_px << ","
          << line.image_line.theta_rad << "\n";
    }
  }
  test::WriteText(dir / "truth.csv", csv.str());
  CompareOptions options;
  options.input = data;
  options.truth = dir / "truth.csv";
  const CompareReport report = RunOnImages(options, "four-line-board");
  EXPECT_EQ(report.truth_source, "csv");
  EXPECT_EQ(report.methods[0].truth_lines, kFrames * 4);
  EXPECT_EQ(report.methods[0].frames_all_found, kFrames);
}

TEST(Compare, MissingTruthFileNamesIt) {
  test::TestDir dir;
  CompareOptions options;
  options.input = RenderShort(dir);
  fs::remove(fs::path(options.input) / "frame_0003.json");
  options.out_dir = dir / "out";
  const std::string error = CompareError(options);
  EXPECT_THAT(error, HasSubstr("frame_0003.json"));
  EXPECT_FALSE(fs::exists(fs::path(options.out_dir) / "compare.md"));
  EXPECT_FALSE(fs::exists(fs::path(options.out_dir) / "compare.json"));

  options.truth = dir / "nowhere.csv";
  EXPECT_THAT(CompareError(options), HasSubstr("nowhere.csv"));
}

TEST(Compare, MalformedCsvNamesFileAndLine) {
  test::TestDir dir;
  test::WriteText(dir / "bad.csv", "frame,line,rho,theta\n0,0,10.5,0.3\n1,0,abc,0.3\n");
  EXPECT_THROW(LoadTruthCsv(dir / "bad.csv"), std::runtime_error);
  try {
    LoadTruthCsv(dir / "bad.csv");
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), HasSubstr("bad.csv:3"));
    EXPECT_THAT(error.what(), HasSubstr("rho"));
  }
  test::WriteText(dir / "short.csv", "0,0,10.5\n");
  try {
    LoadTruthCsv(dir / "short.csv");
    ADD_FAILURE() << "no error for a short row";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), HasSubstr("short.csv:1"));
    EXPECT_THAT(error.what(), HasSubstr("4 comma-separated fields"));
  }

  // Through the comparison: the error names the file and no output is left behind.
  CompareOptions options;
  options.input = RenderShort(dir);
  options.truth = dir / "bad.csv";
  options.out_dir = dir / "out";
  EXPECT_THAT(CompareError(options), HasSubstr("bad.csv:3"));
  EXPECT_FALSE(fs::exists(fs::path(options.out_dir) / "compare.md"));
}

TEST(Compare, WithoutTruthOnlyTimes) {
  test::TestDir dir;
  const std::string data = RenderShort(dir);
  fs::create_directories(dir / "images");
  for (int f = 0; f < 3; ++f) {
    char name[32];
    std::snprintf(name, sizeof(name), "frame_%04d.png", f);
    fs::copy_file(fs::path(data) / name, fs::path(dir / "images") / name);
  }
  CompareOptions options;
  options.input = dir / "images";
  const CompareReport report = RunOnImages(options);
  EXPECT_EQ(report.truth_source, "none");
  EXPECT_EQ(report.frames, 3);
  EXPECT_THAT(CompareMarkdown(report), HasSubstr("| vpMeLine |"));
  EXPECT_GE(report.methods[1].lines[0].size(), 1u);  // trackers started on our detections
}

// Writes `count` images of `width`x`height` into `dir` (frame_0000.png, ...): a dark left
// half, a bright right half (one vertical edge), so the methods have something to see.
std::string WriteEdgeImages(const fs::path& dir, int count, int width, int height) {
  fs::create_directories(dir);
  for (int f = 0; f < count; ++f) {
    cv::Mat image(height, width, CV_8UC1, cv::Scalar(40));
    image.colRange(width / 2, width).setTo(cv::Scalar(200));
    char name[32];
    std::snprintf(name, sizeof(name), "frame_%04d.png", f);
    EXPECT_TRUE(cv::imwrite((dir / name).string(), image));
  }
  return dir.string();
}

TEST(Compare, CsvTruthMatchingNoFrameIsAnError) {
  test::TestDir dir;
  CompareOptions options;
  options.input = WriteEdgeImages(dir / "images", 3, 64, 48);
  options.out_dir = dir / "out";

  // No line row at all.
  test::WriteText(dir / "empty.csv", "frame,line,rho,theta\n");
  options.truth = dir / "empty.csv";
  std::string error = CompareError(options);
  EXPECT_THAT(error, HasSubstr("empty.csv"));
  EXPECT_THAT(error, HasSubstr("no line row"));

  // Rows, but for a frame the input does not have: both sets of frame numbers are named.
  test::WriteText(dir / "elsewhere.csv", "frame,line,rho,theta\n999,0,31.5,0\n");
  options.truth = dir / "elsewhere.csv";
  error = CompareError(options);
  EXPECT_THAT(error, HasSubstr("elsewhere.csv matches no frame"));
  EXPECT_THAT(error, HasSubstr("rows are for frames 999"));
  EXPECT_THAT(error, HasSubstr("the input's frames are 0-2"));
  EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(Compare, FramesWithoutCsvTruthAreWarnedAbout) {
  test::TestDir dir;
  CompareOptions options;
  options.input = WriteEdgeImages(dir / "images", 4, 64, 48);
  options.out_dir = dir / "out";
  options.target_kind = TargetKind::kEdges;
  test::WriteText(dir / "truth.csv", "frame,line,rho,theta\n0,0,31.5,0\n2,0,31.5,0\n");
  options.truth = dir / "truth.csv";
  const CompareReport report = RunOnImages(options);
  EXPECT_EQ(report.frames, 4);
  EXPECT_EQ(report.methods[0].truth_lines, 2);
  const std::string expected = "2 of 4 frames have no row in truth " + options.truth;
  EXPECT_TRUE(AnyContains(report.warnings, expected)) << ::testing::PrintToString(report.warnings);
  EXPECT_TRUE(AnyContains(report.warnings, "(frames 1, 3)"));
  const json parsed = json::parse(test::ReadText(fs::path(options.out_dir) / "compare.json"));
  EXPECT_TRUE(AnyContains(parsed.at("warnings").get<std::vector<std::string>>(), expected));
}

TEST(Compare, CsvThetaOutsideTwoPiNamesFileAndLine) {
  test::TestDir dir;
  test::WriteText(dir / "theta.csv", "frame,line,rho,theta\n0,0,10,-3.0\n1,0,10,6.0\n2,0,10,7.5\n");
  const std::string error = test::ErrorMessageOf([&] { LoadTruthCsv(dir / "theta.csv"); });
  EXPECT_THAT(error, HasSubstr("theta.csv:4"));
  EXPECT_THAT(error, HasSubstr("theta = 7.5"));
  EXPECT_THAT(error, HasSubstr("[-2 pi, 2 pi]"));
  // Within [-2 pi, 2 pi] any value is accepted and normalised to [0, pi).
  test::WriteText(dir / "ok.csv", "0,0,10,-3.0\n1,0,10,6.0\n");
  const auto truth = LoadTruthCsv(dir / "ok.csv");
  ASSERT_EQ(truth.size(), 2u);
  for (const auto& [frame, lines] : truth) {
    ASSERT_EQ(lines.size(), 1u);
    EXPECT_GE(lines[0].image_line.theta_rad, 0.0) << frame;
    EXPECT_LT(lines[0].image_line.theta_rad, kPi) << frame;
  }
  // The same through LoadTruthCsvWithPoses (oalservo evaluate's reader).
  EXPECT_THAT(test::ErrorMessageOf([&] { LoadTruthCsvWithPoses(dir / "theta.csv"); }),
              HasSubstr("theta.csv:4"));
}

TEST(Compare, TinyImagesGiveAWarningNamingFrameAndSize) {
  for (const auto& [width, height] : {std::pair{5, 5}, std::pair{640, 3}}) {
    test::TestDir dir;
    CompareOptions options;
    options.input = WriteEdgeImages(dir / "images", 2, width, height);
    options.out_dir = dir / "out";
    const std::string size = std::to_string(width) + "x" + std::to_string(height) + " px";
    CompareReport report;
    ASSERT_NO_THROW(report = RunOnImages(options)) << size;
    EXPECT_EQ(report.frames, 2);
    // Some OpenCV method cannot run on such an image: a warning, no raw assertion.
    EXPECT_TRUE(AnyContains(report.warnings, "could not run on 2 frames (first: frame 0 '"))
        << ::testing::PrintToString(report.warnings);
    EXPECT_TRUE(AnyContains(report.warnings, size)) << size;
    EXPECT_TRUE(fs::is_regular_file(fs::path(options.out_dir) / "compare.json"));
  }
}

TEST(Compare, APatternWithAGapIsWarnedAbout) {
  test::TestDir dir;
  const std::string images = WriteEdgeImages(dir / "images", 4, 64, 48);
  fs::remove(fs::path(images) / "frame_0002.png");
  CompareOptions options;
  options.input = images + "/frame_%04d.png";
  const CompareReport report = RunOnImages(options);
  EXPECT_EQ(report.frames, 2);
  EXPECT_TRUE(AnyContains(report.warnings, "the sequence ends at the missing file"))
      << ::testing::PrintToString(report.warnings);
}

TEST(Compare, CameraForAnotherImageSizeIsWarnedAbout) {
  test::TestDir dir;
  Lens camera = Lens::Pinhole(600.0, 600.0, 319.5, 239.5);
  SaveCameraFile(dir / "camera.xml", camera, "cam", 640, 480);
  CompareOptions options;
  options.input = WriteEdgeImages(dir / "images", 2, 64, 48);
  options.camera_path = dir / "camera.xml";
  const CompareReport report = RunOnImages(options);
  EXPECT_TRUE(AnyContains(report.warnings, "calibrated for 640x480"))
      << ::testing::PrintToString(report.warnings);
  EXPECT_TRUE(AnyContains(report.warnings, "is 64x48"));

  // The right size: no such warning.
  SaveCameraFile(dir / "camera.xml", camera, "cam", 64, 48);
  EXPECT_FALSE(AnyContains(RunOnImages(options).warnings, "calibrated for"));
}

}  // namespace
}  // namespace oal
