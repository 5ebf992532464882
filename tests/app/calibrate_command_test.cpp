// `oalservo calibrate` as a user runs it: a directory of chessboard photographs in, a ViSP
// camera file out, or a clear error and nothing written.
#include "app/calibrate_command.h"

#include <gtest/gtest.h>
#include <visp3/io/vpImageIo.h>

#include <filesystem>
#include <string>

#include "app/camera_file.h"
#include "tests/app/command_test_util.h"
#include "tests/app/test_util.h"
#include "tests/calibration/chessboard_views.h"

namespace oal {
namespace {

using test::OalservoRun;
using test::RunOalservo;
using test::TestDir;

// Twelve chessboard views through `camera` as PGM files in dir/shots.
std::string WriteShots(const TestDir& dir, const vpCameraParameters& camera) {
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
  const vpCameraParameters truth = CameraWithKdu(700.0, 702.0, 326.0, 235.0, 0.25, 640, 480);
  const std::string shots = WriteShots(dir, truth);
  const OalservoRun run =
      RunOalservo(dir, "calibrate '" + shots + "' --chessboard 9x6 --square 0.02 --out '" +
                           (dir / "cam/camera.xml") + "' --name Bench");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("view00.pgm: 54 corners, RMS"), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("reprojection RMS"), std::string::npos) << run.out;
  const CameraFile file = LoadCameraFile(dir / "cam/camera.xml", "Bench");
  EXPECT_NEAR(file.camera.get_px(), 700.0, 0.003 * 700.0);
  EXPECT_NEAR(file.camera.get_u0(), 326.0, 1.5);
  EXPECT_NEAR(file.camera.get_kdu(), 0.25, 0.03 * 0.25);
  EXPECT_EQ(file.width, 640u);
  EXPECT_EQ(file.height, 480u);
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
  EXPECT_NE(run.err.find("0 of 3 images show the whole chessboard, at least 3 needed: nothing "
                         "written to"),
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
