#include "io/camera_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <visp3/core/vpXmlParserCamera.h>

#include <opencv2/core/persistence.hpp>
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
  Lens camera = Lens::WithKudKdu(500.0, 501.0, 159.5, 119.5, -0.2, 0.25);
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

// OpenCV's sample camera (its calibration tutorial's out_camera_data.yml), as OpenCV writes it.
const Lens kOpenCvSample = Lens::WithDistortion(
    535.91573396163199, 535.91573396163199, 342.28315473308373, 235.57082909788173,
    {-0.26637260909660682, -0.038588898922304653, 0.0017831947042852964, -0.00028122100441115472,
     0.23839153080878486});

TEST(CameraFile, ReadsOpenCvsOwnCalibrationYaml) {
  test::TestDir dir;
  const std::string path = dir / "out_camera_data.yml";
  {
    cv::FileStorage fs(path, cv::FileStorage::WRITE);
    fs << "calibration_time"
       << "Sat Dec  5 2026";
    fs << "image_width" << 640 << "image_height" << 480;
    fs << "camera_matrix"
       << (cv::Mat_<double>(3, 3) << kOpenCvSample.px(), 0, kOpenCvSample.u0(), 0,
           kOpenCvSample.py(), kOpenCvSample.v0(), 0, 0, 1);
    const auto d = kOpenCvSample.distortion().ToArray();
    fs << "distortion_coefficients" << (cv::Mat_<double>(5, 1) << d[0], d[1], d[2], d[3], d[4]);
    fs << "avg_reprojection_error" << 0.39;
  }
  const CameraFile read = LoadCameraFile(path);
  EXPECT_EQ(read.format, CameraFileFormat::kOpenCvYaml);
  EXPECT_EQ(read.camera, kOpenCvSample);
  EXPECT_EQ(read.width, 640u);
  EXPECT_EQ(read.height, 480u);
  EXPECT_EQ(read.name, "");
}

TEST(CameraFile, OpenCvYamlWrittenIsReadByOpenCvAndBack) {
  test::TestDir dir;
  const std::string path = dir / "camera.yaml";
  EXPECT_FALSE(SaveCameraFile(path, kOpenCvSample, "", 640, 480).has_value());
  cv::FileStorage fs(path, cv::FileStorage::READ);
  ASSERT_TRUE(fs.isOpened());
  cv::Mat k, d;
  fs["camera_matrix"] >> k;
  fs["distortion_coefficients"] >> d;
  EXPECT_EQ(static_cast<int>(fs["image_width"]), 640);
  ASSERT_EQ(k.rows, 3);
  EXPECT_EQ(k.at<double>(0, 0), kOpenCvSample.px());
  EXPECT_EQ(k.at<double>(1, 2), kOpenCvSample.v0());
  ASSERT_EQ(d.total(), 5u);
  EXPECT_EQ(d.at<double>(4), kOpenCvSample.distortion().k3);
  EXPECT_EQ(LoadCameraFile(path).camera, kOpenCvSample);
  // The rational model keeps its eight coefficients.
  const Lens rational =
      Lens::WithDistortion(600, 600, 319.5, 239.5, {0.3, 0.02, 0, 0, 0, 0.62, 0.05, 0});
  SaveCameraFile(path, rational, "", 640, 480);
  EXPECT_EQ(LoadCameraFile(path).camera, rational);
}

TEST(CameraFile, RosCameraInfoReadAndWritten) {
  test::TestDir dir;
  // As ROS's camera_calibration writes it.
  const std::string ros = dir / "head_camera.yaml";
  test::WriteText(ros, R"(image_width: 640
image_height: 480
camera_name: head_camera
camera_matrix:
  rows: 3
  cols: 3
  data: [535.9157, 0, 342.2832, 0, 535.9157, 235.5708, 0, 0, 1]
distortion_model: plumb_bob
distortion_coefficients:
  rows: 1
  cols: 5
  data: [-0.266373, -0.0385889, 0.00178319, -0.000281221, 0.238392]
rectification_matrix:
  rows: 3
  cols: 3
  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]
projection_matrix:
  rows: 3
  cols: 4
  data: [535.9157, 0, 342.2832, 0, 0, 535.9157, 235.5708, 0, 0, 0, 1, 0]
)");
  const CameraFile read = LoadCameraFile(ros, "head_camera");
  EXPECT_EQ(read.format, CameraFileFormat::kRosCameraInfo);
  EXPECT_EQ(read.name, "head_camera");
  EXPECT_EQ(read.camera.distortion().k3, 0.238392);
  EXPECT_EQ(read.camera.u0(), 342.2832);
  const std::string path = dir / "written.yaml";
  EXPECT_FALSE(SaveCameraFile(path, kOpenCvSample, "wrist", 640, 480,
                              CameraFileFormat::kRosCameraInfo, {"fitted by a test"})
                   .has_value());
  const CameraFile back = LoadCameraFile(path);
  EXPECT_EQ(back.format, CameraFileFormat::kRosCameraInfo);
  EXPECT_EQ(back.name, "wrist");
  EXPECT_EQ(back.camera, kOpenCvSample);
  EXPECT_THAT(test::ReadText(path), HasSubstr("# fitted by a test\n"));
  EXPECT_THAT(test::ReadText(path), HasSubstr("distortion_model: plumb_bob\n"));
}

