// `oalservo camera`, run as a user runs it: a camera file shown, converted between ViSP's XML,
// OpenCV's YAML and ROS's camera_info, the approximation said, bad paths refused.
#include "app/camera_command.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "io/camera_file.h"
#include "tests/app/command_test_util.h"
#include "tests/test_util.h"

namespace oal {
namespace {

using test::OalservoRun;
using test::RunOalservo;

const std::string kSample = std::string(OAL_SOURCE_DIR) + "/config/lenses/opencv-sample.yaml";

TEST(CameraCommand, ShowsAndConvertsAFileSayingWhatTheNewFormatCannotHold) {
  const test::TestDir dir;
  const OalservoRun show = RunOalservo(dir, "camera '" + kSample + "'");
  ASSERT_EQ(show.exit_code, 0) << show.err;
  EXPECT_NE(show.out.find("OpenCV's calibration YAML, 640x480"), std::string::npos) << show.out;
  EXPECT_NE(show.out.find("plumb_bob: px 535.916"), std::string::npos) << show.out;

  const OalservoRun xml =
      RunOalservo(dir, "camera '" + kSample + "' --out '" + (dir / "c.xml") + "'");
  ASSERT_EQ(xml.exit_code, 0) << xml.err;
  EXPECT_NE(xml.err.find("best approximation of the plumb_bob lens over the 640 x 480 image"),
            std::string::npos)
      << xml.err;
  const CameraFile visp = LoadCameraFile(dir / "c.xml");
  EXPECT_EQ(visp.camera.model(), Lens::Model::kViSP);
  EXPECT_EQ(visp.width, 640u);

  const OalservoRun ros =
      RunOalservo(dir, "camera '" + kSample + "' --out '" + (dir / "c.yaml") + "' --ros");
  ASSERT_EQ(ros.exit_code, 0) << ros.err;
  EXPECT_TRUE(ros.err.empty()) << ros.err;  // the full model, exactly
  const CameraFile back = LoadCameraFile(dir / "c.yaml", "Camera");
  EXPECT_EQ(back.format, CameraFileFormat::kRosCameraInfo);
  EXPECT_EQ(back.camera, LoadCameraFile(kSample).camera);
}

TEST(CameraCommand, BadPathsAreRefusedAndNothingIsWritten) {
  const test::TestDir dir;
  const OalservoRun txt =
      RunOalservo(dir, "camera '" + kSample + "' --out '" + (dir / "c.txt") + "'");
  EXPECT_EQ(txt.exit_code, 2);
  EXPECT_NE(txt.err.find("--out: camera file"), std::string::npos) << txt.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "c.txt"));
  test::WriteText(dir / "bad.yaml", "camera_matrix: {rows: 3, cols: 3, data: [1, 2]}\n");
  const OalservoRun bad =
      RunOalservo(dir, "camera '" + (dir / "bad.yaml") + "' --out '" + (dir / "c.xml") + "'");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.err.find("bad.yaml:1: 'camera_matrix.data' has 2 numbers"), std::string::npos)
      << bad.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "c.xml"));
}

}  // namespace
}  // namespace oal
