// The markers users would print instead of our target (eval/rendered/marker_method.h): the AprilTag
// and the ChArUco board printed on a rendered A3 sheet, found and posed by their libraries within
// 1 % and 1 degree of the truth; the tag's corners where the sheet's plane projects them; the
// lens handed to OpenCV (k1 = ViSP's kud, and the coefficients fitted to the rendered lens); the
// markers' names and sizes.
#include "eval/rendered/marker_method.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <visp3/core/vpMeterPixelConversion.h>
#include <visp3/core/vpPixelMeterConversion.h>
#include <visp3/detection/vpDetectorAprilTag.h>

#include <algorithm>
#include <cmath>
#include <opencv2/aruco.hpp>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "base/pose_distance.h"
#include "detector/lens.h"
#include "eval/rendered/apriltag_method.h"
#include "eval/rendered/charuco_method.h"
#include "eval/rendered/pose_accuracy.h"
#include "scene/scene.h"

namespace oal {
namespace {

using ::testing::HasSubstr;

// The evaluations' sheet lens at 640 x 480 (kdu 0.15: barrel).
Lens SheetCamera() {
  return Lens::WithKdu(600.0, 600.0, 319.5, 239.5, 0.15, 640, 480);
}

// A camera `distance_m` from the sheet's point (x_m, y_m), tilted by tilt_rad about an axis
// in the sheet at `azimuth_rad` from its x axis, rolled by roll_rad about the optical axis.
vpHomogeneousMatrix ViewOfSheet(double distance_m, double x_m, double y_m, double tilt_rad,
                                double azimuth_rad, double roll_rad) {
  // oMc: the camera at the point, looking along +z of the sheet (into it), then tilted.
  vpHomogeneousMatrix roll, tilt, back, to_point;
  roll.buildFrom(0, 0, 0, 0, 0, roll_rad);
  tilt.buildFrom(0, 0, 0, tilt_rad * std::cos(azimuth_rad), tilt_rad * std::sin(azimuth_rad), 0);
  back.buildFrom(0, 0, -distance_m, 0, 0, 0);
  to_point.buildFrom(x_m, y_m, 0, 0, 0, 0);
  const vpHomogeneousMatrix oMc = to_point * tilt * back * roll;
  return oMc.inverse();
}

// `method`'s marker printed on the A3 sheet's board, rendered from cMo through `camera`: a
// little noise and blur, the paper's texture and the sheet's shadow on a grey bench.
RenderedFrame RenderMarker(const MarkerMethod& method, const vpHomogeneousMatrix& cMo,
                           const Lens& camera = SheetCamera()) {
  RenderOptions options;
  options.camera = camera;
  options.noise_sigma = 2.0;
  options.blur_sigma_px = 0.7;
  options.paper_texture_grey = 3.0;
  options.shadow_darkness = 0.3;
  options.printed_picture = method.Print().picture;
  return SceneRenderer(MarkerSheet(FourLineA3Target(), method), options).Render(cMo, 7);
}

// Views of the A3 sheet near and far, tilted and rolled every way (the marker all in view).
std::vector<vpHomogeneousMatrix> Views() {
  return {ViewOfSheet(0.55, 0.01, -0.02, 0.35, 0.4, 0.3),
          ViewOfSheet(0.7, -0.03, 0.02, 0.45, 2.0, 1.8),
          ViewOfSheet(0.8, 0.02, 0.01, 0.2, -1.2, -2.6)};
}

void ExpectPosedWithinOnePercentAndOneDegree(SheetMarker marker) {
  const std::unique_ptr<MarkerMethod> method =
      MakeMarkerMethod(marker, FourLineA3Target(), SheetCamera(), 640, 480);
  for (const vpHomogeneousMatrix& cMo_true : Views()) {
    const MarkerPose found = method->Find(RenderMarker(*method, cMo_true).image);
    ASSERT_EQ(found.status, MarkerStatus::kOk) << found.message;
    const PoseDistance error = Distance(cMo_true, found.cMo);
    EXPECT_LT(error.translation_m / cMo_true.getTranslationVector().frobeniusNorm(), 0.01)
        << method->Name() << " at " << vpPoseVector(cMo_true).t();
    EXPECT_LT(vpMath::deg(error.rotation_rad), 1.0)
        << method->Name() << " at " << vpPoseVector(cMo_true).t();
    EXPECT_GT(found.detect_us, 0.0);
    EXPECT_GT(found.pose_us, 0.0);
  }
}

TEST(AprilTagMethod, PosesARenderedA3SheetWithinOnePercentAndOneDegree) {
  ExpectPosedWithinOnePercentAndOneDegree(SheetMarker::kAprilTag);
}

TEST(CharucoMethod, PosesARenderedA3SheetWithinOnePercentAndOneDegree) {
  ExpectPosedWithinOnePercentAndOneDegree(SheetMarker::kCharuco);
}

// The printed tag's black corners, found by ViSP's detector in the rendered frame, lie where
// the sheet's plane points (+-black side / 2) project, in the AprilTag library's pixels: their
// centres at (i + 1/2, j + 1/2), half a pixel right of and below ours and ViSP's (which is why
// the method hands getPose a camera whose principal point is moved by as much). Through a
// pinhole: the library fits straight edges, which a lens bends (the rendered lens itself is
// checked in scene_tests).
TEST(AprilTagMethod, TheTagsCornersAreFoundAtTheirProjectedPlanePoints) {
  const LineTarget sheet = FourLineA3Target();
  Lens pinhole = Lens::Pinhole(600.0, 600.0, 319.5, 239.5);
  const std::unique_ptr<MarkerMethod> method = MakeAprilTagMethod(sheet, pinhole, 640, 480);
  const double h = 0.5 * AprilTagBlackSide(sheet);
  EXPECT_NEAR(2.0 * h, 0.25, 0.001) << "A3: the largest tag with a white border";
  for (const vpHomogeneousMatrix& cMo : Views()) {
    vpDetectorAprilTag detector(vpDetectorAprilTag::TAG_36h11);
    detector.detect(RenderMarker(*method, cMo, pinhole).image);
    ASSERT_EQ(detector.getNbObjects(), 1u);
    for (const vpImagePoint& corner : detector.getPolygon(0)) {
      double nearest = 1e9;
      for (const auto& [X, Y] : {std::pair{-h, -h}, {h, -h}, {h, h}, {-h, h}}) {
        const vpColVector c = cMo * vpColVector({X, Y, 0.0, 1.0});
        nearest = std::min(nearest, std::hypot(319.5 + 600.0 * c[0] / c[2] + 0.5 - corner.get_u(),
                                               239.5 + 600.0 * c[1] / c[2] + 0.5 - corner.get_v()));
      }
      EXPECT_LT(nearest, 0.15) << corner;
    }
  }
}

// The ChArUco board's inner corners as OpenCV interpolates them lie where the sheet's plane
// points project, in the aruco module's pixels: their centres at (i + 1/2, j + 1/2), half a
// pixel right of and below ours and cornerSubPix's (which is why the method hands OpenCV a
// camera matrix whose principal point is moved by as much).
TEST(CharucoMethod, TheBoardsCornersAreFoundAtTheirProjectedPlanePoints) {
  const LineTarget sheet = FourLineA3Target();
  Lens pinhole = Lens::Pinhole(600.0, 600.0, 319.5, 239.5);
  const std::unique_ptr<MarkerMethod> method = MakeCharucoMethod(sheet, pinhole, 640, 480);
  const double square = CharucoSquareSide(sheet);
  const auto dictionary = cv::aruco::getPredefinedDictionary(cv::aruco::DICT_5X5_100);
  const auto board = cv::aruco::CharucoBoard::create(10, 7, static_cast<float>(square),
                                                     static_cast<float>(0.75 * square), dictionary);
  const vpHomogeneousMatrix cMo = Views()[1];
  const RenderedFrame frame = RenderMarker(*method, cMo, pinhole);
  const cv::Mat view(480, 640, CV_8U, frame.image.bitmap);
  std::vector<std::vector<cv::Point2f>> markers;
  std::vector<int> ids;
  cv::aruco::detectMarkers(view, dictionary, markers, ids);
  std::vector<cv::Point2f> corners;
  std::vector<int> corner_ids;
  cv::aruco::interpolateCornersCharuco(markers, ids, view, board, corners, corner_ids);
  ASSERT_GE(corner_ids.size(), 40u);
  double worst = 0.0, sum_u = 0.0, sum_v = 0.0;
  for (std::size_t i = 0; i < corner_ids.size(); ++i) {
    const int id = corner_ids[i];  // row by row over the 9 x 6 inner corners
    const double X = (id % 9 + 1 - 5.0) * square, Y = (id / 9 + 1 - 3.5) * square;
    const vpColVector c = cMo * vpColVector({X, Y, 0.0, 1.0});
    const double du = corners[i].x - (319.5 + 600.0 * c[0] / c[2] + 0.5);
    const double dv = corners[i].y - (239.5 + 600.0 * c[1] / c[2] + 0.5);
    worst = std::max(worst, std::hypot(du, dv));
    sum_u += du;
    sum_v += dv;
  }
  const double n = static_cast<double>(corner_ids.size());
  EXPECT_NEAR(sum_u / n, 0.0, 0.05);
  EXPECT_NEAR(sum_v / n, 0.0, 0.05);
  EXPECT_LT(worst, 0.45);  // each corner: cornerSubPix on a noisy frame
}

// ViSP's kud maps a normalised point to its distorted pixel as u = u0 + px x (1 + kud r^2),
// r^2 = x^2 + y^2 of the undistorted point: OpenCV's projection with k1 = kud and nothing else
// gives the same pixels.
TEST(OpenCvDistortion, OpenCvsK1IsViSPsKud) {
  const Lens camera = SheetCamera();
  ASSERT_NE(camera.kud(), 0.0);
  const cv::Matx<double, 1, 5> distortion = KudAsOpenCvDistortion(camera);
  EXPECT_EQ(distortion(0), camera.kud());
  for (int i = 1; i < 5; ++i) EXPECT_EQ(distortion(i), 0.0);
  std::vector<cv::Point3d> points;
  for (double x = -0.6; x <= 0.6; x += 0.1) {
    for (double y = -0.45; y <= 0.45; y += 0.15) points.emplace_back(x, y, 1.0);
  }
  std::vector<cv::Point2d> projected;
  cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), OpenCvCameraMatrix(camera),
                    distortion, projected);
  for (std::size_t i = 0; i < points.size(); ++i) {
    double u = 0.0, v = 0.0;
    vpMeterPixelConversion::convertPoint(camera.ViSPCamera(640, 480), points[i].x, points[i].y, u,
                                         v);
    EXPECT_NEAR(projected[i].x, u, 1e-9);
    EXPECT_NEAR(projected[i].y, v, 1e-9);
  }
  EXPECT_EQ(KudAsOpenCvDistortion(Lens::Pinhole(600.0, 600.0, 319.5, 239.5))(0), 0.0);
}

