// `oalservo calibrate` as a user runs it: a directory of chessboard photographs in, a ViSP
// camera file out, or a clear error and nothing written.
#include "app/calibrate_command.h"

#include <gtest/gtest.h>
#include <visp3/io/vpImageIo.h>

#include <filesystem>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <string>

#include "app/evaluation_config.h"
#include "io/camera_file.h"
#include "scene/bench_scene.h"
#include "tests/app/command_test_util.h"
#include "tests/calibration/chessboard_views.h"
#include "tests/test_util.h"

namespace oal {
namespace {

using test::OalservoRun;
using test::RunOalservo;
using test::TestDir;

// Twelve chessboard views through `camera` as PGM files in dir/shots.
std::string WriteShots(const TestDir& dir, const Lens& camera) {
  const std::string shots = dir / "shots";
  std::filesystem::create_directories(shots);
  const std::vector<vpHomogeneousMatrix> poses = test::VariedPoses();
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const std::string name = "view" + std::string(k < 10 ? "0" : "") + std::to_string(k) + ".pgm";
    vpImageIo::write(test::RenderChessboard(camera, poses[k], 7 + k), shots + "/" + name);
  }
  return shots;
}

TEST(CalibrateCommand, WritesACameraFileThatTheOtherCommandsRead) {
  const TestDir dir;
  const Lens truth = Lens::WithKdu(700.0, 702.0, 326.0, 235.0, 0.25, 640, 480);
  const std::string shots = WriteShots(dir, truth);
  const OalservoRun run =
      RunOalservo(dir, "calibrate '" + shots + "' --chessboard 9x6 --square 0.02 --out '" +
                           (dir / "cam/camera.xml") + "' --name Bench");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("view00.pgm: 54 corners, RMS"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("reprojection RMS"), std::string::npos) << run.out;
  const CameraFile file = LoadCameraFile(dir / "cam/camera.xml", "Bench");
  EXPECT_NEAR(file.camera.px(), 700.0, 0.003 * 700.0);
  EXPECT_NEAR(file.camera.u0(), 326.0, 1.5);
  EXPECT_NEAR(file.camera.kdu(), 0.25, 0.03 * 0.25);
  EXPECT_EQ(file.width, 640u);
  EXPECT_EQ(file.height, 480u);
  // ViSP's XML holds one term: the command says so, and how far it misses.
  EXPECT_NE(run.err.find("ViSP's camera XML holds one radial term each way: its kud, kdu is the "
                         "best approximation of the plumb_bob lens"),
            std::string::npos)
      << run.err;
  EXPECT_NE(run.out.find("plumb_bob: k1 "), std::string::npos) << run.out;
}

// The full model goes to OpenCV's YAML and ROS's camera_info, with each term's deviation.
TEST(CalibrateCommand, WritesTheFullModelToOpenCvAndRosFiles) {
  const TestDir dir;
  const Lens truth = Lens::WithKdu(700.0, 702.0, 326.0, 235.0, 0.25, 640, 480);
  const std::string shots = WriteShots(dir, truth);
  const std::string base = "calibrate '" + shots + "' --chessboard 9x6 --square 0.02 --out '";
  const OalservoRun run = RunOalservo(dir, base + (dir / "camera.yaml") + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.err.find("approximation"), std::string::npos) << run.err;
  const CameraFile file = LoadCameraFile(dir / "camera.yaml");
  EXPECT_EQ(file.format, CameraFileFormat::kOpenCvYaml);
  EXPECT_EQ(file.camera.model(), Lens::Model::kOpenCV);
  EXPECT_NEAR(file.camera.px(), 700.0, 0.003 * 700.0);
  const std::string text = test::ReadText(dir / "camera.yaml");
  EXPECT_NE(text.find("# standard deviations: px "), std::string::npos) << text;
  EXPECT_NE(text.find("; k1 "), std::string::npos) << text;
  EXPECT_NE(text.find("# reprojection RMS "), std::string::npos) << text;
  const OalservoRun ros = RunOalservo(dir, base + (dir / "head.yaml") + "' --ros --name head");
  ASSERT_EQ(ros.exit_code, 0) << ros.err;
  const CameraFile ros_file = LoadCameraFile(dir / "head.yaml", "head");
  EXPECT_EQ(ros_file.format, CameraFileFormat::kRosCameraInfo);
  EXPECT_EQ(ros_file.camera, file.camera);
  // An extension that names no camera format is refused before any work.
  const OalservoRun bad = RunOalservo(dir, base + (dir / "camera.txt") + "'");
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
  EXPECT_NE(bad.err.find("--out"), std::string::npos) << bad.err;
  EXPECT_NE(bad.err.find("the extension names the format"), std::string::npos) << bad.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "camera.txt"));
  const OalservoRun ros_xml = RunOalservo(dir, base + (dir / "c.xml") + "' --ros");
  EXPECT_EQ(ros_xml.exit_code, 2) << ros_xml.err;
  EXPECT_NE(ros_xml.err.find("ROS's camera_info is a .yaml or .yml file"), std::string::npos)
      << ros_xml.err;
}

