#include "io/camera_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "tests/test_util.h"

namespace oal {
namespace {

using ::testing::HasSubstr;

constexpr const char* kTwoCameras = R"(<?xml version="1.0"?>
<root>
  <!-- hand-written, as a user would -->
  <camera>
    <name>left</name>
    <image_width>320</image_width>
    <image_height>240</image_height>
    <model>
      <type>perspectiveProjWithoutDistortion</type>
      <px>300</px> <py>301</py> <u0>160</u0> <v0>120</v0>
    </model>
    <model>
      <type>perspectiveProjWithDistortion</type>
      <px>310</px> <py>311</py> <u0>161</u0> <v0>121</v0> <kud>-0.1</kud> <kdu>0.11</kdu>
    </model>
  </camera>
  <camera>
    <name>right</name>
    <image_width>640</image_width>
    <image_height>480</image_height>
    <model>
      <type>perspectiveProjWithoutDistortion</type>
      <px>600</px> <py>600</py> <u0>319.5</u0> <v0>239.5</v0>
    </model>
  </camera>
</root>
)";

std::string LoadError(const std::string& path, const std::string& name = "") {
  try {
    LoadCameraFile(path, name);
  } catch (const std::runtime_error& error) {
    return error.what();
  }
  return "";
}

TEST(CameraFile, FirstCameraWithItsDistortionModelWhenNoNameIsGiven) {
  test::TestDir dir;
  test::WriteText(dir / "cams.xml", kTwoCameras);
  const CameraFile camera = LoadCameraFile(dir / "cams.xml");
  EXPECT_EQ(camera.name, "left");
  EXPECT_EQ(camera.width, 320u);
  EXPECT_EQ(camera.camera.model(), Lens::Model::kViSP);
  EXPECT_EQ(camera.camera.px(), 310.0);
  EXPECT_EQ(camera.camera.kdu(), 0.11);
  EXPECT_EQ(camera.camera.kud(), -0.1);
}

TEST(CameraFile, CameraByNameWithoutDistortion) {
  test::TestDir dir;
  test::WriteText(dir / "cams.xml", kTwoCameras);
  const CameraFile camera = LoadCameraFile(dir / "cams.xml", "right");
  EXPECT_EQ(camera.name, "right");
  EXPECT_EQ(camera.height, 480u);
  EXPECT_EQ(camera.camera.model(), Lens::Model::kPinhole);
  EXPECT_EQ(camera.camera.u0(), 319.5);
}

TEST(CameraFile, SaveThenLoad) {
  test::TestDir dir;
  Lens camera;
  camera = Lens::WithKudKdu(500.0, 501.0, 159.5, 119.5, -0.2, 0.25);
  SaveCameraFile(dir / "camera.xml", camera, "mine", 320, 240);
  SaveCameraFile(dir / "camera.xml", camera, "mine", 320, 240);  // replaces, never appends
  const CameraFile loaded = LoadCameraFile(dir / "camera.xml");
  EXPECT_EQ(loaded.name, "mine");
  EXPECT_EQ(loaded.camera.py(), 501.0);
  EXPECT_EQ(loaded.camera.kdu(), 0.25);
  EXPECT_TRUE(test::TempFilesIn(dir.path()).empty());
}

TEST(CameraFile, UnusableFilesAreNamed) {
  test::TestDir dir;
  EXPECT_THAT(LoadError(dir / "none.xml"), HasSubstr("none.xml' does not exist"));
  test::WriteText(dir / "cams.xml", kTwoCameras);
  EXPECT_THAT(LoadError(dir / "cams.xml", "middle"),
              HasSubstr("has no camera named 'middle' (cameras: 'left', 'right')"));
  test::WriteText(dir / "text.xml", "not xml at all <<<");
  EXPECT_THAT(LoadError(dir / "text.xml"), HasSubstr("text.xml' is not valid XML"));
  test::WriteText(dir / "empty.xml", "<?xml version=\"1.0\"?>\n<root></root>\n");
  EXPECT_THAT(LoadError(dir / "empty.xml"), HasSubstr("empty.xml' has no <camera>"));
  test::WriteText(dir / "nomodel.xml", "<root><camera><name>c</name></camera></root>");
  EXPECT_THAT(LoadError(dir / "nomodel.xml"), HasSubstr("has no model of type"));
  test::WriteText(dir / "partial.xml",
                  "<root><camera><name>c</name><model><type>perspectiveProjWithDistortion"
                  "</type><px>1</px></model></camera></root>");
  EXPECT_THAT(LoadError(dir / "partial.xml"),
              HasSubstr("vpXmlParserCamera cannot read camera 'c'"));
}

// A parameter that is not a number, or a focal length <= 0, is named with the file, its line,
// the camera, the model and the field (ViSP alone says "Camera parameter px = 0").
TEST(CameraFile, BadParametersNameTheFileAndTheField) {
  test::TestDir dir;
  const auto camera = [](const std::string& px, const std::string& kdu) {
    return "<?xml version=\"1.0\"?>\n<root>\n  <camera>\n    <name>c</name>\n    <model>\n"
           "      <type>perspectiveProjWithDistortion</type>\n      <px>" +
           px + "</px>\n      <py>600</py> <u0>320</u0> <v0>240</v0>\n      <kud>0</kud> <kdu>" +
           kdu + "</kdu>\n    </model>\n  </camera>\n</root>\n";
  };
  const std::string path = dir / "cam.xml";
  test::WriteText(path, camera("abc", "0"));
  EXPECT_EQ(LoadError(path), path +
                                 ":7: camera 'c', model perspectiveProjWithDistortion: <px> is "
                                 "'abc', not a number");
  test::WriteText(path, camera("0", "0"));
  EXPECT_EQ(LoadError(path), path +
                                 ":7: camera 'c', model perspectiveProjWithDistortion: <px> = 0: "
                                 "a focal length in pixels must be > 0");
  test::WriteText(path, camera("-600", "0"));
  EXPECT_THAT(LoadError(path), HasSubstr("<px> = -600: a focal length"));
  test::WriteText(path, camera("600", "0.1x"));
  EXPECT_THAT(LoadError(path), HasSubstr(":9: camera 'c', model perspectiveProjWithDistortion: "
                                         "<kdu> is '0.1x', not a number"));
  test::WriteText(path, camera(" 600 ", "0.1"));  // whitespace around a number is fine
  EXPECT_EQ(LoadCameraFile(path).camera.px(), 600.0);
}

}  // namespace
}  // namespace oal