// The worst distance over the image between where the rendered (kdu) lens puts the ideal point
// of each pixel and where OpenCV's model with `distortion` puts it.
double WorstPixelMiss(const Lens& camera, int width, int height,
                      const std::vector<double>& distortion) {
  std::vector<cv::Point3d> rays;
  std::vector<cv::Point2d> pixels;
  for (int v = 0; v < height; v += 8) {
    for (int u = 0; u < width; u += 8) {
      const Point2d ray = camera.Normalised(u, v);
      rays.emplace_back(ray.u, ray.v, 1.0);
      pixels.emplace_back(u, v);
    }
  }
  std::vector<cv::Point2d> projected;
  cv::projectPoints(rays, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), OpenCvCameraMatrix(camera),
                    distortion, projected);
  double worst = 0.0;
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    worst = std::max(worst, std::hypot(projected[i].x - pixels[i].x, projected[i].y - pixels[i].y));
  }
  return worst;
}

// The lens the ChArUco method hands OpenCV: three coefficients fitted to the rendered kdu lens
// follow it to a tenth of a pixel over the image where kud alone misses it by pixels.
TEST(OpenCvDistortion, TheFittedCoefficientsFollowTheRenderedLens) {
  const struct {
    int width, height;
    double focal_px, fitted_px, kud_px;
  } cases[] = {
      {640, 480, 600.0, 0.02, 1.5}, {1280, 720, 914.0, 0.07, 5.0}, {1920, 1080, 1371.0, 0.1, 8.0}};
  for (const auto& c : cases) {
    const Lens camera = Lens::WithKdu(c.focal_px, c.focal_px, 0.5 * (c.width - 1),
                                      0.5 * (c.height - 1), 0.15, c.width, c.height);
    const std::vector<double> fitted = OpenCvDistortion(camera, c.width, c.height);
    ASSERT_EQ(fitted.size(), 5u);
    EXPECT_EQ(fitted[2], 0.0);
    EXPECT_EQ(fitted[3], 0.0);
    EXPECT_LT(WorstPixelMiss(camera, c.width, c.height, fitted), c.fitted_px) << c.width;
    const cv::Matx<double, 1, 5> kud = KudAsOpenCvDistortion(camera);
    EXPECT_GT(WorstPixelMiss(camera, c.width, c.height, std::vector<double>(kud.val, kud.val + 5)),
              c.kud_px)
        << c.width;
  }
  EXPECT_EQ(OpenCvDistortion(Lens::Pinhole(600.0, 600.0, 319.5, 239.5), 640, 480),
            std::vector<double>(5, 0.0));
  // A lens in OpenCV's model goes as it is.
  const Distortion d{-0.27, -0.04, 0.0018, -0.0003, 0.24};
  EXPECT_EQ(OpenCvDistortion(Lens::WithDistortion(536.0, 536.0, 342.3, 235.6, d), 640, 480),
            std::vector<double>({d.k1, d.k2, d.p1, d.p2, d.k3}));
}

