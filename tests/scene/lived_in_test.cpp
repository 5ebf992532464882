// A lived-in scene: objects over the sheet on its plane, glares, motion blur, JPEG, and the
// per-frame draws of scene/lived_in.h.
#include "scene/lived_in.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

#include "scene/scene.h"
#include "tests/scene/scene_test_util.h"

namespace oal {
namespace {

using testing::FrontoParallel;
using testing::SameImage;

// FrontoParallel(0.5) with the default camera: plane point (X, Y) at pixel
// (319.5 + 1200 X, 239.5 + 1200 Y).
constexpr double kPxPerM = 1200.0;
double U(double X) {
  return 319.5 + kPxPerM * X;
}
double V(double Y) {
  return 239.5 + kPxPerM * Y;
}

double MeanGrey(const vpImage<unsigned char>& image) {
  return std::accumulate(image.bitmap, image.bitmap + image.getSize(), 0.0) / image.getSize();
}

PlaneOccluder Pen(double x1, double y1, double x2, double y2, double radius, int grey) {
  PlaneOccluder pen;
  pen.capsules.push_back({x1, y1, x2, y2, radius});
  pen.grey = grey;
  return pen;
}

TEST(PlaneOccluder, SignedDistanceOfCapsulesIsExactAndOfEllipsesHasTheRightSign) {
  PlaneOccluder o = Pen(0.0, 0.0, 0.1, 0.0, 0.01, 100);
  EXPECT_NEAR(o.SignedDistance(0.05, 0.03), 0.02, 1e-12);
  EXPECT_NEAR(o.SignedDistance(0.05, 0.0), -0.01, 1e-12);
  EXPECT_NEAR(o.SignedDistance(0.13, 0.04), 0.04, 1e-12);  // beyond the end: from the end point
  o.capsules.clear();
  o.ellipses.push_back({0.0, 0.0, 0.05, 0.02, 0.5});
  EXPECT_LT(o.SignedDistance(0.0, 0.0), 0.0);
  const double along = 0.05 * std::cos(0.5), across = 0.05 * std::sin(0.5);
  EXPECT_NEAR(o.SignedDistance(along, across), 0.0, 1e-9);  // the rim at the major axis' end
  EXPECT_NEAR(o.SignedDistance(1.01 * along, 1.01 * across), 0.0005, 5e-5);
  EXPECT_GT(o.SignedDistance(0.0, 0.03), 0.0);
}

TEST(RenderLivedIn, APenOnThePlaneHidesTheStripeAndIsCountedInTheTruth) {
  const LineTarget target = TwoLineTarget();
  const SceneRenderer renderer(target, RenderOptions());
  const vpHomogeneousMatrix cMo = FrontoParallel(0.5);
  const double x_line = target.lines[0].x1_m;
  // A pen lying along line 0 over the top half of its visible part (y from -0.2 to 0; its
  // end's cap is round).
  FrameEffects effects;
  effects.plane_occluders.push_back(Pen(x_line, -0.5, x_line, -0.02, 0.02, 150));
  const RenderedFrame frame = renderer.Render(cMo, 1, effects);
  const int u = static_cast<int>(std::lround(U(x_line)));
  EXPECT_EQ(frame.image[100][u], 150);
  EXPECT_EQ(frame.image[100][u + 20], 150);  // 17 mm from its axis
  EXPECT_EQ(frame.image[400][u], target.line_grey);
  EXPECT_NEAR(frame.truth[0].occluded_fraction, 0.5, 0.01);
  EXPECT_EQ(frame.truth[1].occluded_fraction, 0.0);
}

TEST(RenderLivedIn, AnOccludersShadowDarkensWhatLiesUnderItBesideIt) {
  const LineTarget target = TwoLineTarget();
  const SceneRenderer renderer(target, RenderOptions());
  PlaneOccluder disc;
  disc.ellipses.push_back({0.0, 0.05, 0.01, 0.01, 0.0});
  disc.grey = 200;
  disc.shadow_darkness = 0.5;
  disc.shadow_offset_m = 0.03;  // along +x
  disc.shadow_softness_m = 0.001;
  FrameEffects effects;
  effects.plane_occluders.push_back(disc);
  const RenderedFrame frame = renderer.Render(FrontoParallel(0.5), 1, effects);
  const int v = static_cast<int>(std::lround(V(0.05)));
  EXPECT_EQ(frame.image[v][static_cast<int>(std::lround(U(0.0)))], 200);
  EXPECT_NEAR(frame.image[v][static_cast<int>(std::lround(U(0.03)))], 0.5 * target.board_grey, 1);
  EXPECT_EQ(frame.image[v][static_cast<int>(std::lround(U(-0.03)))], target.board_grey);
}

TEST(RenderLivedIn, AGlareSaturatesInkAndPaperAtItsCoreAndFadesAway) {
  const LineTarget target = TwoLineTarget();
  const SceneRenderer renderer(target, RenderOptions());
  const double x_line = target.lines[0].x1_m;
  FrameEffects effects;
  effects.glares.push_back({x_line, 0.0, 0.01, 400.0});
  const RenderedFrame frame = renderer.Render(FrontoParallel(0.5), 1, effects);
  const int u = static_cast<int>(std::lround(U(x_line))), v = static_cast<int>(std::lround(V(0.0)));
  EXPECT_EQ(frame.image[v][u], 255);  // ink + 400
  EXPECT_EQ(frame.image[v][u + 12], 255);
  // 5 sigma away the glare adds 400 exp(-12.5) < 0.002.
  EXPECT_EQ(frame.image[v + 60][u], target.line_grey);
}

TEST(RenderLivedIn, MotionBlurSpreadsAnEdgeAlongItsDirectionOnlyAndKeepsTheMean) {
  const LineTarget target = TwoLineTarget();  // vertical stripes
  const SceneRenderer renderer(target, RenderOptions());
  const vpHomogeneousMatrix cMo = FrontoParallel(0.5);
  const RenderedFrame sharp = renderer.Render(cMo, 1);
  FrameEffects along;  // along the stripes: nothing changes away from their ends
  along.motion_blur_px = 10.0;
  along.motion_blur_angle_rad = kPi / 2.0;
  const RenderedFrame vertical = renderer.Render(cMo, 1, along);
  FrameEffects across = along;
  across.motion_blur_angle_rad = 0.0;
  const RenderedFrame horizontal = renderer.Render(cMo, 1, across);
  const int u = static_cast<int>(std::lround(U(target.lines[0].x1_m)));
  const int half_width = static_cast<int>(0.5 * target.lines[0].width_m * kPxPerM);
  EXPECT_EQ(vertical.image[240][u + half_width + 3], sharp.image[240][u + half_width + 3]);
  // Across, the 10 px path smears the edge over about 10 px.
  int ramp = 0;
  for (int du = -15; du <= 15; ++du) {
    const int grey = horizontal.image[240][u + half_width + du];
    ramp += grey > target.line_grey + 5 && grey < target.board_grey - 5;
  }
  EXPECT_GE(ramp, 8);
  EXPECT_LE(ramp, 12);
  EXPECT_NEAR(MeanGrey(horizontal.image), MeanGrey(sharp.image), 0.5);
}

TEST(RenderLivedIn, JpegCompressionChangesTheFrameLittleAndOnlyWhenAsked) {
  RenderOptions options;
  options.noise_sigma = 3.0;
  const SceneRenderer renderer(FourLineTarget(), options);
  const vpHomogeneousMatrix cMo = FrontoParallel(0.8, 0.01, 0.0, 0.3);
  const RenderedFrame plain = renderer.Render(cMo, 5);
  FrameEffects effects;
  effects.jpeg_quality = 40;
  const RenderedFrame jpeg = renderer.Render(cMo, 5, effects);
  EXPECT_FALSE(SameImage(plain.image, jpeg.image));
  EXPECT_NEAR(MeanGrey(jpeg.image), MeanGrey(plain.image), 1.0);
  effects.jpeg_quality = 0;
  EXPECT_TRUE(SameImage(plain.image, renderer.Render(cMo, 5, effects).image));
}

TEST(RenderLivedIn, BadValuesNameTheField) {
  const SceneRenderer renderer(TwoLineTarget(), RenderOptions());
  const auto message = [&](const FrameEffects& effects) -> std::string {
    try {
      renderer.Render(FrontoParallel(0.5), 1, effects);
    } catch (const std::invalid_argument& error) {
      return error.what();
    }
    return "no error";
  };
  FrameEffects effects;
  effects.plane_occluders.push_back(Pen(0.0, 0.0, 0.1, 0.0, 0.0, 100));
  EXPECT_NE(message(effects).find("PlaneOccluder::Capsule::radius_m = 0"), std::string::npos);
  effects.plane_occluders = {PlaneOccluder{}};
  EXPECT_NE(message(effects).find("at least one capsule or ellipse"), std::string::npos);
  effects.plane_occluders.clear();
  effects.glares.push_back({0.0, 0.0, 0.0, 100.0});
  EXPECT_NE(message(effects).find("Glare::sigma_m = 0"), std::string::npos);
  effects.glares.clear();
  effects.jpeg_quality = 101;
  EXPECT_NE(message(effects).find("FrameEffects::jpeg_quality = 101"), std::string::npos);
  effects.jpeg_quality = 0;
  effects.motion_blur_px = -1.0;
  EXPECT_NE(message(effects).find("FrameEffects::motion_blur_px = -1"), std::string::npos);
}

LivedInOptions EveryCondition() {
  LivedInOptions options;
  options.occluders.fraction = 0.6;
  options.glare.fraction = 0.4;
  options.exposure.fraction = 0.3;
  options.motion_blur.fraction = 0.5;
  options.jpeg.fraction = 0.5;
  return options;
}

TEST(LivedIn, EachConditionStrikesItsFractionOfTheFrames) {
  const LivedInOptions options = EveryCondition();
  const LineTarget target = FourLineA3Target();
  int occluded = 0, glared = 0, exposed = 0, blurred = 0, compressed = 0;
  constexpr int kFrames = 2000;
  for (int frame = 0; frame < kFrames; ++frame) {
    FrameEffects effects;
    DrawLivedIn(options, target, 7, frame, &effects);
    occluded += !effects.plane_occluders.empty();
    glared += !effects.glares.empty();
    exposed += effects.gain != 1.0;
    blurred += effects.motion_blur_px > 0.0;
    compressed += effects.jpeg_quality > 0;
    if (effects.gain != 1.0) {
      EXPECT_TRUE((effects.gain >= 1.0 / 3.0 && effects.gain <= 2.0 / 3.0) ||
                  (effects.gain >= 1.25 && effects.gain <= 1.5))
          << effects.gain;
    }
    if (effects.motion_blur_px > 0.0) {
      EXPECT_GE(effects.motion_blur_px, 3.0);
      EXPECT_LE(effects.motion_blur_px, 12.0);
    }
    if (effects.jpeg_quality > 0) {
      EXPECT_GE(effects.jpeg_quality, 40);
      EXPECT_LE(effects.jpeg_quality, 90);
    }
    EXPECT_NO_THROW(effects.Check());
  }
  // Binomial: 3.5 standard deviations at most.
  EXPECT_NEAR(occluded, 0.6 * kFrames, 40);
  EXPECT_NEAR(glared, 0.4 * kFrames, 40);
  EXPECT_NEAR(exposed, 0.3 * kFrames, 40);
  EXPECT_NEAR(blurred, 0.5 * kFrames, 40);
  EXPECT_NEAR(compressed, 0.5 * kFrames, 40);
}

TEST(LivedIn, DrawsAreReproducibleAndEachConditionIndependentOfTheOthers) {
  const LineTarget target = FourLineA3Target();
  LivedInOptions options = EveryCondition();
  LivedInOptions without_glare = options;
  without_glare.glare.fraction = 0.0;
  for (int frame = 0; frame < 50; ++frame) {
    FrameEffects a, b, c;
    DrawLivedIn(options, target, 3, frame, &a);
    DrawLivedIn(options, target, 3, frame, &b);
    DrawLivedIn(without_glare, target, 3, frame, &c);
    ASSERT_EQ(a.plane_occluders.size(), b.plane_occluders.size());
    ASSERT_EQ(a.plane_occluders.size(), c.plane_occluders.size());
    for (std::size_t i = 0; i < a.plane_occluders.size(); ++i) {
      EXPECT_EQ(a.plane_occluders[i].grey, c.plane_occluders[i].grey);
      EXPECT_EQ(a.plane_occluders[i].capsules.size(), c.plane_occluders[i].capsules.size());
      EXPECT_EQ(a.plane_occluders[i].SignedDistance(0.0, 0.0),
                c.plane_occluders[i].SignedDistance(0.0, 0.0));
    }
    EXPECT_EQ(a.glares.size(), b.glares.size());
    EXPECT_TRUE(c.glares.empty());
    EXPECT_EQ(a.motion_blur_px, c.motion_blur_px);
    EXPECT_EQ(a.jpeg_quality, c.jpeg_quality);
    EXPECT_EQ(a.gain, c.gain);
  }
}

TEST(LivedIn, ObjectsLieOverTheSheet) {
  const LineTarget target = FourLineA3Target();
  const double hw = 0.5 * target.board_width_m, hh = 0.5 * target.board_height_m;
  for (const OccluderKind kind :
       {OccluderKind::kHand, OccluderKind::kPen, OccluderKind::kCable, OccluderKind::kTool}) {
    LivedInOptions options;
    options.occluders.fraction = 1.0;
    options.occluders.kinds = {kind};
    int over_sheet = 0;
    for (int frame = 0; frame < 100; ++frame) {
      FrameEffects effects;
      DrawLivedIn(options, target, 11, frame, &effects);
      ASSERT_EQ(effects.plane_occluders.size(), 1u) << ToString(kind);
      // Some point of the sheet lies under it: probe a 5 mm grid.
      bool covers = false;
      for (double x = -hw; x <= hw && !covers; x += 0.005) {
        for (double y = -hh; y <= hh && !covers; y += 0.005) {
          covers = effects.plane_occluders[0].Contains(x, y);
        }
      }
      over_sheet += covers;
    }
    // A hand may reach in from just beside the sheet, a cable wind out past a corner.
    const bool always = kind == OccluderKind::kPen || kind == OccluderKind::kTool;
    EXPECT_GE(over_sheet, always ? 100 : 95) << ToString(kind);
  }
}

TEST(LivedIn, BadOptionsNameTheField) {
  const auto message = [](const LivedInOptions& options) -> std::string {
    try {
      options.Check();
    } catch (const std::invalid_argument& error) {
      return error.what();
    }
    return "no error";
  };
  LivedInOptions options;
  EXPECT_EQ(message(options), "no error");
  options.glare.fraction = 1.5;
  EXPECT_NE(message(options).find("LivedInOptions::glare.fraction = 1.5"), std::string::npos);
  options.glare.fraction = 0.0;
  options.occluders.kinds.clear();
  EXPECT_NE(message(options).find("LivedInOptions::occluders.kinds"), std::string::npos);
  options.occluders.kinds = {OccluderKind::kPen};
  options.jpeg.quality = {90.0, 40.0};
  EXPECT_NE(message(options).find("LivedInOptions::jpeg.quality"), std::string::npos);
  options.jpeg.quality = {40.0, 90.0};
  options.exposure.gain = {1.2, 1.5};
  EXPECT_NE(message(options).find("LivedInOptions::exposure.gain"), std::string::npos);
  EXPECT_THROW(OccluderKindFromString("foot"), std::invalid_argument);
  EXPECT_EQ(OccluderKindFromString("cable"), OccluderKind::kCable);
}

}  // namespace
}  // namespace oal
