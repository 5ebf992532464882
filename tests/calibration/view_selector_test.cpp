// Which frames become calibration views (calibration/view_selector.h): a target that holds
// still and stands apart from the views taken is taken once; one that moves, or repeats a
// view, or is not placed, is not.
#include "calibration/view_selector.h"

#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

#include "calibration/sheet_view.h"
#include "target/line_target.h"
#include "tests/calibration/sheet_views.h"

namespace oal {
namespace {

using test::LookingAtTheSheet;
using test::SeenAlongStripes;
using Verdict = ViewSelector::Verdict;

class ViewSelectorTest : public ::testing::Test {
 protected:
  CalibrationView ViewFrom(const vpHomogeneousMatrix& cMo) {
    return SheetView(target_, SeenAlongStripes(target_, camera_, cMo, 0.3, &random_), "frame");
  }

  const LineTarget target_ = FourLineA3Target();
  const Lens camera_ = Lens::WithKdu(700.0, 700.0, 320.0, 240.0, 0.1, 640, 480);
  std::mt19937 random_{3};
};

TEST_F(ViewSelectorTest, AStillTargetIsTakenOnceAfterHoldingStill) {
  ViewSelectorOptions options;
  options.still_frames = 4;
  ViewSelector selector(640, 480, options);
  const vpHomogeneousMatrix pose = LookingAtTheSheet(0.5, 20.0, 10.0, 5.0);
  EXPECT_EQ(selector.Offer(ViewFrom(pose)), Verdict::kMoving);
  EXPECT_EQ(selector.Offer(ViewFrom(pose)), Verdict::kMoving);
  EXPECT_EQ(selector.Offer(ViewFrom(pose)), Verdict::kMoving);
  EXPECT_EQ(selector.Offer(ViewFrom(pose)), Verdict::kTaken);
  EXPECT_EQ(selector.taken(), 1);
  // Still there: the same view again is not taken twice.
  EXPECT_EQ(selector.Offer(ViewFrom(pose)), Verdict::kTooLike);
  EXPECT_EQ(selector.similar_to(), 0);
  EXPECT_EQ(selector.taken(), 1);
}

TEST_F(ViewSelectorTest, AMovingTargetIsNotTaken) {
  ViewSelector selector(640, 480);
  for (int k = 0; k < 20; ++k) {
    // Turning by half a degree a frame moves the outline's corners by a few pixels.
    EXPECT_EQ(selector.Offer(ViewFrom(LookingAtTheSheet(0.5, 20.0, 10.0, 0.5 * k))),
              Verdict::kMoving)
        << k;
  }
  EXPECT_EQ(selector.taken(), 0);
}

TEST_F(ViewSelectorTest, ANewPoseIsTakenAndALostTargetStartsOver) {
  ViewSelectorOptions options;
  options.still_frames = 2;
  ViewSelector selector(640, 480, options);
  const vpHomogeneousMatrix first = LookingAtTheSheet(0.5, 20.0, 10.0, 5.0);
  const vpHomogeneousMatrix second = LookingAtTheSheet(0.45, -25.0, 5.0, 40.0);
  selector.Offer(ViewFrom(first));
  ASSERT_EQ(selector.Offer(ViewFrom(first)), Verdict::kTaken);
  EXPECT_EQ(selector.Offer(CalibrationView{"blank", {}, {}}), Verdict::kNoTarget);
  EXPECT_EQ(selector.Offer(ViewFrom(second)), Verdict::kMoving);  // after a frame without it
  EXPECT_EQ(selector.Offer(ViewFrom(second)), Verdict::kTaken);
  EXPECT_EQ(selector.taken(), 2);
  // Back to the first pose: too like view 0.
  selector.Offer(ViewFrom(first));
  EXPECT_EQ(selector.Offer(ViewFrom(first)), Verdict::kTooLike);
  EXPECT_EQ(selector.similar_to(), 0);
}

TEST(TargetOutline, IsTheSheetsInkSeenThroughTheView) {
  const LineTarget target = FourLineA3Target();
  const Lens pinhole = Lens::WithKdu(700.0, 700.0, 320.0, 240.0, 0.0, 640, 480);
  std::mt19937 random(1);
  const CalibrationView view = SheetView(
      target,
      SeenAlongStripes(target, pinhole, LookingAtTheSheet(0.6, 0.0, 0.0, 0.0), 0.0, &random),
      "facing");
  const auto outline = TargetOutline(view);
  ASSERT_TRUE(outline);
  // The stripes' ends span 0.40 x 0.277 m: 467 x 323 px at 0.6 m, centred on (320, 240).
  EXPECT_NEAR((*outline)[0].u, 320.0 - 0.5 * 0.400 * 700.0 / 0.6, 1.0);
  EXPECT_NEAR((*outline)[0].v, 240.0 - 0.5 * 0.277 * 700.0 / 0.6, 1.0);
  EXPECT_NEAR((*outline)[2].u, 320.0 + 0.5 * 0.400 * 700.0 / 0.6, 1.0);
  EXPECT_NEAR((*outline)[2].v, 240.0 + 0.5 * 0.277 * 700.0 / 0.6, 1.0);
  EXPECT_FALSE(TargetOutline(CalibrationView{"blank", {}, {}}));
}

TEST(ViewSelector, BadOptionsAreNamed) {
  ViewSelectorOptions options;
  options.still_frames = 0;
  try {
    ViewSelector selector(640, 480, options);
    FAIL() << "no error";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("still_frames"), std::string::npos) << error.what();
  }
  EXPECT_THROW(ViewSelector(0, 480), std::invalid_argument);
}

}  // namespace
}  // namespace oal