// The sizes: the ChArUco squares 0.038 m on A3, in proportion on A4; the tag in proportion too.
TEST(MarkerPrint, SizesFollowTheSheet) {
  EXPECT_NEAR(CharucoSquareSide(FourLineA3Target()), 0.038, 1e-12);
  EXPECT_NEAR(CharucoSquareSide(FourLineA4Target()), 0.038 * 0.210 / 0.297, 1e-12);
  EXPECT_NEAR(AprilTagBlackSide(FourLineA4Target()), 0.21 * 8.0 / 9.5, 1e-12);
  for (const SheetMarker marker : {SheetMarker::kAprilTag, SheetMarker::kCharuco}) {
    for (const LineTarget& sheet : {FourLineA3Target(), FourLineA4Target()}) {
      const std::unique_ptr<MarkerMethod> method =
          MakeMarkerMethod(marker, sheet, SheetCamera(), 640, 480);
      const MarkerPrint& print = method->Print();
      const PrintedPicture& picture = print.picture;
      const double height_m =
          picture.width_m * picture.image->getHeight() / picture.image->getWidth();
      EXPECT_LE(picture.width_m, sheet.board_width_m + 1e-9) << method->Name() << " " << sheet.name;
      EXPECT_LE(height_m, sheet.board_height_m + 1e-9) << method->Name() << " " << sheet.name;
      for (const auto& corner : print.outline_m) {
        EXPECT_LE(std::fabs(corner[0]), 0.5 * picture.width_m + 1e-12);
        EXPECT_LE(std::fabs(corner[1]), 0.5 * height_m + 1e-12);
      }
    }
  }
}

