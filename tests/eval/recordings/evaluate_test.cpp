#include "eval/recordings/evaluate.h"

#include <fcntl.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>
#include <visp3/core/vpDebug.h>
#include <visp3/core/vpThetaUVector.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "eval/recordings/report.h"
#include "io/camera_file.h"
#include "io/quiet_stderr.h"
#include "io/truth_file.h"
#include "tests/eval/rendered_data_set.h"
#include "tests/test_util.h"

namespace oal {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using ::testing::HasSubstr;
using ::testing::Not;

constexpr int kFrames = 8;
constexpr double kRhoShiftPx = 1.5;  // the truth CSV's lines are this far off
constexpr double kShiftTxM = 0.010;  // and its poses this far along x
constexpr double kOffsetTolerancePx = 0.35;
constexpr double kTranslationToleranceMm = 4.0;

std::string FrameName(int index, const char* extension) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%04d%s", index, extension);
  return name;
}

// `count` rendered 320x240 frames of the four-line target, with truth JSON and camera.xml.
std::string RenderFrames(const test::TestDir& dir, const std::string& name, int count,
                         std::uint64_t seed = 11) {
  test::RandomDataSet render;
  render.count = count;
  render.seed = seed;
  render.width = 320;
  render.height = 240;
  render.noise_sigma = 2.0;
  render.min_visible_px = 60.0;
  return test::WriteDataSet(render, dir / name);
}

// The rendered frames of `frames_dir` as an MJPG AVI (OpenCV's own encoder).
void WriteVideo(const std::string& frames_dir, int count, const std::string& path) {
  cv::VideoWriter writer(path, cv::CAP_OPENCV_MJPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'),
                         25.0, cv::Size(320, 240), true);  // its grey mode fails (OpenCV 4.6)
  ASSERT_TRUE(writer.isOpened()) << path;
  for (int i = 0; i < count; ++i) {
    writer.write(cv::imread(frames_dir + "/" + FrameName(i, ".png"), cv::IMREAD_COLOR));
  }
}

// A truth CSV from the renderer's JSON, every line kRhoShiftPx off and every pose kShiftTxM
// off: the errors the evaluation must report.
void WriteShiftedTruthCsv(const std::string& frames_dir, int count, const std::string& path) {
  std::ofstream out(path);
  out << "frame,line,rho,theta\n# poses: frame,pose,tx,ty,tz,tux,tuy,tuz\n";
  out.precision(12);
  for (int i = 0; i < count; ++i) {
    const json truth = json::parse(test::ReadText(frames_dir + "/" + FrameName(i, ".json")));
    for (const json& line : truth.at("lines")) {
      if (!line.at("visible").get<bool>()) continue;
      out << i << "," << line.at("index") << ","
          << line.at("distorted_fit").at("rho").get<double>() + kRhoShiftPx << ","
          << line.at("distorted_fit").at("theta").get<double>() << "\n";
    }
    const std::vector<double> t = truth.at("cMo").at("t_m");
    const std::vector<double> tu = truth.at("cMo").at("thetau_rad");
    out << i << ",pose," << t[0] + kShiftTxM << "," << t[1] << "," << t[2] << "," << tu[0] << ","
        << tu[1] << "," << tu[2] << "\n";
  }
}

// A directory with one video (and the renderer's camera.xml next to it).
std::string VideoDir(const test::TestDir& dir, const std::string& frames_dir,
                     const std::string& name, const std::vector<std::string>& videos) {
  const fs::path videos_dir = dir / name;
  fs::create_directories(videos_dir);
  for (const char* companion : {"camera.xml"}) {
    fs::copy_file(frames_dir + "/" + companion, videos_dir / companion,
                  fs::copy_options::overwrite_existing);
  }
  for (const std::string& video : videos)
    WriteVideo(frames_dir, kFrames, (videos_dir / video).string());
  return videos_dir.string();
}

json ReadJson(const fs::path& path) {
  return json::parse(test::ReadText(path));
}

// Evaluating `inputs` into `out`, our detector tracking `target`'s lines ("": no target known).
EvaluateOptions Options(const std::vector<std::string>& inputs, const std::string& out,
                        const std::string& target = "four-line-board") {
  EvaluateOptions options;
  options.inputs = inputs;
  options.out_dir = out;
  options.thumbnails = 3;
  options.setup = target.empty() ? TrackerSetup() : test::SetupFor(target);
  return options;
}

