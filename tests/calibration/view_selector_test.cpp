// Which frames become calibration views (calibration/view_selector.h): a target that holds
// still and stands apart from the views taken is taken once; one that moves, or repeats a
// view, or is not placed, is not.
#include "calibration/view_selector.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <stdexcept>
#include <vector>

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

// The view with each line's points kept only over the middle `fraction` of the stretch seen.
CalibrationView MiddleOfEachLine(CalibrationView view, double fraction) {
  for (CalibrationLine& line : view.lines) {
    if (line.seen.size() < 2) continue;
    double u0 = HUGE_VAL, u1 = -HUGE_VAL, v0 = HUGE_VAL, v1 = -HUGE_VAL;
    for (const Point2d& p : line.seen) {
      u0 = std::min(u0, p.u), u1 = std::max(u1, p.u), v0 = std::min(v0, p.v),
      v1 = std::max(v1, p.v);
    }
    const bool along_u = u1 - u0 >= v1 - v0;
    const double lo = along_u ? u0 : v0, hi = along_u ? u1 : v1;
    const double keep_lo = lo + 0.5 * (1.0 - fraction) * (hi - lo);
    const double keep_hi = hi - 0.5 * (1.0 - fraction) * (hi - lo);
    std::vector<Point2d> kept, kept_runs;
    for (std::size_t i = 0; i < line.seen.size(); ++i) {
      const double at = along_u ? line.seen[i].u : line.seen[i].v;
      if (at < keep_lo || at > keep_hi) continue;
      kept.push_back(line.seen[i]);
      if (i < line.runs.size()) kept_runs.push_back(line.runs[i]);
    }
    line.seen = std::move(kept);
    if (!line.runs.empty()) line.runs = std::move(kept_runs);
  }
  return view;
}

// The A3 sheet's view from cMo through `lens`, its stripes' points with 0.05 px of noise.
CalibrationView SheetSeenThrough(const Lens& lens, const vpHomogeneousMatrix& cMo,
                                 std::mt19937* random) {
  const LineTarget target = FourLineA3Target();
  return SheetView(target, SeenAlongStripes(target, lens, cMo, 0.05, random), "frame");
}

// Through a lens that bends the stripes (kdu 0.25), a still sheet seen over all of its stripes
// in one frame and over their middle halves in the next: the straight lines through the
// points, and the outline they give, move by pixels; the stripes do not, and the target counts
// as still. Turned by half a degree, or moved by two pixels, it has moved.
TEST(TargetMotion, IsTheStripesNotTheStretchesSeen) {
  const Lens bending = Lens::WithKdu(690.0, 694.0, 331.0, 232.0, 0.25, 640, 480);
  std::mt19937 random(5);
  const vpHomogeneousMatrix pose = LookingAtTheSheet(0.45, 25.0, -10.0, 20.0);
  const auto view_at = [&](const vpHomogeneousMatrix& cMo) {
    return SheetSeenThrough(bending, cMo, &random);
  };
  const CalibrationView whole = view_at(pose);
  const CalibrationView middle = MiddleOfEachLine(view_at(pose), 0.5);
  const auto outline_whole = TargetOutline(whole), outline_middle = TargetOutline(middle);
  ASSERT_TRUE(outline_whole && outline_middle);
  double outline_moved = 0.0;
  for (std::size_t k = 0; k < 4; ++k) {
    outline_moved =
        std::max(outline_moved, std::hypot((*outline_whole)[k].u - (*outline_middle)[k].u,
                                           (*outline_whole)[k].v - (*outline_middle)[k].v));
  }
  EXPECT_GT(outline_moved, 1.5);  // what made a still sheet look moving
  for (const auto& [from, to] : {std::pair{whole, middle}, std::pair{middle, whole}}) {
    const std::optional<double> still = TargetMotion(from, to, 6.0);
    ASSERT_TRUE(still);
    EXPECT_LT(*still, 0.5);
  }
  const vpHomogeneousMatrix turned =
      pose * vpHomogeneousMatrix(0.0, 0.0, 0.0, 0.0, 0.0, vpMath::rad(0.5));
  const vpHomogeneousMatrix shifted = vpHomogeneousMatrix(0.0013, 0.0, 0.0, 0.0, 0.0, 0.0) * pose;
  for (const vpHomogeneousMatrix& moved_pose : {turned, shifted}) {
    const std::optional<double> moved = TargetMotion(whole, view_at(moved_pose), 6.0);
    ASSERT_TRUE(moved);
    EXPECT_GT(*moved, 1.5);
  }
  EXPECT_FALSE(TargetMotion(whole, CalibrationView{"blank", {}, {}}, 6.0));
}

