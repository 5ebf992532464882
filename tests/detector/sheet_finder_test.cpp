// The sheet finder on rendered sheets: the '#'s middle cell is found, closed in on its four
// sides, and refined onto the stripes' inner edges; nothing of the kind in a frame without it.
#include "detector/sheet_finder.h"

#include <gtest/gtest.h>
#include <visp3/core/vpHomogeneousMatrix.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "base/angles.h"
#include "scene/scene.h"

namespace oal {
namespace {

// The middle cell of a '#' target whose lines 1 and 3 run along y and 2 and 4 along x (the
// built-in sheets): between the stripes' inner edges, object frame.
std::array<Point2d, 4> MiddleCell(const LineTarget& target) {
  const TargetLine& l1 = target.lines[0];
  const TargetLine& l2 = target.lines[1];
  const TargetLine& l3 = target.lines[2];
  const TargetLine& l4 = target.lines[3];
  const double x0 = l1.x1_m + 0.5 * l1.width_m, x1 = l3.x1_m - 0.5 * l3.width_m;
  const double y0 = l2.y1_m + 0.5 * l2.width_m, y1 = l4.y1_m - 0.5 * l4.width_m;
  return {Point2d{x0, y0}, Point2d{x1, y0}, Point2d{x1, y1}, Point2d{x0, y1}};
}

Point2d Image(const vpHomogeneousMatrix& cMo, const Lens& camera, const Point2d& p) {
  const double x = cMo[0][0] * p.u + cMo[0][1] * p.v + cMo[0][3];
  const double y = cMo[1][0] * p.u + cMo[1][1] * p.v + cMo[1][3];
  const double z = cMo[2][0] * p.u + cMo[2][1] * p.v + cMo[2][3];
  return camera.Pixel(x / z, y / z);
}

// The largest distance of quad's corners from the middle cell's image, in the best cyclic
// order.
double CornerError(const LightQuad& quad, const LineTarget& target, const vpHomogeneousMatrix& cMo,
                   const Lens& camera) {
  const std::array<Point2d, 4> cell = MiddleCell(target);
  double best_error = HUGE_VAL;
  for (int shift = 0; shift < 4; ++shift) {
    double error = 0.0;
    for (int k = 0; k < 4; ++k) {
      const Point2d& a = quad.corners[static_cast<std::size_t>(k)];
      const Point2d b = Image(cMo, camera, cell[static_cast<std::size_t>((k + shift) % 4)]);
      error = std::max(error, std::hypot(a.u - b.u, a.v - b.v));
    }
    best_error = std::min(best_error, error);
  }
  return best_error;
}

struct SheetCase {
  const char* target;
  double distance_m, roll_deg, tilt_deg;
  int background_grey;
};

class SheetFinderOnRenderedSheets : public ::testing::TestWithParam<SheetCase> {};

TEST_P(SheetFinderOnRenderedSheets, FindsTheMiddleCellClosedInAndRefinesItOntoTheStripes) {
  const SheetCase param = GetParam();
  RenderOptions render;
  render.camera = Lens::WithKdu(600, 600, 319.5, 239.5, 0.15, 640, 480);
  render.noise_sigma = 5.0;
  render.blur_sigma_px = 1.0;
  render.illumination_gradient = 0.2;
  render.background_grey = param.background_grey;
  const LineTarget target = TargetByName(param.target);
  const SceneRenderer renderer(target, render);
  const vpHomogeneousMatrix cMo(0.01, -0.01, param.distance_m, param.tilt_deg * kRadPerDeg, 0.0,
                                param.roll_deg * kRadPerDeg);
  const RenderedFrame frame = renderer.Render(cMo, 7);

  SheetFinder finder;
  const std::vector<LightQuad>& found = finder.Find(ViewOf(frame.image));
  ASSERT_FALSE(found.empty());
  LightQuad best = found.front();
  EXPECT_EQ(best.ClosedSideCount(), 4);
  ASSERT_TRUE(finder.Refine(ViewOf(frame.image), &best));
  // Its corners are the middle cell's, in some cyclic order, within 2 px.
  EXPECT_LT(CornerError(best, target, cMo, render.camera), 2.0)
      << param.target << " at " << param.distance_m << " m";
}

INSTANTIATE_TEST_SUITE_P(Sheets, SheetFinderOnRenderedSheets,
                         ::testing::Values(SheetCase{"four-line-a3", 0.5, 0.0, 0.0, 90},
                                           SheetCase{"four-line-a3", 0.8, 35.0, 20.0, 90},
                                           SheetCase{"four-line-a3", 0.35, 200.0, 25.0, 60},
                                           SheetCase{"four-line-a4", 0.4, 120.0, 15.0,
                                                     170},  // a light bench
                                           SheetCase{"four-line-a4", 0.55, 300.0, 28.0, 30},
                                           SheetCase{"four-line-letter", 0.45, 80.0, 10.0, 120}));

// Whether the finder's candidates (its first pass, then FindLocallyLight's) hold the middle
// cell closed in on three sides or more (what the target tracker scans), refined within 2 px
// of it.
bool FindsTheMiddleCell(const RenderedFrame& frame, const LineTarget& target, const Lens& camera,
                        const SheetFinderOptions& options = {}) {
  SheetFinder finder(options);
  const GrayImageView view = ViewOf(frame.image);
  std::vector<LightQuad> candidates = finder.Find(view);
  const std::vector<LightQuad>& more = finder.FindLocallyLight(view);
  candidates.insert(candidates.end(), more.begin(), more.end());
  return std::any_of(candidates.begin(), candidates.end(), [&](LightQuad quad) {
    return quad.ClosedSideCount() >= 3 && finder.Refine(view, &quad) &&
           CornerError(quad, target, frame.cMo, camera) < 2.0;
  });
}

// ... and with FindFaintlyDark's last.
bool FindsTheMiddleCellAtLast(const RenderedFrame& frame, const LineTarget& target,
                              const Lens& camera) {
  SheetFinder finder;
  const GrayImageView view = ViewOf(frame.image);
  std::vector<LightQuad> candidates = finder.Find(view);
  const std::vector<LightQuad> more = finder.FindLocallyLight(view);
  candidates.insert(candidates.end(), more.begin(), more.end());
  const std::vector<LightQuad>& faint = finder.FindFaintlyDark(view);
  candidates.insert(candidates.end(), faint.begin(), faint.end());
  return std::any_of(candidates.begin(), candidates.end(), [&](LightQuad quad) {
    return quad.ClosedSideCount() >= 3 && finder.Refine(view, &quad) &&
           CornerError(quad, target, frame.cMo, camera) < 2.0;
  });
}

class SheetFinderInALivedInScene : public ::testing::Test {
 protected:
  SheetFinderInALivedInScene() : target_(TargetByName("four-line-a3")) {
    render_.camera = Lens::WithKdu(600, 600, 319.5, 239.5, 0.15, 640, 480);
    render_.noise_sigma = 4.0;
    render_.blur_sigma_px = 1.0;
    render_.background_grey = 70;
  }
  // The middle cell's corner where lines 1 and 2 cross, on the plane.
  Point2d Crossing12() const { return Point2d{target_.lines[0].x1_m, target_.lines[1].y1_m}; }
  // The sheet seen with `effects`: does the finder find its middle cell?
  bool FindsTheMiddleCellWith(const FrameEffects& effects) const {
    const vpHomogeneousMatrix cMo(0.02, 0.01, 0.5, 12.0 * kRadPerDeg, -8.0 * kRadPerDeg,
                                  30.0 * kRadPerDeg);
    return FindsTheMiddleCell(SceneRenderer(target_, render_).Render(cMo, 5, effects), target_,
                              render_.camera);
  }
  bool FindsTheMiddleCellPast(const PlaneOccluder& occluder) const {
    FrameEffects effects;
    effects.plane_occluders.push_back(occluder);
    return FindsTheMiddleCellWith(effects);
  }

