// Camera calibration (calibration/calibrate.h) from chessboard views rendered through a known
// lens: the intrinsics and the lens come back in OpenCV's model; views that cannot determine the
// camera are refused with the reason.
#include "calibration/calibrate.h"

#include <gtest/gtest.h>
#include <visp3/core/vpMath.h>
#include <visp3/io/vpImageIo.h>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <opencv2/calib3d.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "calibration/chessboard.h"
#include "detector/image_view.h"
#include "scene/scene.h"
#include "tests/calibration/chessboard_views.h"

namespace oal {
namespace {

using test::LookingAtTheBoard;
using test::RenderedViews;
using test::VariedPoses;

CalibrationOptions OptionsFor(int width, int height) {
  CalibrationOptions options;
  options.width = width;
  options.height = height;
  return options;
}

// The largest distance between the ideal pixels two lenses give, within the largest radius
// (from the principal point) where the views saw the target: beyond, a lens is extrapolated.
double WorstDifferenceWhereSeen(const Lens& a, const Lens& b,
                                const std::vector<CalibrationView>& views, double fraction = 1.0) {
  double reach = 0.0;
  for (const CalibrationView& view : views) {
    for (const CalibrationPoint& p : view.points) {
      reach = std::max(reach, std::hypot(p.u - a.u0(), p.v - a.v0()));
    }
  }
  return WorstIdealPixelDifference(a, b, 640, 480, fraction * reach);
}

// `advised`: the advice expected (the last ones).
void ExpectGoodFit(const CalibrationResult& result, std::size_t advised = 0) {
  EXPECT_LT(result.rms_px, 0.2);
  for (std::size_t i = 0; i + advised < result.advice.size(); ++i)
    ADD_FAILURE() << result.advice[i];
  for (const CalibrationViewReport& view : result.views) {
    if (view.used) {
      EXPECT_LT(view.rms_px, 0.3) << view.name;
    }
  }
}

// The lens ViSP's one-term model renders comes back as OpenCV's model that follows it: the
// same ideal pixel, within 0.3 px, for every pixel the views cover.
TEST(Calibrate, RecoversTheIntrinsicsAndAViSPLensFromChessboardViews) {
  for (const double kdu : {0.0, 0.2, 0.35}) {
    SCOPED_TRACE("kdu " + std::to_string(kdu));
    const Lens truth = Lens::WithKdu(760.0, 755.0, 331.0, 228.0, kdu, 640, 480);
    const std::vector<CalibrationView> views = RenderedViews(truth, VariedPoses());
    int found = 0;
    for (const CalibrationView& view : views) {
      found += !view.points.empty();
      EXPECT_FALSE(view.points.empty()) << view.name << ": no chessboard found";
    }
    ASSERT_GE(found, 10) << "the chessboard is found in most views";
    const CalibrationResult result = Calibrate(views, OptionsFor(640, 480));
    EXPECT_NEAR(result.camera.px(), truth.px(), 0.003 * truth.px());
    EXPECT_NEAR(result.camera.py(), truth.py(), 0.003 * truth.py());
    EXPECT_NEAR(result.camera.u0(), truth.u0(), 1.5);
    EXPECT_NEAR(result.camera.v0(), truth.v0(), 1.5);
    EXPECT_LT(WorstDifferenceWhereSeen(result.camera, truth, views), 0.3);
    // These views keep to the middle of the image, and the result says so.
    ASSERT_FALSE(result.advice.empty());
    EXPECT_NE(result.advice.back().find("% of the way to the image's corners"), std::string::npos)
        << result.advice.back();
    // A term the views cannot tell from zero is fixed there, and said.
    if (kdu == 0.0) {
      EXPECT_FALSE(result.fixed_terms.empty());
    }
    for (const std::string& fixed : result.fixed_terms) {
      EXPECT_NE(fixed.find(" fixed at 0: the views "), std::string::npos) << fixed;
    }
    EXPECT_GE(result.visp_rms_px, result.rms_px - 1e-9);
    std::cout << "kdu " << kdu << ": px " << result.camera.px() << " py " << result.camera.py()
              << " u0 " << result.camera.u0() << " v0 " << result.camera.v0() << " "
              << LensModelName(result.camera) << " k1 " << result.camera.distortion().k1 << " RMS "
              << result.rms_px << " px (ViSP's one term " << result.visp_rms_px << ")\n";
    ExpectGoodFit(result, 1);
  }
}

// Lenses in OpenCV's model (the sample camera of OpenCV's tutorial, a wide lens) come back:
// each coefficient fitted within three of its standard deviations, or fixed at zero when the
// views cannot tell it, and OpenCV's model beats ViSP's one term.
TEST(Calibrate, RecoversAnOpenCvLensWithEachTermsDeviation) {
  const struct {
    const char* name;
    Lens lens;
  } lenses[] = {
      {"opencv-sample",
       Lens::WithDistortion(535.9157, 535.9157, 342.2832, 235.5708,
                            {-0.266373, -0.0385889, 0.00178319, -0.000281221, 0.238392})},
      {"wide",
       Lens::WithDistortion(420.0, 420.0, 322.0, 238.0, {-0.28, 0.08, 0.0006, -0.0004, -0.01})},
  };
  for (const auto& c : lenses) {
    SCOPED_TRACE(c.name);
    std::vector<vpHomogeneousMatrix> poses = test::CornerPoses(c.lens.px());
    const std::vector<vpHomogeneousMatrix> varied = VariedPoses();
    for (std::size_t k = 0; k < varied.size(); k += 2) poses.push_back(varied[k]);
    const std::vector<CalibrationView> views = RenderedViews(c.lens, poses);
    const CalibrationResult result = Calibrate(views, OptionsFor(640, 480));
    ASSERT_EQ(result.camera.model(), Lens::Model::kOpenCV);
    EXPECT_NEAR(result.camera.px(), c.lens.px(), 3.0 * result.px_sd + 0.5);
    EXPECT_NEAR(result.camera.u0(), c.lens.u0(), 3.0 * result.u0_sd + 0.5);
    const auto fitted = result.camera.distortion().ToArray();
    const auto sd = result.distortion_sd.ToArray();
    const auto truth = c.lens.distortion().ToArray();
    for (std::size_t i = 0; i < 5; ++i) {
      if (fitted[i] == 0.0 && sd[i] == 0.0) continue;  // fixed, and said
      EXPECT_GT(sd[i], 0.0) << "term " << i;
      // With a term fixed the others absorb what it did: only the lens as a whole is compared.
      if (result.fixed_terms.empty()) {
        EXPECT_NEAR(fitted[i], truth[i], 3.0 * sd[i]) << "term " << i;
      }
    }
    for (const std::string& fixed : result.fixed_terms) {
      std::cout << c.name << ": " << fixed << '\n';
    }
    // Near the edge of where the views reach, the terms' own uncertainty (one standard
    // deviation each here) shows: the lens is compared inside 70 % of that.
    EXPECT_LT(WorstDifferenceWhereSeen(result.camera, c.lens, views, 0.7), 0.6);
    EXPECT_GT(result.visp_rms_px, result.rms_px);
    ExpectGoodFit(result, 1);  // the corners themselves are not seen, and the result says so
  }
}

TEST(Calibrate, ViewsThatFaceTheCameraAreRefusedWithWhatToDo) {
  const Lens truth = Lens::WithKdu(760.0, 755.0, 331.0, 228.0, 0.1, 640, 480);
  std::vector<vpHomogeneousMatrix> facing;
  for (int k = 0; k < 6; ++k)
    facing.push_back(LookingAtTheBoard(0.4 + 0.03 * k, 1.0, -2.0, 15.0 * k));
  const std::vector<CalibrationView> views = RenderedViews(truth, facing);
  try {
    Calibrate(views, OptionsFor(640, 480));
    FAIL() << "no error";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("Tilt the target"), std::string::npos) << error.what();
  }
}

TEST(Calibrate, TooFewUsableViewsNameEachRejectedView) {
  std::vector<CalibrationView> views(4);
  for (std::size_t k = 0; k < views.size(); ++k) views[k].name = "img" + std::to_string(k);
  views[1].points.resize(3);
  try {
    Calibrate(views, OptionsFor(640, 480));
    FAIL() << "no error";
  } catch (const std::runtime_error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("0 usable views of 4, at least 3 needed"), std::string::npos) << message;
    EXPECT_NE(message.find("img1: 3 target points"), std::string::npos) << message;
  }
  CalibrationOptions bad = OptionsFor(0, 480);
  EXPECT_THROW(Calibrate(views, bad), std::invalid_argument);
}