// ViSP's XML holds one radial term: a lens in OpenCV's model goes in as its best one-term
// approximation, which ViSP itself reads, and the writer says so; likewise ViSP's kdu in YAML.
TEST(CameraFile, ApproximationsAreSaidAndReadByViSP) {
  test::TestDir dir;
  const std::string xml = dir / "camera.xml";
  const std::optional<std::string> note = SaveCameraFile(xml, kOpenCvSample, "c", 640, 480);
  ASSERT_TRUE(note.has_value());
  EXPECT_THAT(*note, HasSubstr("best approximation of the plumb_bob lens over the 640 x 480"));
  vpCameraParameters visp;
  vpXmlParserCamera parser;
  ASSERT_EQ(
      parser.parse(visp, xml, "c", vpCameraParameters::perspectiveProjWithDistortion, 640, 480),
      vpXmlParserCamera::SEQUENCE_OK);
  EXPECT_EQ(Lens(visp), kOpenCvSample.ViSPCamera(640, 480));
  const Lens visp_lens = Lens::WithKdu(600, 600, 319.5, 239.5, 0.2, 640, 480);
  const std::optional<std::string> yaml_note =
      SaveCameraFile(dir / "kdu.yaml", visp_lens, "", 640, 480);
  ASSERT_TRUE(yaml_note.has_value());
  EXPECT_THAT(*yaml_note, HasSubstr("perspectiveProjWithDistortion lens"));
  EXPECT_EQ(LoadCameraFile(dir / "kdu.yaml").camera.model(), Lens::Model::kOpenCV);
  EXPECT_FALSE(SaveCameraFile(dir / "kdu.xml", visp_lens, "", 640, 480).has_value());
}

TEST(CameraFile, BadYamlNamesTheFileLineAndKey) {
  test::TestDir dir;
  const std::string path = dir / "cam.yaml";
  const auto file = [](const std::string& k, const std::string& d) {
    return "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\ncamera_matrix: !!opencv-matrix\n"
           "   rows: 3\n   cols: 3\n   dt: d\n   data: [" +
           k +
           "]\ndistortion_coefficients: !!opencv-matrix\n   rows: 1\n   cols: 5\n   dt: d\n"
           "   data: [" +
           d + "]\n";
  };
  const std::string k = "500., 0., 320., 0., 500., 240., 0., 0., 1.";
  test::WriteText(path, file(k, "0.1, 0., 0., 0., 0."));
  EXPECT_EQ(LoadCameraFile(path).camera.distortion().k1, 0.1);
  test::WriteText(path, file("500., 0., 320., 0., abc, 240., 0., 0., 1.", "0., 0., 0., 0., 0."));
  EXPECT_EQ(LoadError(path),
            path + ":9: 'camera_matrix.data[4]' must be a finite number, got 'abc'");
  test::WriteText(path, file(k, "0.1, 0., 0., 0."));
  EXPECT_EQ(LoadError(path), path +
                                 ":14: 'distortion_coefficients.data' has 4 numbers where rows "
                                 "x cols is 5");
  test::WriteText(path, file("500., 0., 320., 0., 500., 240.", "0., 0., 0., 0., 0."));
  EXPECT_THAT(LoadError(path), HasSubstr(":9: 'camera_matrix.data' has 6 numbers"));
  test::WriteText(path, file("-500., 0., 320., 0., 500., 240., 0., 0., 1.", "0., 0., 0., 0., 0."));
  EXPECT_THAT(LoadError(path), HasSubstr("focal lengths in pixels must be > 0"));
  test::WriteText(path, "image_width: 640\n  bad: [\n");
  EXPECT_THAT(LoadError(path), HasSubstr(path + ":"));
  EXPECT_THAT(LoadError(path), HasSubstr("not valid YAML"));
  test::WriteText(path, "image_width: 640\n");
  EXPECT_THAT(LoadError(path), HasSubstr("has no 'camera_matrix'"));
  test::WriteText(path,
                  "image_width: 640\nimage_height: 480\ndistortion_model: equidistant\n"
                  "camera_matrix: {rows: 3, cols: 3, data: [" +
                      k + "]}\n");
  EXPECT_EQ(LoadError(path), path +
                                 ":3: 'distortion_model' is 'equidistant': only plumb_bob and "
                                 "rational_polynomial (OpenCV's model) are supported, not the "
                                 "fisheye (equidistant) model");
  test::WriteText(path, "camera_matrix: {rows: 3, cols: 3, data: [" + k +
                            "]}\ndistortion_coefficients: {rows: 1, cols: 12, data: [0, 0, 0, 0, "
                            "0, 0, 0, 0, 0.01, 0, 0, 0]}\n");
  EXPECT_THAT(LoadError(path), HasSubstr("thin-prism or tilted-sensor terms (coefficient 9"));
  test::WriteText(dir / "cam.txt", "px: 1\n");
  EXPECT_THAT(LoadError(dir / "cam.txt"), HasSubstr("the extension names the format"));
  test::WriteText(path, file(k, "0., 0., 0., 0., 0."));
  EXPECT_THAT(LoadError(path, "left"), HasSubstr("holds one camera, without a name, not 'left'"));
}

TEST(CameraFile, FormatFromTheExtension) {
  EXPECT_EQ(CameraFileFormatFor("a/b.xml", false), CameraFileFormat::kViSPXml);
  EXPECT_EQ(CameraFileFormatFor("b.YAML", false), CameraFileFormat::kOpenCvYaml);
  EXPECT_EQ(CameraFileFormatFor("b.yml", true), CameraFileFormat::kRosCameraInfo);
  EXPECT_THROW(CameraFileFormatFor("b.json", false), std::invalid_argument);
  EXPECT_THROW(CameraFileFormatFor("b.xml", true), std::invalid_argument);
}

}  // namespace
}  // namespace oal