  LineTarget target_;
  RenderOptions render_;
};

TEST_F(SheetFinderInALivedInScene, AGlareOverAStripeStillLeavesTheMiddleCellClosedIn) {
  // A lamp's reflection on line 2 between its crossings, saturating ink and paper alike at its
  // core, lighting the stripe around it above the first threshold: the middle cell joins the
  // cell beyond line 2 there.
  FrameEffects effects;
  effects.glares.push_back(
      {0.5 * (target_.lines[0].x1_m + target_.lines[2].x1_m), target_.lines[1].y1_m, 0.02, 400.0});
  EXPECT_TRUE(FindsTheMiddleCellWith(effects));
}

TEST_F(SheetFinderInALivedInScene, AGreyHandOverACrossingStillLeavesTheMiddleCellClosedIn) {
  // A hand lighter than ink, darker than paper, over the crossing: it bridges the middle cell
  // to the cells beyond; its own edge replaces a stretch of the cell's sides.
  PlaneOccluder hand;
  hand.grey = 150;
  hand.ellipses.push_back({Crossing12().u + 0.015, Crossing12().v + 0.01, 0.03, 0.02, 0.0});
  EXPECT_TRUE(FindsTheMiddleCellPast(hand));
}

TEST_F(SheetFinderInALivedInScene, APaleHandAcrossAStripeIsTakenAsDarkAtLast) {
  // A pale forearm a tenth darker than the paper, from the middle cell across line 2 and off
  // the sheet: light at every threshold and at 0.8 of the paper near it, it joins the middle
  // cell to the cell beyond and to itself on the bench; FindFaintlyDark's 0.9 takes it as
  // dark, and the middle cell is closed in again, on three sides at least.
  PlaneOccluder arm;
  arm.grey = 190;
  arm.capsules.push_back({0.0, -0.02, 0.04, -0.3, 0.022});
  FrameEffects effects;
  effects.plane_occluders.push_back(arm);
  const vpHomogeneousMatrix cMo(0.02, 0.01, 0.5, 12.0 * kRadPerDeg, -8.0 * kRadPerDeg,
                                30.0 * kRadPerDeg);
  const RenderedFrame frame = SceneRenderer(target_, render_).Render(cMo, 5, effects);
  EXPECT_FALSE(FindsTheMiddleCell(frame, target_, render_.camera));
  EXPECT_TRUE(FindsTheMiddleCellAtLast(frame, target_, render_.camera));
}

TEST_F(SheetFinderInALivedInScene, APenAlongASideLeavesItWhereTheStripeIs) {
  // A dark pen lying in the middle cell along line 2, a few millimetres from it, over a third
  // of the cell's width: the side's edge points there lie on the pen; the side is the line
  // most of them lie on.
  PlaneOccluder pen;
  pen.grey = 40;
  const double x = target_.lines[0].x1_m + 0.5 * target_.lines[0].width_m;
  const double y = target_.lines[1].y1_m + 0.5 * target_.lines[1].width_m + 0.007;
  pen.capsules.push_back({x + 0.02, y, x + 0.075, y, 0.003});
  EXPECT_TRUE(FindsTheMiddleCellPast(pen));
}

// Sets the pixels of [left, right) x [top, bottom) of *image to grey.
void Fill(vpImage<unsigned char>* image, int left, int top, int right, int bottom,
          unsigned char grey) {
  for (int v = top; v < bottom; ++v) {
    for (int u = left; u < right; ++u) (*image)[v][u] = grey;
  }
}

// A '#' drawn on a sheet, its upper stripe broken by a gap of paper 16 px long (a stripe washed
// out over a short stretch): the middle cell joins the cell beyond through a bridge two cells
// wide at every threshold and ratio; narrowed by one cell it stands alone again, closed in on
// four sides, and refines back onto the stripes' edges.
TEST(SheetFinder, AGapOfACellInAStripeIsClosedWhenTheCellsAreNarrowed) {
  vpImage<unsigned char> image(480, 640, 70);
  Fill(&image, 100, 60, 540, 420, 215);   // the sheet
  Fill(&image, 230, 70, 250, 410, 30);    // line 1
  Fill(&image, 392, 70, 408, 410, 30);    // line 3
  Fill(&image, 110, 163, 530, 177, 30);   // line 2
  Fill(&image, 110, 302, 530, 318, 30);   // line 4
  Fill(&image, 296, 163, 312, 177, 215);  // the gap
  const std::array<Point2d, 4> middle = {Point2d{249.5, 176.5}, Point2d{391.5, 176.5},
                                         Point2d{391.5, 301.5}, Point2d{249.5, 301.5}};
  const auto is_middle = [&](LightQuad quad, const SheetFinder& finder) {
    if (quad.ClosedSideCount() < 4 || !finder.Refine(ViewOf(image), &quad)) return false;
    for (const Point2d& corner : quad.corners) {
      const bool near = std::any_of(middle.begin(), middle.end(), [&](const Point2d& m) {
        return std::hypot(corner.u - m.u, corner.v - m.v) < 1.5;
      });
      if (!near) return false;
    }
    return true;
  };
  SheetFinder finder;
  const GrayImageView view = ViewOf(image);
  const auto holds_middle = [&](const std::vector<LightQuad>& found) {
    return std::any_of(found.begin(), found.end(),
                       [&](const LightQuad& quad) { return is_middle(quad, finder); });
  };
  EXPECT_FALSE(holds_middle(finder.Find(view)));
  EXPECT_FALSE(holds_middle(finder.FindLocallyLight(view)));
  EXPECT_FALSE(holds_middle(finder.FindFaintlyDark(view)));
  const std::vector<LightQuad>& narrowed = finder.FindNarrowed(view);
  EXPECT_TRUE(std::any_of(narrowed.begin(), narrowed.end(),
                          [&](const LightQuad& quad) { return is_middle(quad, finder); }));
}

// An over-exposed '#' (paper and a glare clip at 255 alike) on a bench of grey 120, whose sheet
// runs out of the image at the bottom, its lower left crossing washed out by a glare eleven
// cells across.
vpImage<unsigned char> ClippedSheetWithAGlare() {
  vpImage<unsigned char> image(480, 640, 120);
  Fill(&image, 100, 60, 540, 480, 255);  // the sheet, out of view at the bottom
  Fill(&image, 230, 70, 250, 480, 30);   // line 1
  Fill(&image, 392, 70, 408, 480, 30);   // line 3
  Fill(&image, 110, 163, 530, 177, 30);  // line 2
  Fill(&image, 110, 302, 530, 318, 30);  // line 4
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      if (std::hypot(u - 240.0, v - 310.0) < 44.0) image[v][u] = 255;  // the glare
    }
  }
  return image;
}