TEST(FindChessboard, NoBoardNoView) {
  vpImage<unsigned char> blank(480, 640, 200);
  EXPECT_FALSE(FindChessboard(ViewOf(blank), ChessboardOptions(), "blank").has_value());
  ChessboardOptions bad;
  bad.square_m = 0.0;
  EXPECT_THROW(FindChessboard(ViewOf(blank), bad, "blank"), std::invalid_argument);
}

// OpenCV's own sample views (Debian's opencv-doc: left01-14.jpg, a 9 x 6 chessboard of 25 mm
// squares): ours against OpenCV's calibrateCamera with its default model on the same corners.
TEST(Calibrate, OpenCvsSampleViewsAgreeWithCalibrateCamera) {
  const std::string dir = "/usr/share/doc/opencv-doc/examples/data/";
  std::vector<CalibrationView> views;
  ChessboardOptions chessboard;
  chessboard.columns = 9;
  chessboard.rows = 6;
  chessboard.square_m = 0.025;
  for (int k = 1; k <= 14; ++k) {
    const std::string name = dir + "left" + (k < 10 ? "0" : "") + std::to_string(k) + ".jpg";
    if (!std::filesystem::exists(name)) continue;  // the package has no left10.jpg
    vpImage<unsigned char> image;
    vpImageIo::read(image, name);
    if (std::optional<CalibrationView> view = FindChessboard(ViewOf(image), chessboard, name)) {
      views.push_back(*view);
    }
  }
  if (views.empty()) GTEST_SKIP() << "Debian's opencv-doc (its sample views) is not installed";
  ASSERT_EQ(views.size(), 13u);
  const CalibrationResult ours = Calibrate(views, OptionsFor(640, 480));

  std::vector<std::vector<cv::Point3f>> object;
  std::vector<std::vector<cv::Point2f>> image;
  for (const CalibrationView& view : views) {
    object.emplace_back();
    image.emplace_back();
    for (const CalibrationPoint& p : view.points) {
      object.back().emplace_back(static_cast<float>(p.x), static_cast<float>(p.y), 0.0f);
      image.back().emplace_back(static_cast<float>(p.u), static_cast<float>(p.v));
    }
  }
  cv::Mat k, d, sd, sd_extrinsics, errors;
  std::vector<cv::Mat> rvecs, tvecs;
  const double rms = cv::calibrateCamera(object, image, cv::Size(640, 480), k, d, rvecs, tvecs, sd,
                                         sd_extrinsics, errors);
  const Lens& lens = ours.camera;
  const double mine[] = {lens.px(), lens.py(), lens.u0(), lens.v0()};
  for (int i = 0; i < 4; ++i) {
    const double reference = i < 2 ? k.at<double>(i, i) : k.at<double>(i - 2, 2);
    EXPECT_NEAR(mine[i], reference, 2.0 * sd.at<double>(i)) << "intrinsic " << i;
  }
  const auto coefficients = lens.distortion().ToArray();
  for (int i = 0; i < 5; ++i) {
    // A term ours fixed at zero: OpenCV's is within two of its deviations of zero too.
    EXPECT_NEAR(coefficients[static_cast<std::size_t>(i)], d.at<double>(i),
                2.0 * sd.at<double>(4 + i))
        << "coefficient " << i;
  }
  EXPECT_NEAR(ours.rms_px, rms, 0.02 * rms);
  std::cout << "ours px " << lens.px() << " u0 " << lens.u0() << " k1 " << coefficients[0]
            << " RMS " << ours.rms_px << "; calibrateCamera px " << k.at<double>(0, 0) << " u0 "
            << k.at<double>(0, 2) << " k1 " << d.at<double>(0) << " RMS " << rms << '\n';
}

}  // namespace
}  // namespace oal