// `views` views of the A3 sheet lying on the bench photographs, through `camera`, tilted
// 15-45 deg, as PGM files in dir/sheet.
std::string WriteSheetShots(const TestDir& dir, const Lens& camera, int views) {
  const std::string shots = dir / "sheet";
  std::filesystem::create_directories(shots);
  const LineTarget target = FourLineA3Target();
  RenderedFrameOptions options;
  options.camera = camera;
  options.seed = 5;
  options.noise_sigma = 4.0;
  options.blur_sigma_px = 1.0;
  options.scene = BenchScene();
  options.backgrounds = DefaultBenchPhotos();
  const EvaluationScenes scenes(target, options);
  PoseSampling sampling = SheetSampling(target);
  sampling.max_tilt_deg = 45.0;
  std::uint64_t state = 11;
  for (int k = 0; k < views; ++k) {
    vpHomogeneousMatrix cMo = SamplePose(scenes.For(k), sampling, &state);
    while (std::acos(std::fabs(cMo[2][2])) < vpMath::rad(15.0)) {
      cMo = SamplePose(scenes.For(k), sampling, &state);
    }
    const RenderedFrame frame = scenes.For(k).Render(cMo, 100 + k, scenes.EffectsFor(k));
    vpImageIo::write(frame.image,
                     shots + "/sheet" + (k < 10 ? "0" : "") + std::to_string(k) + ".pgm");
  }
  return shots;
}