// The first of the finder's looks, in the tracker's order, with a quadrilateral closed in on
// three sides at least that refines onto the middle cell of ClippedSheetWithAGlare's sheet in
// `image` ("none" when no look has one).
std::string FirstLookHoldingTheClippedSheetsMiddle(const vpImage<unsigned char>& image) {
  const std::array<Point2d, 4> middle = {Point2d{249.5, 176.5}, Point2d{391.5, 176.5},
                                         Point2d{391.5, 301.5}, Point2d{249.5, 301.5}};
  SheetFinder finder;
  const GrayImageView view = ViewOf(image);
  const auto is_middle = [&](LightQuad quad) {
    if (quad.ClosedSideCount() < 3 || !finder.Refine(view, &quad)) return false;
    return std::all_of(quad.corners.begin(), quad.corners.end(), [&](const Point2d& corner) {
      return std::any_of(middle.begin(), middle.end(), [&](const Point2d& m) {
        return std::hypot(corner.u - m.u, corner.v - m.v) < 2.0;
      });
    });
  };
  using Look = const std::vector<LightQuad>& (SheetFinder::*)(const GrayImageView&);
  const std::vector<std::pair<std::string, Look>> looks{
      {"Find", &SheetFinder::Find},
      {"FindLocallyLight", &SheetFinder::FindLocallyLight},
      {"FindFaintlyDark", &SheetFinder::FindFaintlyDark},
      {"FindNarrowed", &SheetFinder::FindNarrowed},
      {"FindSplitAtNecks", &SheetFinder::FindSplitAtNecks},
      {"FindClippedAsPaper", &SheetFinder::FindClippedAsPaper}};
  for (const auto& [name, look] : looks) {
    const std::vector<LightQuad>& found = (finder.*look)(view);
    if (std::any_of(found.begin(), found.end(), is_middle)) return name;
  }
  return "none";
}

