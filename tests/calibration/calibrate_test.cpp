// Camera calibration (calibration/calibrate.h) from chessboard views rendered through a known
// lens: the intrinsics and ViSP's distortion come back; views that cannot determine the
// camera are refused with the reason.
#include "calibration/calibrate.h"

#include <gtest/gtest.h>
#include <visp3/core/vpMath.h>

#include <cmath>
#include <iostream>
#include <memory>
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

TEST(Calibrate, RecoversTheIntrinsicsAndViSPsDistortionFromChessboardViews) {
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
    EXPECT_NEAR(result.camera.kdu(), kdu, std::max(0.03 * kdu, 0.005));
    // kud is the best single-term inverse over the part of the image the views cover (the
    // truth's over the whole image differs by a few %): the two directions agree there, to
    // what two single terms can (under a pixel at kdu 0.35).
    const Lens& camera = result.camera;
    for (double u = 120.0; u <= 520.0; u += 50.0) {
      for (double v = 60.0; v <= 420.0; v += 45.0) {
        const double xd = (u - camera.u0()) / camera.px();
        const double yd = (v - camera.v0()) / camera.py();
        const double grow = 1.0 + camera.kdu() * (xd * xd + yd * yd);
        const double xu = xd * grow, yu = yd * grow;
        const double shrink = 1.0 + camera.kud() * (xu * xu + yu * yu);
        EXPECT_NEAR(camera.u0() + camera.px() * xu * shrink, u, 1.0) << u << ", " << v;
        EXPECT_NEAR(camera.v0() + camera.py() * yu * shrink, v, 1.0) << u << ", " << v;
      }
    }
    EXPECT_LT(result.rms_px, 0.2);
    std::cout << "kdu " << kdu << ": px " << result.camera.px() << " py " << result.camera.py()
              << " u0 " << result.camera.u0() << " v0 " << result.camera.v0() << " kdu "
              << result.camera.kdu() << " RMS " << result.rms_px << " px\n";
    for (const std::string& advice : result.advice) ADD_FAILURE() << advice;
    for (const CalibrationViewReport& view : result.views) {
      if (view.used) {
        EXPECT_LT(view.rms_px, 0.3) << view.name;
      }
    }
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

TEST(FitViSPDistortion, OneTermLensesComeBackAsThemselves) {
  // A lens that is exactly one kud term: kud comes back, and kdu is its best inverse: larger
  // than -kud, as the inverse series' next term (3 kud^2 r^4) is positive.
  const RadialFit fit =
      FitViSPDistortion(RadialDistortion{-0.2, 0.0, 0.0}, 700, 700, 320, 240, 640, 480);
  EXPECT_NEAR(fit.kud, -0.2, 1e-9);
  EXPECT_GT(fit.kdu, 0.2);
  EXPECT_LT(fit.kdu, 0.25);
  const RadialFit none = FitViSPDistortion(RadialDistortion{}, 700, 700, 320, 240, 640, 480);
  EXPECT_EQ(none.kud, 0.0);
  EXPECT_EQ(none.kdu, 0.0);
}

TEST(FindChessboard, NoBoardNoView) {
  vpImage<unsigned char> blank(480, 640, 200);
  EXPECT_FALSE(FindChessboard(ViewOf(blank), ChessboardOptions(), "blank").has_value());
  ChessboardOptions bad;
  bad.square_m = 0.0;
  EXPECT_THROW(FindChessboard(ViewOf(blank), bad, "blank"), std::invalid_argument);
}

}  // namespace
}  // namespace oal