TEST(CalibrateCommand, CalibratesFromThePrintedSheetOnABench) {
  if (!std::filesystem::exists("/usr/share/visp-images-data/ViSP-images/Klimt/Klimt.pgm")) {
    GTEST_SKIP() << "Debian's visp-images-data (the bench photographs) is not installed";
  }
  const TestDir dir;
  const Lens truth = Lens::WithKdu(690.0, 694.0, 331.0, 232.0, 0.2, 640, 480);
  const std::string shots = WriteSheetShots(dir, truth, 14);
  // A blank frame among them: listed as not used, the others calibrate.
  vpImageIo::write(vpImage<unsigned char>(480, 640, 128), shots + "/zz-blank.pgm");
  const OalservoRun run =
      RunOalservo(dir, "calibrate '" + shots + "' --out '" + (dir / "camera.xml") + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err << run.out;
  EXPECT_NE(run.out.find("zz-blank.pgm: not used: the target four-line-a3 was not found"),
            std::string::npos)
      << run.out;
  EXPECT_NE(run.out.find("stripe points, RMS"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("of 15 views"), std::string::npos) << run.out;
  const CameraFile file = LoadCameraFile(dir / "camera.xml", "Camera");
  EXPECT_NEAR(file.camera.px(), truth.px(), 0.005 * truth.px());
  EXPECT_NEAR(file.camera.py(), truth.py(), 0.005 * truth.py());
  EXPECT_NEAR(file.camera.u0(), truth.u0(), 3.0);
  EXPECT_NEAR(file.camera.v0(), truth.v0(), 3.0);
  EXPECT_NEAR(file.camera.kdu(), 0.2, 0.02);
}

// Views of the sheet in the corners of a lens about 100 degrees across: the finder's pinhole
// guesses miss the sheet where the lens bends its stripes most; through the lens the other
// views give, it is found there, and every view is used.
TEST(CalibrateCommand, FindsTheSheetInAWideLensCornersThroughTheLensTheOthersGave) {
  const TestDir dir;
  const std::string lens = std::string(OAL_SOURCE_DIR) + "/config/lenses/wide-100.yaml";
  const std::string views = dir / "views";
  const OalservoRun render = RunOalservo(
      dir, "render --camera '" + lens + "' --count 6 --seed 21 --max-tilt-deg 45 --noise 3 " +
               "--blur 0.8 --max-offset 0.3 --min-distance 0.4 --max-distance 0.75 --out '" +
               views + "'");
  ASSERT_EQ(render.exit_code, 0) << render.err;
  const OalservoRun run =
      RunOalservo(dir, "calibrate '" + views + "' --out '" + (dir / "camera.yaml") + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err << run.out;
  EXPECT_NE(run.out.find("more views through the lens the others gave"), std::string::npos)
      << run.out;
  EXPECT_EQ(run.out.find("not used"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("6 of 6 views)"), std::string::npos) << run.out;
  const CameraFile file = LoadCameraFile(dir / "camera.yaml");
  const CameraFile truth = LoadCameraFile(lens);
  EXPECT_NEAR(file.camera.px(), truth.camera.px(), 0.002 * truth.camera.px());
  EXPECT_NEAR(file.camera.distortion().k1, truth.camera.distortion().k1, 0.002);
}

// A video of the sheet moved from pose to pose and held still at each: --live takes one view
// per pose held, and calibrates with them when the video ends.
TEST(CalibrateCommand, LiveTakesAViewWhereTheSheetIsHeldStill) {
  if (!std::filesystem::exists("/usr/share/visp-images-data/ViSP-images/Klimt/Klimt.pgm")) {
    GTEST_SKIP() << "Debian's visp-images-data (the bench photographs) is not installed";
  }
  const TestDir dir;
  const std::string video = dir / "moving.avi";
  const Lens truth = Lens::WithKdu(690.0, 694.0, 331.0, 232.0, 0.2, 640, 480);
  {
    cv::VideoWriter writer(video, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10.0, {640, 480});
    if (!writer.isOpened()) GTEST_SKIP() << "OpenCV cannot write MJPG AVI files here";
    const LineTarget target = FourLineA3Target();
    RenderedFrameOptions options;
    options.camera = truth;
    options.noise_sigma = 3.0;
    options.blur_sigma_px = 0.8;
    options.scene = BenchScene();
    options.backgrounds = {DefaultBenchPhotos().front()};
    const EvaluationScenes scenes(target, options);
    PoseSampling sampling = SheetSampling(target);
    sampling.max_tilt_deg = 40.0;
    std::uint64_t state = 21, noise = 1;
    const auto write = [&](const vpHomogeneousMatrix& cMo) {
      cv::Mat colour;
      const RenderedFrame frame = scenes.For(0).Render(cMo, noise++);
      cv::Mat gray(480, 640, CV_8UC1, const_cast<unsigned char*>(frame.image.bitmap));
      cv::cvtColor(gray, colour, cv::COLOR_GRAY2BGR);
      writer.write(colour);
    };
    for (int held = 0; held < 5; ++held) {
      for (int moving = 0; moving < 3; ++moving) write(SamplePose(scenes.For(0), sampling, &state));
      const vpHomogeneousMatrix still = SamplePose(scenes.For(0), sampling, &state);
      for (int k = 0; k < 7; ++k) write(still);
    }
  }
  const OalservoRun run =
      RunOalservo(dir, "calibrate '" + video + "' --live --out '" + (dir / "camera.xml") + "'");
  ASSERT_EQ(run.exit_code, 0) << run.err << run.out;
  EXPECT_NE(run.out.find("view 5 of 20 taken: " + video + "#"), std::string::npos) << run.out;
  EXPECT_EQ(run.out.find("view 6 of 20"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("hold the target still"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("camera 'Camera', 640x480, 5 of 5 views)"), std::string::npos) << run.out;
  const CameraFile file = LoadCameraFile(dir / "camera.xml", "Camera");
  EXPECT_NEAR(file.camera.px(), truth.px(), 0.03 * truth.px());
}

TEST(CalibrateCommand, TargetOptionsThatDoNotGoTogetherAreUsageErrors) {
  const TestDir dir;
  const std::string out = dir / "camera.xml";
  OalservoRun run =
      RunOalservo(dir, "calibrate '" + dir.path().string() + "' --square 0.02 --out '" + out + "'");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("--square requires --chessboard"), std::string::npos) << run.err;
  run = RunOalservo(dir, "calibrate '" + dir.path().string() +
                             "' --target four-line-a3 --chessboard 9x6 --square 0.02 --out '" +
                             out + "'");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("--target excludes --chessboard"), std::string::npos) << run.err;
  run = RunOalservo(dir, "calibrate '" + dir.path().string() + "' --target a3 --out '" + out + "'");
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.err.find("--target: target 'a3' is not one of: four-line-a3, four-line-a4"),
            std::string::npos)
      << run.err;
  const std::string config = dir / "extra.yaml";
  test::WriteText(config,
                  test::ReadText(std::string(OAL_SOURCE_DIR) + "/config/four-line-a3.yaml") +
                      "camera:\n  px: 600\n");
  run = RunOalservo(
      dir, "calibrate '" + dir.path().string() + "' --config '" + config + "' --out '" + out + "'");
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.err.find("section 'camera' is not used by oalservo calibrate"), std::string::npos)
      << run.err;
  run = RunOalservo(dir, "calibrate '" + dir.path().string() + "' --views 10 --out '" + out + "'");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("--views requires --live"), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST(CalibrateCommand, BadInputIsAClearErrorAndWritesNothing) {
  const TestDir dir;
  const std::string out = dir / "camera.xml";
  OalservoRun run = RunOalservo(dir, "calibrate '" + dir.path().string() +
                                         "' --chessboard 9by6 --square 0.02 --out '" + out + "'");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("--chessboard 9by6: expected the inner corners as COLUMNSxROWS"),
            std::string::npos)
      << run.err;
  run = RunOalservo(dir, "calibrate '" + dir.path().string() +
                             "' --chessboard 9x6 --square -1 --out '" + out + "'");
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_NE(run.err.find("--square = -1. Violated constraint: 0 < --square <= 1"),
            std::string::npos)
      << run.err;

  // Three blank frames: no board anywhere.
  const std::string blank = dir / "blank";
  std::filesystem::create_directories(blank);
  for (int k = 0; k < 3; ++k) {
    vpImageIo::write(vpImage<unsigned char>(480, 640, 200),
                     blank + "/b" + std::to_string(k) + ".pgm");
  }
  run = RunOalservo(dir,
                    "calibrate '" + blank + "' --chessboard 9x6 --square 0.02 --out '" + out + "'");
  EXPECT_EQ(run.exit_code, 1);
  EXPECT_NE(run.err.find("0 of 3 images show the whole chessboard (9x6 inner corners), at least 3 "
                         "needed: nothing written to"),
            std::string::npos)
      << run.err;
  EXPECT_NE(
      run.out.find("b0.pgm: not used: the whole chessboard (9x6 inner corners) was not found"),
      std::string::npos)
      << run.out;
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace oal
