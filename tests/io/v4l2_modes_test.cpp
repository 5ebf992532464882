// The camera modes (io/v4l2_modes.h): the mode chosen for what the user asks among those a
// webcam lists, the request read from its text, and the device listing where there is none.
// Reading a real camera needs one plugged in: not tested here (docs say so).
#include "io/v4l2_modes.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/image_source.h"

namespace oal {
namespace {

using ::testing::HasSubstr;

// What a typical USB webcam lists (a Logitech C920's modes, abridged): YUYV up to 1080p but
// slow there, MJPEG at 30 frames a second at every size.
std::vector<CameraMode> WebcamModes() {
  return {{"YUYV", 640, 480, {30, 24, 15}},  {"YUYV", 1280, 720, {10, 7.5, 5}},
          {"YUYV", 1920, 1080, {5}},         {"MJPG", 640, 480, {30, 24, 15}},
          {"MJPG", 1280, 720, {30, 24, 15}}, {"MJPG", 1920, 1080, {30, 24, 15}}};
}

CameraRequest Asking(CameraFormat format, int width, int height, double fps) {
  CameraRequest request;
  request.format = format;
  request.width = width;
  request.height = height;
  request.fps = fps;
  return request;
}

TEST(ChooseCameraMode, AutoTakesUncompressedFramesWhereTheyComeAtTheRateElseMjpeg) {
  const std::vector<CameraMode> modes = WebcamModes();
  ChosenMode chosen = ChooseCameraMode(modes, Asking(CameraFormat::kAuto, 640, 480, 30));
  EXPECT_EQ(chosen.mode.fourcc, "YUYV");
  EXPECT_EQ(chosen.fps, 30);
  chosen = ChooseCameraMode(modes, Asking(CameraFormat::kAuto, 1280, 720, 30));
  EXPECT_EQ(chosen.mode.fourcc, "MJPG");  // YUYV gives 720p at 10 at most
  EXPECT_EQ(chosen.mode.width, 1280);
  chosen = ChooseCameraMode(modes, Asking(CameraFormat::kAuto, 1280, 720, 10));
  EXPECT_EQ(chosen.mode.fourcc, "YUYV");
  // Nothing asked: the largest size at its highest rate (1080p MJPEG at 30, not YUYV at 5).
  chosen = ChooseCameraMode(modes, CameraRequest());
  EXPECT_EQ(chosen.mode.fourcc, "MJPG");
  EXPECT_EQ(chosen.mode.height, 1080);
  EXPECT_EQ(chosen.fps, 30);
  // A format asked is kept; the size left out is its largest.
  chosen = ChooseCameraMode(modes, Asking(CameraFormat::kYuyv, 0, 0, 0));
  EXPECT_EQ(chosen.mode.fourcc, "YUYV");
  EXPECT_EQ(chosen.mode.width, 1920);
  EXPECT_EQ(chosen.fps, 5);
}

TEST(ChooseCameraMode, AModeTheCameraDoesNotGiveIsRefusedWithTheNearestItDoes) {
  const std::vector<CameraMode> modes = WebcamModes();
  try {
    ChooseCameraMode(modes, Asking(CameraFormat::kYuyv, 1280, 720, 30));
    FAIL() << "no error";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), HasSubstr("the camera gives no yuyv 1280x720 at 30 fps mode"));
    EXPECT_THAT(error.what(), HasSubstr("YUYV 1280x720 at 10, 7.5, 5 fps"));
    EXPECT_THAT(error.what(), HasSubstr("MJPG 1280x720 at 30, 24, 15 fps"));
  }
  try {
    ChooseCameraMode(modes, Asking(CameraFormat::kGrey, 0, 0, 0));
    FAIL() << "no error";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), HasSubstr("it lists no mode of that size or format"));
  }
  EXPECT_THROW(ChooseCameraMode(modes, Asking(CameraFormat::kAuto, 1280, 0, 0)),
               std::invalid_argument);
}

TEST(ParseCameraRequest, ReadsEachPartAndSaysWhatIsWrong) {
  CameraRequest request = ParseCameraRequest("mjpeg:1280x720@30");
  EXPECT_EQ(request.format, CameraFormat::kMjpeg);
  EXPECT_EQ(request.width, 1280);
  EXPECT_EQ(request.height, 720);
  EXPECT_EQ(request.fps, 30.0);
  request = ParseCameraRequest("1920x1080@7.5");
  EXPECT_EQ(request.format, CameraFormat::kAuto);
  EXPECT_EQ(request.fps, 7.5);
  request = ParseCameraRequest("YUYV");
  EXPECT_EQ(request.format, CameraFormat::kYuyv);
  EXPECT_EQ(request.width, 0);
  EXPECT_EQ(ParseCameraRequest("grey:640x480").height, 480);
  for (const char* bad : {"h264:640x480", "640x", "640x480@", "640x480@fast", "0x480", "640x480x2",
                          "640x480@30fps", "mjpeg:1280*720"}) {
    try {
      ParseCameraRequest(bad);
      ADD_FAILURE() << bad << ": no error";
    } catch (const std::invalid_argument& error) {
      EXPECT_THAT(error.what(), HasSubstr(std::string("'") + bad + "'"));
      EXPECT_THAT(error.what(), HasSubstr("e.g. mjpeg:1280x720@30"));
    }
  }
}

TEST(ListCameras, NoDeviceIsAnEmptyListAndAFileNamedLikeOneIsNotACamera) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("oal_no_cameras_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  EXPECT_TRUE(ListCameras(dir.string()).empty());
  std::ofstream(dir / "video0") << "not a device";
  EXPECT_TRUE(ListCameras(dir.string()).empty());
  EXPECT_TRUE(ModesOfDevice((dir / "video0").string()).empty());
  std::filesystem::remove_all(dir);
  EXPECT_TRUE(ListCameras("/no/such/dir").empty());
}

TEST(OpenV4l2Source, AMissingDeviceOrABadRequestIsAClearError) {
  try {
    OpenV4l2Source("/dev/video-none");
    FAIL() << "no error";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), HasSubstr("no V4L2 device at /dev/video-none"));
  }
  EXPECT_THROW(OpenV4l2Source("/dev/video-none", Asking(CameraFormat::kAuto, -1, 480, 0)),
               std::invalid_argument);
}

TEST(CameraFormat, NamesReadBackInAnyCase) {
  for (const CameraFormat format :
       {CameraFormat::kAuto, CameraFormat::kMjpeg, CameraFormat::kYuyv, CameraFormat::kGrey}) {
    EXPECT_EQ(CameraFormatFromString(ToString(format)), format);
  }
  EXPECT_EQ(CameraFormatFromString("MJPEG"), CameraFormat::kMjpeg);
  EXPECT_FALSE(CameraFormatFromString("h264").has_value());
}

}  // namespace
}  // namespace oal