// Every file below `dir`, relative path -> bytes; the timing files left out and the reports'
// timing block removed (timings differ from run to run: evaluate.h).
std::map<std::string, std::string> DeterministicFiles(const fs::path& dir) {
  std::map<std::string, std::string> files;
  const std::regex timing_block(
      R"(<script type="application/json" id="oal-timing">[^<]*</script>)");
  for (const auto& entry : fs::recursive_directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    const std::string name = entry.path().filename().string();
    if (name == "timing.json" || name == "timing.jsonl") continue;
    std::string bytes = test::ReadText(entry.path());
    if (entry.path().extension() == ".html") bytes = std::regex_replace(bytes, timing_block, "");
    files[fs::relative(entry.path(), dir).string()] = std::move(bytes);
  }
  return files;
}

TEST(Evaluate, ParsesShardsAndPlansNamesThatDoNotCollide) {
  EXPECT_EQ(ParseShard("1/4"), std::make_pair(1, 4));
  EXPECT_THROW(ParseShard("4/4"), std::invalid_argument);
  EXPECT_THROW(ParseShard("1"), std::invalid_argument);
  EXPECT_THROW(ParseShard("a/2"), std::invalid_argument);
  test::TestDir dir;
  fs::create_directories(dir / "a");
  fs::create_directories(dir / "b/a");
  test::WriteText(dir / "a/clip.avi", "x");
  test::WriteText(dir / "a/clip.mp4", "x");
  test::WriteText(dir / "a/notes.txt", "x");
  test::WriteText(dir / "a/camera.xml", "x");  // companions: not listed as skipped
  test::WriteText(dir / "a/clip.truth.csv", "x");
  test::WriteText(dir / "b/a/f.png", "x");
  fs::create_directories(dir / "c");
  const InputPlan plan = PlanInputs({dir / "a", dir / "b", dir / "c"});
  ASSERT_EQ(plan.inputs.size(), 3u);
  EXPECT_EQ(plan.inputs[0].name, "clip");
  EXPECT_EQ(plan.inputs[1].name, "clip-2");
  EXPECT_EQ(plan.inputs[2].name, "a");
  ASSERT_EQ(plan.skipped.size(), 2u);
  EXPECT_THAT(plan.skipped[0], HasSubstr("notes.txt"));
  EXPECT_EQ(plan.skipped[1], dir / "c" + ": holds no video and no directory of images");
}