// ClippedSheetWithAGlare: the middle cell joins through the washed-out crossing to the cells
// beyond lines 1 and 4, which run out of view, at every threshold, ratio and narrowing. Split
// where the rooms meet at the washed-out crossing, a neck much narrower than the middle cell,
// it stands alone and refines onto the stripes' edges.
TEST(SheetFinder, ACrossingWashedOutOverSeveralCellsIsSplitAtTheNeck) {
  EXPECT_EQ(FirstLookHoldingTheClippedSheetsMiddle(ClippedSheetWithAGlare()), "FindSplitAtNecks");
}

// ClippedSheetWithAGlare among pages of paper as light as the threshold but not clipped (200)
// that bring the light cells' mean below saturation: the looks that take clipped cells for a
// glare's core leave no paper; taken as paper, the middle cell is split off at the washed-out
// crossing as on a dark bench.
TEST(SheetFinder, AClippedSheetAmongLightPagesIsNotTakenForAGlare) {
  vpImage<unsigned char> image = ClippedSheetWithAGlare();
  Fill(&image, 0, 0, 100, 480, 200);    // pages left,
  Fill(&image, 540, 0, 640, 480, 200);  // right
  Fill(&image, 100, 0, 540, 52, 200);   // and above the sheet
  EXPECT_EQ(FirstLookHoldingTheClippedSheetsMiddle(image), "FindClippedAsPaper");
}