TEST(SheetMarker, NamesRoundTripAndAnUnknownOneListsThem) {
  for (const SheetMarker marker :
       {SheetMarker::kOal, SheetMarker::kAprilTag, SheetMarker::kCharuco}) {
    EXPECT_EQ(SheetMarkerFromString(ToString(marker)), marker);
  }
  try {
    SheetMarkerFromString("qr");
    FAIL() << "accepted 'qr'";
  } catch (const std::invalid_argument& error) {
    EXPECT_THAT(error.what(), HasSubstr("'qr'"));
    EXPECT_THAT(error.what(), HasSubstr("oal, apriltag, charuco"));
  }
  EXPECT_THROW(MakeMarkerMethod(SheetMarker::kOal, FourLineA3Target(), SheetCamera(), 640, 480),
               std::invalid_argument);
}

// The evaluation with a marker: each frame counted, the ones without a pose by the marker's
// status; the lens estimate is ours only.
TEST(PoseAccuracy, AMarkerIsEvaluatedOnItsFrames) {
  PoseAccuracyOptions options;
  options.frames = 2;
  options.noise_sigma = 2.0;
  options.marker = SheetMarker::kAprilTag;
  const PoseAccuracyReport report = EvaluatePoseAccuracy(options);
  EXPECT_EQ(report.frames, 2);
  EXPECT_EQ(report.status_counts.at("ok") + report.status_counts.at("not-found") +
                report.status_counts.at("no-pose"),
            2);
  EXPECT_EQ(report.total_time_us.size(), 2u);
  EXPECT_THAT(report.marker_description, HasSubstr("AprilTag 36h11 id 0"));
  EXPECT_LE(report.posed_in_view, report.marker_in_view);
  options.estimate_distortion = true;
  EXPECT_THROW(options.Check(), std::invalid_argument);
}

}  // namespace
}  // namespace oal
