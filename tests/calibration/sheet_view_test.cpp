// Calibration from the printed four-line sheet (calibration/sheet_view.h, calibration/calibrate.h):
// the points seen along each stripe, projected through a known lens, give the lens back; the
// points that are not a stripe's own are left out; views that cannot place their lines on the
// plane are refused with the reason.
#include "calibration/sheet_view.h"

#include <gtest/gtest.h>
#include <visp3/core/vpMath.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "calibration/calibrate.h"
#include "detector/lens.h"
#include "target/line_target.h"
#include "tests/calibration/sheet_views.h"

namespace oal {
namespace {

using test::LookingAtTheSheet;
using test::SeenAlongStripes;
using test::VariedSheetPoses;

CalibrationOptions Options640x480() {
  CalibrationOptions options;
  options.width = 640;
  options.height = 480;
  return options;
}

TEST(SheetView, KeepsEachStripesOwnPointsAndLeavesOutTheCrossingsAndSpecks) {
  const LineTarget target = FourLineA3Target();
  const Lens camera = Lens::WithKdu(700.0, 700.0, 320.0, 240.0, 0.0, 640, 480);
  std::mt19937 random(1);
  std::vector<std::vector<Point2d>> seen =
      SeenAlongStripes(target, camera, LookingAtTheSheet(0.5, 15.0, -10.0, 20.0), 0.0, &random);
  const std::size_t first_stripe_points = seen[0].size();
  // A speck beside stripe 0, 3 cm off it on the plane: about 40 px at this distance.
  Point2d speck = seen[0][seen[0].size() / 4];
  speck.u += 40.0;
  seen[0].push_back(speck);
  const CalibrationView view = SheetView(target, seen, "shot.png");
  EXPECT_EQ(view.name, "shot.png");
  ASSERT_EQ(view.lines.size(), 4u);
  EXPECT_TRUE(view.points.empty());
  // Around each of its two crossings stripe 0 loses the points within the other stripe's
  // half width plus 8 mm, about 3 cm of its length (7 points); the speck goes too.
  EXPECT_LT(view.lines[0].seen.size(), first_stripe_points - 4);
  EXPECT_GT(view.lines[0].seen.size(), first_stripe_points / 2);
  for (const Point2d& p : view.lines[0].seen) {
    EXPECT_FALSE(p.u == speck.u && p.v == speck.v) << "the speck was kept";
  }
  EXPECT_DOUBLE_EQ(view.lines[0].x, target.lines[0].x1_m);
  EXPECT_DOUBLE_EQ(view.lines[0].dy, target.lines[0].y2_m - target.lines[0].y1_m);
}

TEST(SheetView, FewerThanFourCrossingsGiveAViewWithoutLines) {
  const LineTarget target = FourLineA3Target();
  const Lens camera = Lens::WithKdu(700.0, 700.0, 320.0, 240.0, 0.0, 640, 480);
  std::mt19937 random(2);
  std::vector<std::vector<Point2d>> seen =
      SeenAlongStripes(target, camera, LookingAtTheSheet(0.5, 20.0, 0.0, 0.0), 0.1, &random);
  seen[3].clear();  // three stripes of the '#' cross in two points
  EXPECT_TRUE(SheetView(target, seen, "three.png").lines.empty());
  SheetViewOptions bad;
  bad.min_points_per_stripe = 1;
  EXPECT_THROW(SheetView(target, seen, "x", bad), std::invalid_argument);
}

TEST(CalibrateFromTheSheet, RecoversTheIntrinsicsAndTheLensFromTheStripes) {
  const std::vector<std::pair<LineTarget, double>> cases = {{FourLineA3Target(), 0.3},
                                                            {FourLineA4Target(), 0.0}};
  for (const auto& [target, kdu] : cases) {
    SCOPED_TRACE(target.name + ", kdu " + std::to_string(kdu));
    const Lens truth = Lens::WithKdu(720.0, 716.0, 333.0, 229.0, kdu, 640, 480);
    const double scale = target.board_width_m / 0.42;  // the A4 sheet is seen from nearer
    std::mt19937 random(7);
    std::vector<CalibrationView> views;
    for (const vpHomogeneousMatrix& pose : VariedSheetPoses()) {
      vpHomogeneousMatrix cMo = pose;
      cMo[2][3] *= scale;
      views.push_back(SheetView(target, SeenAlongStripes(target, truth, cMo, 0.2, &random),
                                "view" + std::to_string(views.size())));
    }
    const CalibrationResult result = Calibrate(views, Options640x480());
    EXPECT_NEAR(result.camera.px(), truth.px(), 0.003 * truth.px());
    EXPECT_NEAR(result.camera.py(), truth.py(), 0.003 * truth.py());
    EXPECT_NEAR(result.camera.u0(), truth.u0(), 1.5);
    EXPECT_NEAR(result.camera.v0(), truth.v0(), 1.5);
    // The lens in the middle of the image, where the views' stripes run.
    EXPECT_LT(WorstIdealPixelDifference(result.camera, truth, 640, 480, 200.0), 0.3);
    EXPECT_LT(result.rms_px, 0.3);
    for (const CalibrationViewReport& view : result.views) {
      EXPECT_TRUE(view.used) << view.name << ": " << view.rejected;
    }
  }
}

TEST(CalibrateFromTheSheet, ExactPointsOnTheStripesGiveAStrongLensExactly) {
  // The points slide along their lines freely: the fit settles where the lines' distances
  // are least, not where a pairing with plane points stopped creeping.
  const LineTarget target = FourLineA3Target();
  const Lens truth =
      Lens::WithDistortion(535.9157, 535.9157, 342.2832, 235.5708,
                           {-0.266373, -0.0385889, 0.00178319, -0.000281221, 0.238392});
  std::mt19937 random(4);
  std::vector<CalibrationView> views;
  for (const vpHomogeneousMatrix& pose : VariedSheetPoses()) {
    views.push_back(SheetView(target, SeenAlongStripes(target, truth, pose, 0.0, &random),
                              "view" + std::to_string(views.size())));
  }
  CalibrationOptions options = Options640x480();
  options.min_term_significance = 0.0;  // keep every term: the points are exact
  const CalibrationResult result = Calibrate(views, options);
  EXPECT_NEAR(result.camera.px(), truth.px(), 1e-4 * truth.px());
  EXPECT_NEAR(result.camera.u0(), truth.u0(), 0.05);
  EXPECT_LT(result.rms_px, 1e-3);
  EXPECT_LT(WorstIdealPixelDifference(result.camera, truth, 640, 480, 200.0), 0.01);
}

TEST(CalibrateFromTheSheet, RunsMiddlesAreMovedOntoTheCentreLineThroughTheLens) {
  // Under perspective and a strong lens the middle of a run between a stripe's two edges is
  // off the centre line's image; given the runs, the calibration moves each middle back
  // through the lens it solves, and leaves out the runs through a stripe's ends.
  const LineTarget target = FourLineA3Target();
  const Lens truth =
      Lens::WithDistortion(535.9157, 535.9157, 342.2832, 235.5708,
                           {-0.266373, -0.0385889, 0.00178319, -0.000281221, 0.238392});
  CalibrationOptions options = Options640x480();
  options.min_term_significance = 0.0;
  std::vector<CalibrationView> with_runs, middles_alone;
  for (const vpHomogeneousMatrix& pose : VariedSheetPoses()) {
    std::vector<std::vector<Point2d>> runs;
    const std::vector<std::vector<Point2d>> middles =
        test::RunsAcrossStripes(target, truth, pose, &runs, 0.015);
    const std::string name = "view" + std::to_string(with_runs.size());
    with_runs.push_back(SheetView(target, middles, name, SheetViewOptions(), runs));
    middles_alone.push_back(SheetView(target, middles, name));
  }
  ASSERT_FALSE(with_runs[0].lines.empty());
  EXPECT_GT(with_runs[0].lines[0].width_m, 0.0);
  EXPECT_EQ(with_runs[0].lines[0].runs.size(), with_runs[0].lines[0].seen.size());
  const CalibrationResult centred = Calibrate(with_runs, options);
  const CalibrationResult uncentred = Calibrate(middles_alone, options);
  const double centred_error = std::fabs(centred.camera.px() - truth.px());
  EXPECT_LT(centred_error, 2e-4 * truth.px());
  EXPECT_LT(WorstIdealPixelDifference(centred.camera, truth, 640, 480, 200.0), 0.02);
  // The middles taken as centre-line points (and the runs through the ends kept) bias it.
  EXPECT_GT(std::fabs(uncentred.camera.px() - truth.px()), 5.0 * centred_error);
}

TEST(CalibrateFromTheSheet, AViewWhosePointsDisagreeWithTheOthersIsLeftOut) {
  const LineTarget target = FourLineA3Target();
  const Lens truth = Lens::WithKdu(720.0, 716.0, 333.0, 229.0, 0.15, 640, 480);
  std::mt19937 random(9);
  std::vector<CalibrationView> views;
  for (const vpHomogeneousMatrix& pose : VariedSheetPoses()) {
    views.push_back(SheetView(target, SeenAlongStripes(target, truth, pose, 0.2, &random),
                              "view" + std::to_string(views.size())));
  }
  // A sheet printed stretched (a printer's "fit to page" on one axis): its vertical stripes
  // are 8 % farther apart than the target says, which no camera pose explains.
  LineTarget larger = target;
  for (TargetLine& line : larger.lines) line.x1_m *= 1.08, line.x2_m *= 1.08;
  views.push_back(SheetView(
      target,
      SeenAlongStripes(larger, truth, LookingAtTheSheet(0.45, 30.0, 10.0, 50.0), 0.2, &random),
      "scaled.png"));
  const CalibrationResult result = Calibrate(views, Options640x480());
  ASSERT_EQ(result.views.size(), 13u);
  EXPECT_FALSE(result.views.back().used);
  EXPECT_NE(result.views.back().rejected.find("its points disagree with the other views'"),
            std::string::npos)
      << result.views.back().rejected;
  EXPECT_NEAR(result.camera.px(), truth.px(), 0.003 * truth.px());
  EXPECT_LT(WorstIdealPixelDifference(result.camera, truth, 640, 480, 200.0), 0.3);
}

// A lens about 100 degrees across and views of the sheet in the image's corners, as the
// calibration's advice asks: before the lens has settled, a corner view fits worse than the
// others; once it has, it fits as well, and it is kept.
TEST(CalibrateFromTheSheet, ViewsInTheCornersOfAWideLensAreKept) {
  const LineTarget target = FourLineA3Target();
  Distortion barrel;
  barrel.k1 = -0.28, barrel.k2 = 0.08, barrel.p1 = 0.0006, barrel.p2 = -0.0004, barrel.k3 = -0.01;
  const Lens truth = Lens::WithDistortion(730.0, 730.0, 642.5, 357.5, barrel);
  std::mt19937 random(5);
  std::vector<CalibrationView> views;
  std::vector<vpHomogeneousMatrix> poses = VariedSheetPoses();
  for (int corner = 0; corner < 4; ++corner) {
    const double x = corner % 2 == 0 ? 0.19 : -0.19, y = corner < 2 ? 0.11 : -0.11;
    poses.push_back(vpHomogeneousMatrix(x, y, 0.0, 0.0, 0.0, 0.0) *
                    LookingAtTheSheet(0.41, 15.0 + 8.0 * corner, -10.0 * corner, 40.0 * corner));
  }
  for (const vpHomogeneousMatrix& cMo : poses) {
    views.push_back(SheetView(target, SeenAlongStripes(target, truth, cMo, 0.1, &random, 1280, 720),
                              "view" + std::to_string(views.size())));
  }
  CalibrationOptions options;
  options.width = 1280;
  options.height = 720;
  const CalibrationResult result = Calibrate(views, options);
  for (const CalibrationViewReport& view : result.views) {
    EXPECT_TRUE(view.used) << view.name << ": " << view.rejected;
  }
  EXPECT_NEAR(result.camera.px(), truth.px(), 0.001 * truth.px());
  EXPECT_NEAR(result.camera.u0(), truth.u0(), 0.5);
  EXPECT_NEAR(result.camera.v0(), truth.v0(), 0.5);
}

TEST(CalibrateFromTheSheet, AViewWhoseLinesCannotBePlacedIsRefusedWithTheReason) {
  const LineTarget target = FourLineA3Target();
  CalibrationView view{"two-stripes.png", {}, {}};
  for (std::size_t k = 0; k < 2; ++k) {
    CalibrationLine line;
    line.x = target.lines[k].x1_m;
    line.y = target.lines[k].y1_m;
    line.dx = target.lines[k].x2_m - target.lines[k].x1_m;
    line.dy = target.lines[k].y2_m - target.lines[k].y1_m;
    for (int i = 0; i < 20; ++i) line.seen.push_back(Point2d{100.0 + 10.0 * i, 50.0 + 3.0 * k});
    view.lines.push_back(line);
  }
  try {
    Calibrate({view, view, view}, Options640x480());
    FAIL() << "no error";
  } catch (const std::runtime_error& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("0 usable views of 3"), std::string::npos) << message;
    EXPECT_NE(message.find("two-stripes.png: fewer than four of its lines' crossings"),
              std::string::npos)
        << message;
  }
}

}  // namespace
}  // namespace oal