// A room of light cells with no neck (the paper alone, a '#'s intact middle cell) is not split:
// the split finds nothing Find did not.
TEST(SheetFinder, ARoomWithoutANeckIsNotSplit) {
  vpImage<unsigned char> image(480, 640, 70);
  Fill(&image, 100, 60, 540, 420, 215);  // the sheet
  SheetFinder finder;
  const GrayImageView view = ViewOf(image);
  const std::vector<LightQuad> found = finder.Find(view);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_TRUE(finder.FindSplitAtNecks(view).empty());
}

TEST(SheetFinder, FindLocallyLightAddsNothingAfterFindMadeThatPass) {
  RenderOptions render;
  render.noise_sigma = 3.0;
  LineTarget blank = TargetByName("four-line-a3");
  blank.lines.clear();  // the paper alone: no cell closed in, so Find makes the last pass
  const RenderedFrame frame =
      SceneRenderer(blank, render).Render(vpHomogeneousMatrix(0, 0, 0.6, 0.1, 0.1, 0.3), 3);
  SheetFinder finder;
  finder.Find(ViewOf(frame.image));
  EXPECT_TRUE(finder.FindLocallyLight(ViewOf(frame.image)).empty());
}

TEST(SheetFinder, AFrameWithoutAGridHasNoCandidateClosedIn) {
  RenderOptions render;
  render.noise_sigma = 5.0;
  LineTarget blank = TargetByName("four-line-a3");
  blank.lines.clear();  // the paper alone
  const SceneRenderer renderer(blank, render);
  const RenderedFrame frame = renderer.Render(vpHomogeneousMatrix(0, 0, 0.6, 0.2, 0.1, 0.3), 3);
  SheetFinder finder;
  for (const LightQuad& quad : finder.Find(ViewOf(frame.image))) {
    EXPECT_LT(quad.ClosedSideCount(), 3);
  }
}

TEST_F(SheetFinderInALivedInScene, ADimFrameNeedsLessContrastInProportionToItsPaper) {
  // Exposed at a fifth of the right level on a grey bench (an auto-exposure lagging behind a
  // lamp switched off): paper, bench and ink at a fifth of their grey levels, and so is the
  // contrast between them, under the 30 grey levels of a rightly exposed frame.
  render_.background_grey = 120;
  FrameEffects dim;
  dim.gain = 0.2;
  const vpHomogeneousMatrix cMo(0.02, 0.01, 0.5, 12.0 * kRadPerDeg, -8.0 * kRadPerDeg,
                                30.0 * kRadPerDeg);
  const RenderedFrame frame = SceneRenderer(target_, render_).Render(cMo, 5, dim);
  EXPECT_TRUE(FindsTheMiddleCell(frame, target_, render_.camera));
  SheetFinderOptions absolute;
  absolute.min_relative_contrast = 1.0;  // never less than min_contrast
  EXPECT_FALSE(FindsTheMiddleCell(frame, target_, render_.camera, absolute));
}

TEST(SheetFinder, TheContrastNeededFollowsADimLightButNeverExceedsMinContrast) {
  SheetFinderOptions options;
  EXPECT_DOUBLE_EQ(options.ContrastNeededAt(230.0), options.min_contrast);
  EXPECT_NEAR(options.ContrastNeededAt(100.0), 100.0 * options.min_relative_contrast, 1e-12);
  options.min_relative_contrast = 0.0;
  EXPECT_DOUBLE_EQ(options.ContrastNeededAt(100.0), 0.0);
}

TEST(SheetFinder, OptionsAreChecked) {
  SheetFinderOptions options;
  options.cell_px = 1;
  EXPECT_THROW(SheetFinder{options}, std::invalid_argument);
  options = SheetFinderOptions();
  options.min_area_fraction = 0.0;
  EXPECT_THROW(SheetFinder{options}, std::invalid_argument);
  options = SheetFinderOptions();
  options.min_relative_contrast = 1.5;
  EXPECT_THROW(SheetFinder{options}, std::invalid_argument);
  SheetFinder finder;
  EXPECT_THROW(finder.Find(GrayImageView{}), std::invalid_argument);
}

}  // namespace
}  // namespace oal