// A still sheet whose next view also holds runs cut short at one stripe's printed end (their
// middles 2-8 px off the stripe, at one end of it: a scan route the last frame did not take)
// is still; moved by two pixels with those runs, it has moved.
TEST(TargetMotion, LeavesOutRunsCutShortAtAStripesEnd) {
  const Lens bending = Lens::WithKdu(690.0, 694.0, 331.0, 232.0, 0.2, 640, 480);
  std::mt19937 random(7);
  const vpHomogeneousMatrix pose = LookingAtTheSheet(0.45, 25.0, -10.0, 20.0);
  const auto view_at = [&](const vpHomogeneousMatrix& cMo) {
    return SheetSeenThrough(bending, cMo, &random);
  };
  const auto with_cut_runs = [](CalibrationView view) {
    std::vector<Point2d>& seen = view.lines.front().seen;
    const auto [first, last] = std::minmax_element(
        seen.begin(), seen.end(), [](const Point2d& a, const Point2d& b) { return a.u < b.u; });
    const Point2d end = *last;
    const double du = last->u - first->u, dv = last->v - first->v, length = std::hypot(du, dv);
    for (int k = 0; k < 10; ++k) {
      // Along the stripe towards its end, further off the nearer the end.
      const double along = -1.0 * k, off = -(2.0 + 0.6 * (9 - k));
      seen.push_back(
          {end.u + (along * du - off * dv) / length, end.v + (along * dv + off * du) / length});
    }
    return view;
  };
  const CalibrationView before = view_at(pose);
  const std::optional<double> still = TargetMotion(before, with_cut_runs(view_at(pose)), 6.0);
  ASSERT_TRUE(still);
  EXPECT_LT(*still, 0.5);
  const std::optional<double> back = TargetMotion(with_cut_runs(view_at(pose)), before, 6.0);
  ASSERT_TRUE(back);
  EXPECT_LT(*back, 0.5);
  const vpHomogeneousMatrix shifted = vpHomogeneousMatrix(0.0013, 0.0, 0.0, 0.0, 0.0, 0.0) * pose;
  const std::optional<double> moved = TargetMotion(before, with_cut_runs(view_at(shifted)), 6.0);
  ASSERT_TRUE(moved);
  EXPECT_GT(*moved, 1.5);
}

TEST_F(ViewSelectorTest, AStillTargetSeenOverChangingStretchesIsTaken) {
  ViewSelectorOptions options;
  options.still_frames = 4;
  ViewSelector selector(640, 480, options);
  const vpHomogeneousMatrix pose = LookingAtTheSheet(0.45, 25.0, -10.0, 20.0);
  EXPECT_EQ(selector.Offer(ViewFrom(pose)), Verdict::kMoving);
  EXPECT_EQ(selector.Offer(MiddleOfEachLine(ViewFrom(pose), 0.6)), Verdict::kMoving);
  EXPECT_EQ(selector.Offer(ViewFrom(pose)), Verdict::kMoving);
  EXPECT_EQ(selector.Offer(MiddleOfEachLine(ViewFrom(pose), 0.5)), Verdict::kTaken);
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