TEST(Evaluate, NoInputFoundIsAnErrorAndWritesNothing) {
  test::TestDir dir;
  fs::create_directories(dir / "empty");
  EvaluateOptions options = Options({dir / "empty"}, dir / "out");
  EXPECT_THAT([&] { Evaluate(options); }, ::testing::ThrowsMessage<std::runtime_error>(HasSubstr(
                                              "no inputs found in '" + dir / "empty" + "'")));
  EXPECT_FALSE(fs::exists(dir / "out"));
  test::WriteText(dir / "empty/notes.txt", "x");
  EXPECT_THAT([&] { Evaluate(options); },
              ::testing::ThrowsMessage<std::runtime_error>(HasSubstr("notes.txt: not a video")));
  EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(Evaluate, VideoWithTruthCsvReportsTheKnownErrors) {
  test::TestDir dir;
  const std::string frames = RenderFrames(dir, "frames", kFrames);
  const std::string videos = VideoDir(dir, frames, "videos", {"clip.avi"});
  WriteShiftedTruthCsv(frames, kFrames, videos + "/clip.truth.csv");
  const EvaluateResult result = Evaluate(Options({videos + "/clip.avi"}, dir / "out"));
  ASSERT_EQ(result.inputs.size(), 1u);
  ASSERT_EQ(result.inputs[0].status, "complete") << result.inputs[0].error;
  const json summary = ReadJson(dir / "out/clip/summary.json");
  EXPECT_EQ(summary.at("frames"), kFrames);
  EXPECT_EQ(summary.at("frames_unreadable"), 0);
  EXPECT_EQ(summary.at("truth").at("kind"), "csv");
  const json& truth = summary.at("truth");
  EXPECT_GE(truth.at("found_lines").get<int>(), truth.at("truth_lines").get<int>() * 9 / 10);
  EXPECT_NEAR(truth.at("offset_px").at("mean").get<double>(), kRhoShiftPx, kOffsetTolerancePx);
  ASSERT_GE(summary.at("pose").at("frames_ok").get<int>(), kFrames / 2);
  EXPECT_NEAR(truth.at("pose_translation_mm").at("mean").get<double>(), 1000.0 * kShiftTxM,
              kTranslationToleranceMm);
  // One JSON object per frame, and the annotated video holds every frame, at half size
  // (the default video_scale) in XVID.
  const auto records = test::ParseJsonLines(test::ReadText(dir / "out/clip/frames.jsonl"));
  ASSERT_EQ(records.size(), static_cast<std::size_t>(kFrames));
  EXPECT_EQ(records[0].at("truth").at("lines").size(), 4u);
  // Independent random poses: a pose may turn by more than 90 degrees from the previous one,
  // and is then flagged as a jump.
  int jumps = 0;
  for (const json& record : records) {
    const json& pose = record.at("pose");
    if (pose.at("status") != "ok") continue;
    EXPECT_TRUE(pose.at("identification").at("cost").is_number());
    if (pose.at("jump").is_null()) continue;
    ++jumps;
    EXPECT_LT(pose.at("jump").at("from_frame").get<int>(), record.at("frame").get<int>());
    EXPECT_TRUE(pose.at("jump").at("relabelled").get<bool>() ||
                pose.at("jump").at("rotation_deg").get<double>() > 90.0);
  }
  EXPECT_EQ(summary.at("pose").at("jumps"), jumps);
  cv::VideoCapture annotated(dir / "out/clip/annotated.avi");
  EXPECT_EQ(static_cast<int>(annotated.get(cv::CAP_PROP_FRAME_COUNT)), kFrames);
  EXPECT_EQ(annotated.get(cv::CAP_PROP_FRAME_WIDTH), 160.0);
  EXPECT_EQ(annotated.get(cv::CAP_PROP_FRAME_HEIGHT), 120.0);
  EXPECT_EQ(static_cast<int>(annotated.get(cv::CAP_PROP_FOURCC)),
            cv::VideoWriter::fourcc('X', 'V', 'I', 'D'));
  EXPECT_TRUE(test::TempFilesIn(dir / "out").empty());
}

// The JSON a report page embeds under `id`.
json ReportBlock(const std::string& html, const std::string& id) {
  const std::string open = "id=\"" + id + "\">";
  const std::size_t from = html.find(open);
  if (from == std::string::npos) return json();
  const std::size_t begin = from + open.size();
  return json::parse(html.substr(begin, html.find("</script>", begin) - begin));
}

// A long input costs bounded memory: its plots keep plot_frames to twice as many of its
// frames, evenly spread, and its statistics still count every frame.
TEST(Evaluate, ALongInputsPlotsKeepABoundedNumberOfFrames) {
  test::TestDir dir;
  // Small frames: the test is about the frames' count, not their content.
  test::RandomDataSet render;
  render.count = kFrames;
  render.seed = 5;
  render.width = 160;
  render.height = 120;
  render.min_visible_px = 30.0;
  const std::string frames = test::WriteDataSet(render, dir / "frames");
  const fs::path videos = dir / "long";
  fs::create_directories(videos);
  fs::copy_file(frames + "/camera.xml", videos / "camera.xml");
  constexpr int kPlotFrames = 64;
  constexpr int kLong = 2 * kPlotFrames + 10;  // the plots' frames were halved once
  {
    cv::VideoWriter writer((videos / "loop.avi").string(), cv::CAP_OPENCV_MJPEG,
                           cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 25.0, cv::Size(160, 120),
                           true);
    ASSERT_TRUE(writer.isOpened());
    std::vector<cv::Mat> images;
    for (int i = 0; i < kFrames; ++i) {
      images.push_back(cv::imread(frames + "/" + FrameName(i, ".png"), cv::IMREAD_COLOR));
    }
    for (int i = 0; i < kLong; ++i) writer.write(images[static_cast<std::size_t>(i % kFrames)]);
  }
  EvaluateOptions options = Options({(videos / "loop.avi").string()}, dir / "out");
  options.write_video = false;
  options.plot_frames = kPlotFrames;
  ASSERT_EQ(Evaluate(options).inputs.at(0).status, "complete");
  const json timing = ReadJson(dir / "out/loop/timing.json");
  EXPECT_EQ(timing.at("track_us").at("count"), kLong);
  EXPECT_LE(timing.at("track_us").at("median").get<double>(),
            timing.at("track_us").at("p95").get<double>());
  EXPECT_LE(timing.at("track_us").at("p95").get<double>(),
            timing.at("track_us").at("max").get<double>());
  const std::string html = test::ReadText(dir / "out/loop/report.html");
  const json series = ReportBlock(html, "oal-data").at("series");
  const json& plotted = series.at("frame");
  ASSERT_GE(plotted.size(), static_cast<std::size_t>(kPlotFrames));
  ASSERT_LT(plotted.size(), static_cast<std::size_t>(2 * kPlotFrames));
  EXPECT_EQ(plotted.front(), 0);
  for (std::size_t i = 1; i < plotted.size(); ++i) {
    ASSERT_EQ(plotted[i].get<int>() - plotted[i - 1].get<int>(), 2) << i;  // every other
  }
  for (const char* column : {"status", "held", "pose_ok"}) {
    EXPECT_EQ(series.at(column).size(), plotted.size()) << column;
  }
  for (const auto& [id, values] : series.at("rho").items()) {
    EXPECT_EQ(values.size(), plotted.size()) << "track " << id;
  }
  const json timing_series = ReportBlock(html, "oal-timing").at("series");
  EXPECT_EQ(timing_series.at("track_us").size(), plotted.size());
}

TEST(Evaluate, SmoothSequenceHasNoPoseJump) {
  test::TestDir dir;
  const std::string frames = test::WriteSequence("slow", 12, 3, dir / "slow");
  EvaluateOptions options = Options({frames}, dir / "out");
  options.write_video = false;
  ASSERT_EQ(Evaluate(options).inputs.at(0).status, "complete");
  const json pose = ReadJson(dir / "out/slow/summary.json").at("pose");
  EXPECT_GE(pose.at("frames_ok").get<int>(), 10);
  EXPECT_EQ(pose.at("jumps"), 0);
  EXPECT_TRUE(pose.at("jump_frames").empty());
  // The renderer's camera.xml, sequence.json and frame JSON are no "skipped" files.
  const json warnings = ReadJson(dir / "out/slow/summary.json").at("warnings");
  EXPECT_THAT(warnings.dump(), ::testing::Not(HasSubstr("skipped"))) << warnings;
}

TEST(Evaluate, FullSizeMjpgVideoOnRequest) {
  test::TestDir dir;
  const std::string frames = RenderFrames(dir, "frames", 3);
  EvaluateOptions options = Options({frames}, dir / "out");
  options.video_scale = 1.0;
  options.video_codec = "mjpg";
  ASSERT_EQ(Evaluate(options).inputs.at(0).status, "complete");
  cv::VideoCapture annotated(dir / "out/frames/annotated.avi");
  EXPECT_EQ(static_cast<int>(annotated.get(cv::CAP_PROP_FRAME_COUNT)), 3);
  EXPECT_EQ(annotated.get(cv::CAP_PROP_FRAME_WIDTH), 320.0);
  EXPECT_EQ(annotated.get(cv::CAP_PROP_FRAME_HEIGHT), 240.0);
  EXPECT_EQ(static_cast<int>(annotated.get(cv::CAP_PROP_FOURCC)),
            cv::VideoWriter::fourcc('M', 'J', 'P', 'G'));
  options.video_codec = "h264";
  EXPECT_THROW(Evaluate(options), std::invalid_argument);
}

TEST(Evaluate, RenderedJsonTruthNextToTheImagesGivesSmallErrors) {
  test::TestDir dir;
  const std::string frames = RenderFrames(dir, "frames", kFrames);
  EvaluateOptions options = Options({frames}, dir / "out");
  options.write_video = false;
  const EvaluateResult result = Evaluate(options);
  ASSERT_EQ(result.inputs.at(0).status, "complete") << result.inputs[0].error;
  const json summary = ReadJson(dir / "out/frames/summary.json");
  const json& truth = summary.at("truth");
  EXPECT_EQ(truth.at("kind"), "json");
  EXPECT_LT(truth.at("offset_px").at("mean").get<double>(), 0.5);
  EXPECT_LT(truth.at("pose_translation_mm").at("mean").get<double>(), 10.0);
  EXPECT_FALSE(fs::exists(dir / "out/frames/annotated.avi"));
}

TEST(Evaluate, TruncatedVideoAndNonVideoFilesAreListedNotFatal) {
  test::TestDir dir;
  const std::string frames = RenderFrames(dir, "frames", kFrames);
  const std::string videos = VideoDir(dir, frames, "videos", {"good.avi", "whole.avi"});
  // truncated.avi: the first 60 % of a good video.
  const std::string bytes = test::ReadText(videos + "/whole.avi");
  test::WriteText(videos + "/truncated.avi", bytes.substr(0, bytes.size() * 6 / 10));
  fs::remove(videos + "/whole.avi");
  test::WriteText(videos + "/garbage.avi", "not a video at all");
  test::WriteText(videos + "/notes.txt", "recorded on Monday");
  EvaluateOptions options = Options({videos}, dir / "out");
  options.write_video = false;
  const EvaluateResult result = Evaluate(options);
  ASSERT_EQ(result.inputs.size(), 3u);  // garbage, good, truncated (notes skipped)
  EXPECT_EQ(result.inputs[0].name, "garbage");
  EXPECT_EQ(result.inputs[0].status, "failed");
  EXPECT_THAT(result.inputs[0].error, HasSubstr("garbage.avi"));
  EXPECT_EQ(result.inputs[1].status, "complete");
  EXPECT_EQ(result.inputs[1].summary.at("frames"), kFrames);
  ASSERT_EQ(result.inputs[2].status, "complete") << result.inputs[2].error;
  const json& truncated = result.inputs[2].summary;
  EXPECT_LT(truncated.at("frames_readable").get<int>(), kFrames);
  EXPECT_GT(truncated.at("frames_unreadable").get<int>(), 0);
  EXPECT_THAT(truncated.at("warnings").dump(), HasSubstr("truncated"));
  ASSERT_EQ(result.skipped.size(), 1u);  // not camera.xml, a known companion file
  EXPECT_THAT(result.skipped[0], HasSubstr("notes.txt"));
  // The index lists the failure and the skipped files; the truncated report its frames.
  const std::string index = test::ReadText(dir / "out/index.html");
  EXPECT_THAT(index, HasSubstr("garbage.avi"));
  EXPECT_THAT(index, HasSubstr("notes.txt"));
  EXPECT_THAT(test::ReadText(dir / "out/truncated/report.html"), HasSubstr("announces"));
}

// ViSP's line/ sequence shows one edge, not the dark stripes the default detector looks for:
// the summary (and the console) says what was looked for and what to try.
TEST(Evaluate, NearlyNothingDetectedSaysWhatToTry) {
  const std::string pattern = "/usr/share/visp-images-data/ViSP-images/line/image.%04d.pgm";
  if (!fs::exists("/usr/share/visp-images-data/ViSP-images/line/image.0001.pgm")) {
    GTEST_SKIP() << "Debian's visp-images-data is not installed";
  }
  test::TestDir dir;
  EvaluateOptions options = Options({pattern}, dir / "out", "");
  options.write_video = false;
  options.max_frames = 5;
  const EvaluateResult result = Evaluate(options);
  ASSERT_EQ(result.inputs.size(), 1u);
  ASSERT_EQ(result.inputs[0].status, "complete") << result.inputs[0].error;
  const std::string warnings = result.inputs[0].summary.at("warnings").dump();
  EXPECT_THAT(warnings, HasSubstr("found in only 0 of 5 frames"));
  EXPECT_THAT(warnings, HasSubstr("looked for dark stripes"));
  EXPECT_THAT(warnings, HasSubstr("config/visp_line_edges.yaml"));
}

// A printed sheet among clutter: the pose comes from the target tracker, in every frame, where
// the line tracker's tracks alone give it in about half of them.
TEST(Evaluate, ASheetsPoseComesFromTheTargetTracker) {
  const std::string bench = "/usr/share/visp-images-data/ViSP-images/Klimt/Klimt.pgm";
  if (!fs::exists(bench)) GTEST_SKIP() << "Debian's visp-images-data is not installed";
  test::TestDir dir;
  const std::string frames =
      test::WriteSequence("slow", 8, 1, dir / "sheet", "four-line-a3", bench);
  EvaluateOptions options = Options({frames}, dir / "out", "four-line-a3");
  options.camera_path = frames + "/camera.xml";
  options.write_video = false;
  const EvaluateResult result = Evaluate(options);
  ASSERT_EQ(result.inputs.size(), 1u);
  ASSERT_EQ(result.inputs[0].status, "complete") << result.inputs[0].error;
  const json& summary = result.inputs[0].summary;
  EXPECT_EQ(summary.at("pose").at("frames_ok"), 8) << summary.dump(2);
  EXPECT_LT(summary.at("truth").at("pose_translation_mm").at("max").get<double>(), 2.0);
}

// The lens check: a camera file without the lens's distortion leaves the sheet's stripes
// bent; the summary says so once, with the kdu error the stripes show and the median bend,
// the frames give theirs.
TEST(Evaluate, ACameraFileThatMissesTheLensIsSaid) {
  test::TestDir dir;
  test::RandomDataSet render;
  render.seed = 3;
  render.target = "four-line-a3";
  render.kdu = 0.2;
  const std::string frames = test::WriteDataSet(render, dir / "sheet");
  const double fx = 600.0;
  const Lens pinhole = Lens::Pinhole(fx, fx, 0.5 * (render.width - 1), 0.5 * (render.height - 1));
  SaveCameraFile(dir / "pinhole.xml", pinhole, "Camera", render.width, render.height);
  for (const bool right : {true, false}) {
    EvaluateOptions options = Options({frames}, dir / (right ? "right" : "wrong"), "four-line-a3");
    options.camera_path = right ? frames + "/camera.xml" : dir / "pinhole.xml";
    options.write_video = false;
    const EvaluateResult result = Evaluate(options);
    ASSERT_EQ(result.inputs.size(), 1u);
    ASSERT_EQ(result.inputs[0].status, "complete") << result.inputs[0].error;
    const json& summary = result.inputs[0].summary;
    const double median = summary.at("pose").at("straightness_px_median").get<double>();
    const std::string warnings = summary.at("warnings").dump();
    if (right) {
      EXPECT_LT(median, 0.2);
      EXPECT_THAT(warnings, Not(HasSubstr("still bend")));
    } else {
      EXPECT_GT(median, 0.2);
      EXPECT_THAT(warnings, HasSubstr("lines 1-4 still bend"));
      EXPECT_THAT(warnings, HasSubstr("as if the lens's kdu were the camera's +0."));
      EXPECT_THAT(warnings, HasSubstr("pinhole.xml"));
    }
  }
}

TEST(Evaluate, UndecodableImageIsSkippedCountedAndListed) {
  test::TestDir dir;
  const std::string frames = RenderFrames(dir, "frames", 4);
  const std::string png2 = frames + "/" + FrameName(2, ".png");
  test::WriteText(png2, "\x89PNG truncated");
  // Frame 1 as the first half of a JPEG: libjpeg alone would decode it with a warning.
  const std::string png1 = frames + "/" + FrameName(1, ".png"), jpg1 = frames + "/frame_0001.jpg";
  ASSERT_TRUE(cv::imwrite(jpg1, cv::imread(png1)));
  const std::string jpeg = test::ReadText(jpg1);
  test::WriteText(jpg1, jpeg.substr(0, jpeg.size() / 2));
  fs::remove(png1);
  EvaluateOptions options = Options({frames}, dir / "out");
  options.write_video = false;
  const EvaluateResult result = Evaluate(options);
  ASSERT_EQ(result.inputs.at(0).status, "complete") << result.inputs[0].error;
  const json& summary = result.inputs[0].summary;
  EXPECT_EQ(summary.at("frames"), 4);
  EXPECT_EQ(summary.at("frames_unreadable"), 2);
  EXPECT_EQ(summary.at("unreadable").at(0).at("frame"), 1);
  EXPECT_EQ(summary.at("unreadable").at(0).at("source"), jpg1);
  EXPECT_EQ(summary.at("unreadable").at(1).at("frame"), 2);
  EXPECT_EQ(summary.at("unreadable").at(1).at("source"), png2);
  const auto records = test::ParseJsonLines(test::ReadText(dir / "out/frames/frames.jsonl"));
  ASSERT_EQ(records.size(), 4u);
  EXPECT_EQ(records[1].at("status"), "unreadable");
  EXPECT_EQ(records[1].at("source"), jpg1);  // the file, as for a readable frame
  EXPECT_THAT(records[1].at("error").get<std::string>(), HasSubstr("truncated JPEG"));
  EXPECT_EQ(records[2].at("status"), "unreadable");
  EXPECT_EQ(records[2].at("source"), png2);
  EXPECT_EQ(records[3].at("status"), "pose");
  EXPECT_EQ(records[3].at("source"), frames + "/" + FrameName(3, ".png"));
  EXPECT_THAT(test::ReadText(dir / "out/frames/report.html"), HasSubstr("cannot decode image"));
}

TEST(Evaluate, ResumeSkipsCompletedInputsAndRedoesInterruptedOnes) {
  test::TestDir dir;
  const std::string a = RenderFrames(dir, "a", 4, 3);
  const std::string b = RenderFrames(dir, "b", 4, 5);
  EvaluateOptions options = Options({a, b}, dir / "out");
  options.write_video = false;
  ASSERT_EQ(Evaluate(options).inputs.at(1).status, "complete");
  const std::string b_frames = test::ReadText(dir / "out/b/frames.jsonl");
  const auto a_time = fs::last_write_time(dir / "out/a/summary.json");
  // An interrupted run: b has no summary, a temporary file of a killed process, and an
  // older frames.jsonl.
  fs::remove(dir / "out/b/summary.json");
  test::WriteText(dir / "out/b/frames.jsonl.tmp-999999", "{\"frame\":0");
  test::WriteText(dir / "out/b/frames.jsonl", "stale\n");
  options.resume = true;
  const EvaluateResult resumed = Evaluate(options);
  EXPECT_EQ(resumed.inputs.at(0).status, "resumed");
  EXPECT_EQ(resumed.inputs.at(1).status, "complete");
  EXPECT_EQ(resumed.frames, 4);
  EXPECT_EQ(fs::last_write_time(dir / "out/a/summary.json"), a_time);
  EXPECT_EQ(test::ReadText(dir / "out/b/frames.jsonl"), b_frames);
  EXPECT_TRUE(fs::exists(dir / "out/b/summary.json"));
  EXPECT_TRUE(test::TempFilesIn(dir / "out").empty());
  EXPECT_THAT(test::ReadText(dir / "out/index.html"), HasSubstr("a/report.html"));
}

TEST(Evaluate, TwoJobsWriteWhatOneJobWrites) {
  test::TestDir dir;
  const std::string frames = RenderFrames(dir, "frames", kFrames);
  const std::string videos = VideoDir(dir, frames, "videos", {"v1.avi", "v2.avi"});
  const std::string other = RenderFrames(dir, "other", 4, 7);
  EvaluateOptions options = Options({videos, other}, dir / "serial");
  Evaluate(options);
  options.out_dir = dir / "parallel";
  options.jobs = 2;
  Evaluate(options);
  const auto serial = DeterministicFiles(dir / "serial");
  const auto parallel = DeterministicFiles(dir / "parallel");
  ASSERT_EQ(serial.size(), parallel.size());
  EXPECT_TRUE(serial.count("v1/annotated.avi"));
  for (const auto& [name, bytes] : serial) {
    ASSERT_TRUE(parallel.count(name)) << name;
    EXPECT_TRUE(parallel.at(name) == bytes) << name << " differs";
  }
}

TEST(Evaluate, ShardTakesEveryNthInputAndNamesItsIndex) {
  test::TestDir dir;
  const std::string a = RenderFrames(dir, "a", 2, 3);
  const std::string b = RenderFrames(dir, "b", 2, 5);
  const std::string c = RenderFrames(dir, "c", 2, 7);
  EvaluateOptions options = Options({a, b, c}, dir / "out");
  options.write_video = false;
  options.shard_index = 1;
  options.shard_count = 2;
  const EvaluateResult result = Evaluate(options);
  ASSERT_EQ(result.inputs.size(), 1u);
  EXPECT_EQ(result.inputs[0].name, "b");
  EXPECT_TRUE(fs::exists(dir / "out/index-1-of-2.html"));
  EXPECT_FALSE(fs::exists(dir / "out/a"));
  // Gathering: a run over everything with --resume evaluates only what is missing.
  options.shard_count = 1;
  options.shard_index = 0;
  options.resume = true;
  const EvaluateResult all = Evaluate(options);
  EXPECT_EQ(all.frames, 4);
  EXPECT_EQ(all.inputs[1].status, "resumed");
}

// The report of a rendered input: written, `dir` / out.
std::string EvaluateRendered(const test::TestDir& dir) {
  const std::string frames = RenderFrames(dir, "frames", kFrames);
  EvaluateOptions options = Options({frames}, dir / "out");
  options.write_video = false;
  EXPECT_EQ(Evaluate(options).inputs.at(0).status, "complete");
  return dir / "out";
}

TEST(EvaluateReport, IsOneSelfContainedPageWithPlotsAndThumbnails) {
  test::TestDir dir;
  const std::string out = EvaluateRendered(dir);
  const std::string html = test::ReadText(out + "/frames/report.html");
  EXPECT_THAT(html, HasSubstr("Chart.js v"));  // inlined, not linked
  EXPECT_THAT(html, ::testing::Not(HasSubstr("src=\"http")));
  EXPECT_THAT(html, ::testing::Not(HasSubstr("<link")));
  for (const char* id : {"chart-status", "chart-rho", "chart-theta", "chart-line-errors",
                         "chart-pose-errors", "chart-timing"}) {
    EXPECT_THAT(html, HasSubstr(std::string("id=\"") + id + "\"")) << id;
  }
  EXPECT_THAT(html, HasSubstr("id=\"oal-data\""));
  EXPECT_THAT(html, HasSubstr("id=\"oal-timing\""));
  EXPECT_THAT(html, HasSubstr("data:image/jpeg;base64,/9j/"));  // a JPEG thumbnail
  // Why fewer thumbnails than were asked for can show, said where they are.
  EXPECT_THAT(html,
              HasSubstr("as many as the evaluation was asked to show, at least 10 frames apart"));
  // A rendered data set's truth lines are named as the target's lines 1-4.
  EXPECT_THAT(html, HasSubstr("'target line '"));
  const std::string index = test::ReadText(out + "/index.html");
  EXPECT_THAT(index, HasSubstr("frames/report.html"));
  EXPECT_THAT(index, HasSubstr("time (s) / over decoding alone"));
}

// Runs Debian's chromium headless on `page`; returns the dumped DOM, `log` gets stderr.
std::string DumpDom(const test::TestDir& dir, const std::string& page, std::string* log) {
  const std::string dom = dir / "dom.html", err = dir / "chromium.log";
  const std::string command =
      "chromium --headless=new --no-sandbox --disable-gpu --no-first-run "
      "--user-data-dir='" +
      (dir / "profile") +
      "' --enable-logging=stderr --v=0 "
      "--virtual-time-budget=5000 --dump-dom 'file://" +
      page + "' > '" + dom + "' 2> '" + err + "'";
  const int status = std::system(command.c_str());
  *log = test::ReadText(err);
  EXPECT_EQ(status, 0) << command << "\n" << *log;
  return test::ReadText(dom);
}

TEST(EvaluateReport, LoadsInHeadlessChromiumWithEveryPlotDrawn) {
  if (std::system("command -v chromium > /dev/null 2>&1") != 0) {
    GTEST_SKIP() << "chromium is missing: the report's browser test needs Debian's chromium "
                    "(scripts/install-deps.sh installs it)";
  }
  test::TestDir dir;
  const std::string out = EvaluateRendered(dir);
  const std::regex canvas(R"(<canvas class="oal-chart" id="[^"]+"([^>]*)>)");
  for (const std::string& page : {out + "/frames/report.html", out + "/index.html"}) {
    std::string log;
    const std::string dom = DumpDom(dir, fs::absolute(page).string(), &log);
    int canvases = 0, drawn = 0;
    for (auto it = std::sregex_iterator(dom.begin(), dom.end(), canvas);
         it != std::sregex_iterator(); ++it) {
      ++canvases;
      drawn += (*it)[1].str().find("data-drawn=\"1\"") != std::string::npos;
    }
    EXPECT_GE(canvases, 1) << page;
    EXPECT_EQ(drawn, canvases) << page << ": not every plot was drawn";
    EXPECT_THAT(dom, HasSubstr("data-charts=\"" + std::to_string(canvases) + "\"")) << page;
    EXPECT_THAT(log, ::testing::Not(HasSubstr("Uncaught"))) << page << "\n" << log;
    EXPECT_THAT(log, ::testing::Not(::testing::ContainsRegex("CONSOLE.*[Ee]rror"))) << log;
  }
}

}  // namespace
}  // namespace oal
