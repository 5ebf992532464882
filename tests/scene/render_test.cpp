// Rendering: anti-aliased stripes where the truth says, noise, blur, illumination, background;
// a sheet on a bench (background image, light fall-off, shadow, paper, annotations, clutter).
#include <gtest/gtest.h>
#include <visp3/core/vpPixelMeterConversion.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "scene/scene.h"
#include "tests/scene/scene_image_util.h"
#include "tests/scene/scene_test_util.h"

namespace oal {
namespace {

using testing::Darkness;
using testing::FrontoParallel;
using testing::ImageChecksum;
using testing::ReferenceGrey;
using testing::SameImage;

// Coverage is read back from 8-bit grey levels with 180 levels of contrast.
constexpr double kEdgeTolerancePx = 0.02;
constexpr double kCentreTolerancePx = 0.05;

// Sub-pixel edges of the dark run of row v between columns [u_begin, u_end) of a stripe whose
// edges are not parallel to the row: a = left edge, b = right edge. The coverage of a partly
// dark pixel gives the edge position inside it.
void VerticalStripeEdges(const RenderedFrame& frame, const LineTarget& target, int v, int u_begin,
                         int u_end, double* a, double* b) {
  int first = -1, last = -1;
  for (int u = u_begin; u < u_end; ++u) {
    if (Darkness(frame.image, target, u, v) <= 0.0) continue;
    if (first < 0) first = u;
    last = u;
  }
  ASSERT_GE(first, 0);
  *a = first + 0.5 - Darkness(frame.image, target, first, v);
  *b = last - 0.5 + Darkness(frame.image, target, last, v);
}

// Darkness-weighted mean column of row v over [u_begin, u_end).
double RowCentroid(const RenderedFrame& frame, const LineTarget& target, int v, int u_begin,
                   int u_end) {
  double sum = 0.0, weighted = 0.0;
  for (int u = u_begin; u < u_end; ++u) {
    const double d = Darkness(frame.image, target, u, v);
    sum += d;
    weighted += d * u;
  }
  return weighted / sum;
}

TEST(Render, FrontoParallelStripeEdgesAreWhereTheTruthSays) {
  const LineTarget target = TwoLineTarget();
  const SceneRenderer renderer(target, RenderOptions());
  // Off-centre so the stripe edges fall at fractional pixels.
  const RenderedFrame frame = renderer.Render(FrontoParallel(0.5, 0.0123, 0.0), 1);
  ASSERT_EQ(frame.truth.size(), 2u);
  const double width_px = 600.0 * 0.02 / 0.5;
  for (const TruthLine& truth : frame.truth) {
    ASSERT_TRUE(truth.visible);
    ASSERT_NEAR(truth.ideal.theta_rad, 0.0, 1e-12);
    const double centre = truth.ideal.rho_px;
    const int u_begin = static_cast<int>(centre - 30), u_end = static_cast<int>(centre + 30);
    for (int v : {0, 77, 240, 479}) {
      double a = 0.0, b = 0.0;
      VerticalStripeEdges(frame, target, v, u_begin, u_end, &a, &b);
      EXPECT_NEAR(0.5 * (a + b), centre, kEdgeTolerancePx)
          << "line " << truth.index << " row " << v;
      EXPECT_NEAR(b - a, width_px, kEdgeTolerancePx) << "line " << truth.index << " row " << v;
    }
    EXPECT_NEAR(truth.width_px, width_px, 1e-9);
  }
  // Between the stripes: bare board.
  EXPECT_EQ(frame.image[240][320], target.board_grey);
}

TEST(Render, RolledStripeRowCentroidsLieOnTheIdealLine) {
  const LineTarget target = TwoLineTarget();
  const SceneRenderer renderer(target, RenderOptions());
  const RenderedFrame frame = renderer.Render(FrontoParallel(0.6, 0.004, -0.01, 0.35), 1);
  for (const TruthLine& truth : frame.truth) {
    ASSERT_TRUE(truth.visible);
    const double c = std::cos(truth.ideal.theta_rad), s = std::sin(truth.ideal.theta_rad);
    for (int v = 40; v < 440; v += 37) {
      const double expected = (truth.ideal.rho_px - v * s) / c;
      const double centroid = RowCentroid(frame, target, v, static_cast<int>(expected) - 30,
                                          static_cast<int>(expected) + 30);
      EXPECT_NEAR(centroid, expected, kCentreTolerancePx) << "line " << truth.index << " row " << v;
    }
  }
}

TEST(Render, DistortedStripeCentresUndistortOntoTheIdealLine) {
  RenderOptions options;
  options.camera = Lens::WithKudKdu(600.0, 600.0, 319.5, 239.5, 0.0, 0.33);
  const LineTarget target = TwoLineTarget();
  const SceneRenderer renderer(target, options);
  // The left stripe lies far right of the centre, where the distortion bends it most.
  const RenderedFrame frame = renderer.Render(FrontoParallel(0.6, -0.22, 0.0), 1);
  const TruthLine& truth = frame.truth[0];
  ASSERT_TRUE(truth.visible);
  for (int v = 0; v < 480; v += 40) {
    // Search around the straight line fitted to the distorted stripe (a few pixels off).
    const LineParams& fit = truth.distorted_fit;
    const int guess =
        static_cast<int>((fit.rho_px - v * std::sin(fit.theta_rad)) / std::cos(fit.theta_rad));
    const double centroid = RowCentroid(frame, target, v, guess - 25, guess + 25);
    const Point2d ray = options.camera.Normalised(centroid, v);
    const double distance =
        truth.ideal.SignedDistance(319.5 + 600.0 * ray.u, 239.5 + 600.0 * ray.v);
    EXPECT_NEAR(distance, 0.0, kCentreTolerancePx) << "row " << v;
  }
}

// Every pixel that is neither bare board nor full stripe in a tilted, rolled four-line view
// (edges at all angles, stripe crossings, a board corner, perspective, with and without lens
// distortion) against 32 x 32 point samples; plus a sparse grid of the other pixels.
class PixelsMatchDenseSampling : public ::testing::TestWithParam<double> {};

TEST_P(PixelsMatchDenseSampling, UnderPerspective) {
  const LineTarget target = FourLineTarget();
  RenderOptions options;
  options.width = 320;
  options.height = 240;
  options.camera = Lens::WithKudKdu(300.0, 300.0, 159.5, 119.5, 0.0, GetParam());
  const SceneRenderer renderer(target, options);
  vpHomogeneousMatrix tilt;
  tilt.buildFrom(0.0, 0.0, 0.0, 0.45, -0.3, 0.0);
  const vpHomogeneousMatrix cMo = tilt * FrontoParallel(0.55, 0.01, 0.0, 0.5);
  const RenderedFrame frame = renderer.Render(cMo, 1);
  const double contrast = target.board_grey - target.line_grey;
  int checked = 0, background = 0;
  double worst = 0.0, total_error = 0.0;
  for (int v = 0; v < options.height; ++v) {
    for (int u = 0; u < options.width; ++u) {
      const int grey = frame.image[v][u];
      const bool mixed = grey != target.board_grey && grey != target.line_grey;
      if (!mixed && (u % 9 != 0 || v % 9 != 0)) continue;
      const double error = (grey - ReferenceGrey(target, options, cMo, u, v, 32)) / contrast;
      worst = std::max(worst, std::fabs(error));
      total_error += error;
      ++checked;
      background += grey == options.background_grey;
    }
  }
  EXPECT_GT(checked, 1500);
  EXPECT_GT(background, 10);  // the view includes a corner of the board
  EXPECT_LT(worst, 0.025);
  // No bias: the summed error (an area, pixels^2) is small.
  EXPECT_LT(std::fabs(total_error), 0.5);
}

INSTANTIATE_TEST_SUITE_P(Lenses, PixelsMatchDenseSampling, ::testing::Values(0.0, 0.33),
                         [](const ::testing::TestParamInfo<double>& param) {
                           return param.param == 0.0 ? std::string("pinhole")
                                                     : std::string("barrel");
                         });

TEST(Render, NoiseIsReproducibleFromTheSeed) {
  RenderOptions options;
  options.width = 160;
  options.height = 120;
  options.noise_sigma = 5.0;
  const SceneRenderer renderer(TwoLineTarget(), options);
  const vpHomogeneousMatrix cMo = FrontoParallel(0.5);
  const RenderedFrame a = renderer.Render(cMo, 42);
  const RenderedFrame b = renderer.Render(cMo, 42);
  const RenderedFrame c = renderer.Render(cMo, 43);
  EXPECT_TRUE(SameImage(a.image, b.image));
  EXPECT_FALSE(SameImage(a.image, c.image));
}

TEST(Render, NoiseHasTheRequestedStandardDeviation) {
  LineTarget blank = TwoLineTarget();
  blank.lines.clear();
  RenderOptions options;
  options.width = 200;
  options.height = 150;
  options.noise_sigma = 6.0;
  const SceneRenderer renderer(blank, options);
  const RenderedFrame frame = renderer.Render(FrontoParallel(0.5), 7);
  double sum = 0.0, sum2 = 0.0;
  const double n = frame.image.getSize();
  for (unsigned i = 0; i < frame.image.getSize(); ++i) {
    sum += frame.image.bitmap[i];
    sum2 += frame.image.bitmap[i] * static_cast<double>(frame.image.bitmap[i]);
  }
  const double mean = sum / n;
  const double sigma = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, blank.board_grey, 0.1);
  // Rounding to integers adds 1/12 to the variance.
  EXPECT_NEAR(sigma, std::sqrt(36.0 + 1.0 / 12.0), 0.15);
}

TEST(Render, BlurSoftensEdgesWithoutMovingTheStripe) {
  const LineTarget target = TwoLineTarget();
  RenderOptions options;
  options.blur_sigma_px = 1.5;
  const SceneRenderer sharp_renderer(target, RenderOptions());
  const SceneRenderer blurred_renderer(target, options);
  const vpHomogeneousMatrix cMo = FrontoParallel(0.5, 0.0123, 0.0);
  const RenderedFrame sharp = sharp_renderer.Render(cMo, 1);
  const RenderedFrame blurred = blurred_renderer.Render(cMo, 1);
  const double centre = sharp.truth[0].ideal.rho_px;
  const int begin = static_cast<int>(centre) - 25, end = static_cast<int>(centre) + 25;
  int max_step_sharp = 0, max_step_blurred = 0;
  for (int u = begin; u < end; ++u) {
    max_step_sharp =
        std::max(max_step_sharp, std::abs(sharp.image[200][u + 1] - sharp.image[200][u]));
    max_step_blurred =
        std::max(max_step_blurred, std::abs(blurred.image[200][u + 1] - blurred.image[200][u]));
  }
  EXPECT_LT(max_step_blurred, 0.5 * max_step_sharp);
  EXPECT_NEAR(RowCentroid(blurred, target, 200, begin, end), centre, kCentreTolerancePx);
}

TEST(Render, IlluminationFallsAlongTheGradientDirection) {
  LineTarget blank = TwoLineTarget();
  blank.lines.clear();
  RenderOptions options;
  options.width = 100;
  options.height = 80;
  options.illumination_gradient = 0.5;
  {
    const RenderedFrame frame = SceneRenderer(blank, options).Render(FrontoParallel(0.5), 1);
    EXPECT_EQ(frame.image[40][0], blank.board_grey);
    EXPECT_NEAR(frame.image[40][99], 0.5 * blank.board_grey, 0.51);
    EXPECT_NEAR(frame.image[0][50], frame.image[79][50], 0.51);  // constant along v
  }
  options.gradient_angle_rad = kPi / 2.0;
  {
    const RenderedFrame frame = SceneRenderer(blank, options).Render(FrontoParallel(0.5), 1);
    EXPECT_EQ(frame.image[0][50], blank.board_grey);
    EXPECT_NEAR(frame.image[79][50], 0.5 * blank.board_grey, 0.51);
  }
}

TEST(Render, UniformBackgroundAroundTheBoard) {
  const LineTarget target = TwoLineTarget();
  RenderOptions options;
  const SceneRenderer renderer(target, options);
  // At 5 m the 2 m board covers 240 x 240 pixels in the middle.
  const RenderedFrame frame = renderer.Render(FrontoParallel(5.0), 1);
  EXPECT_EQ(frame.image[5][5], options.background_grey);
  EXPECT_EQ(frame.image[470][630], options.background_grey);
  EXPECT_EQ(frame.image[239][200], target.board_grey);
  // The board edge at u = 319.5 - 120 = 199.5 falls between pixels 199 and 200.
  EXPECT_EQ(frame.image[150][199], options.background_grey);
}

TEST(Render, BackgroundImageIsShownAroundTheBoardOnly) {
  const std::string path = std::string(OAL_VISP_IMAGES_DIR) + "/Klimt/Klimt.pgm";
  if (!std::ifstream(path).good()) GTEST_SKIP() << "ViSP test image missing: " << path;
  const LineTarget target = TwoLineTarget();
  RenderOptions options;
  options.background = testing::ReadPgm(path);
  const SceneRenderer renderer(target, options);
  const vpHomogeneousMatrix cMo = FrontoParallel(5.0);
  const RenderedFrame frame = renderer.Render(cMo, 1);
  int lo = 255, hi = 0;
  for (int v = 0; v < 100; ++v) {
    for (int u = 0; u < 150; ++u) {
      lo = std::min<int>(lo, frame.image[v][u]);
      hi = std::max<int>(hi, frame.image[v][u]);
    }
  }
  EXPECT_GT(hi - lo, 50) << "the background should be textured";
  EXPECT_EQ(frame.image[239][200], target.board_grey);
  // The background is fixed to the board plane: moving the camera moves it in the image.
  const RenderedFrame moved = renderer.Render(FrontoParallel(5.0, 0.1, 0.0), 1);
  EXPECT_FALSE(SameImage(frame.image, moved.image));
}

// Frames rendered with options that existed before the scene effects of sheets on a bench
// (background image, light fall-off, shadow, annotations, clutter): their checksums were
// computed from the renderer before those were added, so figures made with the old options
// stay reproducible. A change here means old data sets and figures change too. (Computed on
// x86-64 Debian bookworm with OpenCV 4.6, the CI's platform: another libm or OpenCV may round
// a few pixels differently.)
vpHomogeneousMatrix TiltedView(double distance_m, double x_m, double y_m, double roll_rad) {
  vpHomogeneousMatrix tilt;
  tilt.buildFrom(0.0, 0.0, 0.0, 0.35, -0.25, 0.0);
  return tilt * FrontoParallel(distance_m, x_m, y_m, roll_rad);
}

RenderOptions OldEffects() {
  RenderOptions options;
  options.camera = Lens::WithKdu(600.0, 600.0, 319.5, 239.5, 0.15, 640, 480);
  options.noise_sigma = 4.0;
  options.blur_sigma_px = 1.0;
  options.illumination_gradient = 0.3;
  options.gradient_angle_rad = 0.7;
  return options;
}

FrameEffects OldFrameEffects() {
  FrameEffects effects;
  effects.gain = 0.9;
  effects.offset = 3.0;
  Occluder disc;
  disc.shape = Occluder::Shape::kDisc;
  disc.centre_u_px = 500.0;
  disc.centre_v_px = 100.0;
  disc.half_width_px = 40.0;
  disc.grey = 60;
  effects.occluders = {disc};
  return effects;
}

TEST(RenderRegression, DefaultOptionsGiveTheFramesOfBefore) {
  const SceneRenderer sheet(FourLineA3Target(), RenderOptions());
  const std::uint64_t a = ImageChecksum(sheet.Render(TiltedView(0.6, 0.03, -0.02, 0.4), 1).image);
  const SceneRenderer board(FourLineTarget(), OldEffects());
  const std::uint64_t b =
      ImageChecksum(board.Render(TiltedView(0.8, 0.01, 0.02, -0.3), 5, OldFrameEffects()).image);
  EXPECT_EQ(a, 0x878c8ffb90ebe51bull);
  EXPECT_EQ(b, 0x02a814192561b888ull);
}

TEST(RenderRegression, BackgroundFileGivesTheFrameOfBefore) {
  const std::string path = std::string(OAL_VISP_IMAGES_DIR) + "/Klimt/Klimt.pgm";
  if (!std::ifstream(path).good()) GTEST_SKIP() << "ViSP test image missing: " << path;
  RenderOptions options = OldEffects();
  options.background = testing::ReadPgm(path);
  const SceneRenderer sheet(FourLineA3Target(), options);
  const std::uint64_t a =
      ImageChecksum(sheet.Render(TiltedView(0.7, -0.05, 0.03, 1.1), 9, OldFrameEffects()).image);
  EXPECT_EQ(a, 0x824b16d68999c6d4ull);
}

// The sheet dressed as the evaluations' bench (paper texture, annotations, shadow, clutter,
// light fall-off) on a photograph, near and far: the frames of before the printed picture
// (RenderOptions::printed_picture) shared the dressing's code.
TEST(RenderRegression, DressedBenchGivesTheFramesOfBefore) {
  const std::string path = std::string(OAL_VISP_IMAGES_DIR) + "/Klimt/Klimt.pgm";
  if (!std::ifstream(path).good()) GTEST_SKIP() << "ViSP test image missing: " << path;
  RenderOptions options = OldEffects();
  options.background = testing::ReadPgm(path);
  options.vignetting = 0.3;
  options.shadow_darkness = 0.3;
  options.paper_texture_grey = 3.0;
  options.annotations = true;
  options.clutter_sheets = 2;
  options.clutter_objects = 4;
  options.clutter_reach_m = 0.25;
  options.scene_seed = 3;
  const SceneRenderer sheet(FourLineA3Target(), options);
  const std::uint64_t near =
      ImageChecksum(sheet.Render(TiltedView(0.35, -0.12, 0.08, 0.4), 2, OldFrameEffects()).image);
  const std::uint64_t far = ImageChecksum(sheet.Render(TiltedView(0.9, 0.02, -0.03, 2.0), 4).image);
  EXPECT_EQ(near, 0xdb38ac6f0498f246ull);
  EXPECT_EQ(far, 0x5033d4e4865dc388ull);
}

// ---------------------------------------------------------------------------------------------
// A sheet on a bench: background image, light fall-off, shadow, paper, annotations, clutter.

using testing::ReadPgm;

// A fronto-parallel camera at 0.6 m with px = 600 sees 1 mm of the board plane per pixel, pixel
// (u, v) looking at X = (u - 319.5) mm, Y = (v - 239.5) mm.
constexpr double kMmPerPxAt06 = 0.001;

double PlaneX(int u) {
  return (u - 319.5) * kMmPerPxAt06;
}
double PlaneY(int v) {
  return (v - 239.5) * kMmPerPxAt06;
}

// Distance on the plane from (X, Y) to the nearest stripe of `target` (0 inside one).
double DistanceToStripes(const LineTarget& target, double X, double Y) {
  double best = 1e300;
  for (const TargetLine& line : target.lines) {
    const double ex = line.x2_m - line.x1_m, ey = line.y2_m - line.y1_m;
    const double length = std::hypot(ex, ey);
    const double along = ((X - line.x1_m) * ex + (Y - line.y1_m) * ey) / length;
    const double across = std::fabs((X - line.x1_m) * -ey + (Y - line.y1_m) * ex) / length;
    const double da = std::max({0.0, -along, along - length});
    const double dc = std::max(0.0, across - 0.5 * line.width_m);
    best = std::min(best, std::hypot(da, dc));
  }
  return best;
}

// Distance on the plane from (X, Y) outside the board to it (negative inside, the distance to
// its edge).
double DistanceOutsideBoard(const LineTarget& target, double X, double Y) {
  const double dx = std::fabs(X) - 0.5 * target.board_width_m;
  const double dy = std::fabs(Y) - 0.5 * target.board_height_m;
  if (dx <= 0.0 && dy <= 0.0) return std::max(dx, dy);
  return std::hypot(std::max(dx, 0.0), std::max(dy, 0.0));
}

bool SameTruth(const std::vector<TruthLine>& a, const std::vector<TruthLine>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].visible != b[i].visible || a[i].ideal.rho_px != b[i].ideal.rho_px ||
        a[i].ideal.theta_rad != b[i].ideal.theta_rad ||
        a[i].distorted_fit.rho_px != b[i].distorted_fit.rho_px || a[i].end_a.u != b[i].end_a.u ||
        a[i].end_b.v != b[i].end_b.v || a[i].width_px != b[i].width_px) {
      return false;
    }
  }
  return true;
}

// A small image whose texels all differ: 10 + 8 i + 29 j at column i, row j.
std::shared_ptr<const vpImage<unsigned char>> NumberedTexels(unsigned width, unsigned height) {
  auto image = std::make_shared<vpImage<unsigned char>>(height, width);
  for (unsigned j = 0; j < height; ++j) {
    for (unsigned i = 0; i < width; ++i)
      (*image)[j][i] = static_cast<unsigned char>(10 + 8 * i + 29 * j);
  }
  return image;
}

TEST(RenderBackground, TexelIsSeenAtItsPlanePointAndTiles) {
  LineTarget small = TwoLineTarget();
  small.lines.clear();
  small.board_width_m = 0.02;
  small.board_height_m = 0.02;
  RenderOptions options;
  options.background = NumberedTexels(6, 4);
  options.background_texel_m = 0.004;  // 4 pixels at 0.6 m
  // Pixel u looks at X = (u - 319) mm: texel column i at u = 319 + 4 i, row j at v = 239 + 4 j.
  const SceneRenderer renderer(small, options);
  const RenderedFrame frame = renderer.Render(FrontoParallel(0.6, 0.0005, 0.0005), 1);
  EXPECT_EQ(frame.image[239 + 4 * 3][319 + 4 * 5], 10 + 8 * 5 + 29 * 3);  // (5, 3)
  EXPECT_EQ(frame.image[239 + 4 * 1][319 + 4 * 4], 10 + 8 * 4 + 29 * 1);  // (4, 1)
  // Tiled: column 5 + 6 = column 5, row 3 - 4 = row 3; column -3 = column 3.
  EXPECT_EQ(frame.image[239 + 4 * -1][319 + 4 * 11], 10 + 8 * 5 + 29 * 3);
  EXPECT_EQ(frame.image[239 + 4 * 2][319 + 4 * -3], 10 + 8 * 3 + 29 * 2);
  // Half-way between columns 4 and 5 of row 1: the mean.
  EXPECT_EQ(frame.image[239 + 4][319 + 18], 10 + 8 * 4.5 + 29 * 1);
  // The board hides it.
  EXPECT_EQ(frame.image[239][319], small.board_grey);
}

TEST(RenderLight, VignettingFallsWithTheSquaredRadiusFromThePrincipalPoint) {
  LineTarget blank = TwoLineTarget();
  blank.lines.clear();
  RenderOptions options;
  options.width = 101;
  options.height = 81;
  options.camera = vpCameraParameters(100.0, 100.0, 40.0, 30.0);  // off-centre principal point
  options.vignetting = 0.6;
  const RenderedFrame frame = SceneRenderer(blank, options).Render(FrontoParallel(0.5), 1);
  // The farthest corner from (40, 30) is (100, 80): r_corner^2 = 60^2 + 50^2.
  const double corner2 = 60.0 * 60.0 + 50.0 * 50.0;
  for (const auto& [u, v] : {std::pair<int, int>{40, 30}, {100, 80}, {0, 0}, {70, 10}, {5, 77}}) {
    const double r2 = (u - 40.0) * (u - 40.0) + (v - 30.0) * (v - 30.0);
    EXPECT_NEAR(frame.image[v][u], blank.board_grey * (1.0 - 0.6 * r2 / corner2), 0.5001)
        << u << ", " << v;
  }
  EXPECT_EQ(frame.image[30][40], blank.board_grey);
}

TEST(RenderLight, HotSpotBrightensAroundItsCentre) {
  LineTarget blank = TwoLineTarget();
  blank.lines.clear();
  blank.board_grey = 150;
  RenderOptions options;
  options.width = 200;
  options.height = 100;
  options.hot_spot_gain = 0.5;
  options.hot_spot_u = 0.25;     // column 49.75
  options.hot_spot_v = 1.0;      // row 99
  options.hot_spot_sigma = 0.2;  // 0.2 * hypot(200, 100) pixels
  const RenderedFrame frame = SceneRenderer(blank, options).Render(FrontoParallel(0.5), 1);
  const double sigma = 0.2 * std::hypot(200.0, 100.0);
  for (const auto& [u, v] : {std::pair<int, int>{50, 99}, {120, 60}, {199, 0}, {0, 50}}) {
    const double d2 = (u - 49.75) * (u - 49.75) + (v - 99.0) * (v - 99.0);
    EXPECT_NEAR(frame.image[v][u], 150.0 * (1.0 + 0.5 * std::exp(-d2 / (2.0 * sigma * sigma))),
                0.5001)
        << u << ", " << v;
  }
  EXPECT_EQ(frame.image[99][50], 225);
}

// The A3 sheet fronto-parallel at 0.6 m, 1 mm a pixel: its right edge X = 0.21 m falls between
// columns 529 and 530, its bottom edge Y = 0.1485 m between rows 388 and 389.
TEST(RenderShadow, DarkensABandOutsideTheSheetByTheFactorAndNeverThePaper) {
  const LineTarget sheet = FourLineA3Target();
  RenderOptions plain;
  plain.background_grey = 100;
  RenderOptions shadowed = plain;
  shadowed.shadow_darkness = 0.4;
  shadowed.shadow_offset_m = 0.008;
  shadowed.shadow_angle_rad = 0.0;  // towards +x: a band along the right edge
  shadowed.shadow_softness_m = 0.002;
  const vpHomogeneousMatrix cMo = FrontoParallel(0.6);
  const RenderedFrame a = SceneRenderer(sheet, plain).Render(cMo, 1);
  const RenderedFrame b = SceneRenderer(sheet, shadowed).Render(cMo, 1);
  // The moved outline's edge is at X = 0.218 m, its penumbra [0.217, 0.219] m.
  for (int v : {100, 240, 380}) {
    for (int u = 530; u <= 536; ++u) EXPECT_EQ(b.image[v][u], 60) << u << ", " << v;
    EXPECT_EQ(b.image[v][537], 70);  // X = 0.2175: three quarters in the shadow
    EXPECT_EQ(b.image[v][538], 90);  // X = 0.2185: one quarter
    EXPECT_EQ(b.image[v][540], 100);
  }
  int changed = 0;
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      if (a.image[v][u] == b.image[v][u]) continue;
      ++changed;
      // Only on the surface (a pixel on the sheet's edge is half surface), inside the moved
      // outline grown by half the penumbra and half a pixel.
      const double X = PlaneX(u), Y = PlaneY(v);
      EXPECT_GE(DistanceOutsideBoard(sheet, X, Y), -0.0005) << u << ", " << v;
      EXPECT_LE(std::fabs(X - 0.008), 0.21 + 0.0015) << u << ", " << v;
      EXPECT_LE(std::fabs(Y), 0.1485 + 0.0015) << u << ", " << v;
    }
  }
  EXPECT_GT(changed, 8 * 290);
  EXPECT_TRUE(SameTruth(a.truth, b.truth));
}

TEST(RenderShadow, FollowsItsDirectionOnThePlane) {
  const LineTarget sheet = FourLineA3Target();
  RenderOptions options;
  options.background_grey = 100;
  options.shadow_darkness = 0.5;
  options.shadow_offset_m = 0.006;
  options.shadow_angle_rad = kPi / 2.0;  // towards +y: along the bottom edge (rows > 388)
  options.shadow_softness_m = 0.0;
  const RenderedFrame frame = SceneRenderer(sheet, options).Render(FrontoParallel(0.6), 1);
  EXPECT_EQ(frame.image[391][320], 50);
  EXPECT_EQ(frame.image[400][320], 100);
  EXPECT_EQ(frame.image[240][535], 100);  // beside the right edge: no shadow
  EXPECT_EQ(frame.image[85][320], 100);   // above the top edge: none
}

TEST(RenderPaper, TextureStaysWithinItsAmplitudeOnThePaperOnly) {
  const LineTarget sheet = FourLineA3Target();
  RenderOptions options;
  options.paper_texture_grey = 2.0;
  const vpHomogeneousMatrix cMo = FrontoParallel(0.6);
  const RenderedFrame plain = SceneRenderer(sheet, RenderOptions()).Render(cMo, 1);
  const RenderedFrame textured = SceneRenderer(sheet, options).Render(cMo, 1);
  int lo = 255, hi = 0;
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      const int a = plain.image[v][u], b = textured.image[v][u];
      if (a == sheet.board_grey) {
        lo = std::min(lo, b);
        hi = std::max(hi, b);
      } else if (a == sheet.line_grey || a == RenderOptions().background_grey) {
        EXPECT_EQ(a, b) << u << ", " << v;
      }
    }
  }
  EXPECT_GE(lo, sheet.board_grey - 2);
  EXPECT_LE(hi, sheet.board_grey + 2);
  EXPECT_LT(lo, hi);
}

// Renders `sheet` with and without `dressed`'s scene dressing from a few poses and reports the
// plane points of the pixels that differ (fronto-parallel, 0.3 m: 0.5 mm a pixel).
struct Difference {
  double x = 0.0, y = 0.0;
};
std::vector<Difference> DressingDifferences(const LineTarget& sheet, const RenderOptions& dressed,
                                            double distance_m, bool* same_truth) {
  const SceneRenderer plain(sheet, RenderOptions());
  const SceneRenderer renderer(sheet, dressed);
  std::vector<Difference> differences;
  *same_truth = true;
  const double mm_per_px = distance_m / 600.0;
  for (const double x : {-0.15, 0.0, 0.15}) {
    for (const double y : {-0.1, 0.0, 0.1}) {
      const vpHomogeneousMatrix cMo = FrontoParallel(distance_m, x, y);
      const RenderedFrame a = plain.Render(cMo, 1);
      const RenderedFrame b = renderer.Render(cMo, 1);
      *same_truth = *same_truth && SameTruth(a.truth, b.truth);
      for (int v = 0; v < 480; ++v) {
        for (int u = 0; u < 640; ++u) {
          if (a.image[v][u] != b.image[v][u]) {
            differences.push_back({x + (u - 319.5) * mm_per_px, y + (v - 239.5) * mm_per_px});
          }
        }
      }
    }
  }
  return differences;
}

TEST(RenderAnnotations, InkStaysFiveMillimetresClearOfTheStripesOnThePaper) {
  for (const LineTarget& sheet : {FourLineA3Target(), FourLineA4Target()}) {
    RenderOptions options;
    options.annotations = true;
    bool same_truth = false;
    const std::vector<Difference> ink = DressingDifferences(sheet, options, 0.3, &same_truth);
    EXPECT_TRUE(same_truth) << sheet.name;
    EXPECT_GT(ink.size(), 1000u) << sheet.name << ": the annotations are seen";
    double nearest_stripe = 1e300, nearest_edge = 1e300;
    for (const Difference& d : ink) {
      nearest_stripe = std::min(nearest_stripe, DistanceToStripes(sheet, d.x, d.y));
      nearest_edge = std::min(nearest_edge, -DistanceOutsideBoard(sheet, d.x, d.y));
    }
    // 5 mm less one pixel (0.5 mm) of filtering.
    EXPECT_GE(nearest_stripe, 0.0045) << sheet.name;
    EXPECT_GE(nearest_edge, 0.0035) << sheet.name;
  }
}

TEST(RenderAnnotations, CarryTheLineNumbersTheNameAndTheScaleBar) {
  // Ink near each stripe end, in the top-left corner cell and below the '#' (A3).
  const LineTarget sheet = FourLineA3Target();
  RenderOptions options;
  options.annotations = true;
  bool same_truth = false;
  const std::vector<Difference> ink = DressingDifferences(sheet, options, 0.3, &same_truth);
  const auto ink_near = [&ink](double x, double y, double radius) {
    return std::any_of(ink.begin(), ink.end(),
                       [&](const Difference& d) { return std::hypot(d.x - x, d.y - y) <= radius; });
  };
  for (const TargetLine& line : sheet.lines) {
    EXPECT_TRUE(ink_near(line.x1_m, line.y1_m, 0.025)) << line.x1_m << ", " << line.y1_m;
    EXPECT_TRUE(ink_near(line.x2_m, line.y2_m, 0.025)) << line.x2_m << ", " << line.y2_m;
  }
  EXPECT_TRUE(ink_near(-0.18, -0.135, 0.03));  // the name
  // The scale bar: one row of pixels (0.5 mm) below line 4 inked over 100 mm.
  std::map<long, std::set<long>> rows;  // row -> inked columns, in 0.5 mm steps
  for (const Difference& d : ink) {
    if (d.y > 0.075) rows[std::lround(d.y / 0.0005)].insert(std::lround(d.x / 0.0005));
  }
  std::size_t longest = 0;
  for (const auto& [row, columns] : rows) longest = std::max(longest, columns.size());
  EXPECT_GE(longest * 0.0005, 0.099);
}

TEST(RenderClutter, LiesOnTheSurfaceOnlyAndLeavesTheTruthUnchanged) {
  const LineTarget sheet = FourLineA3Target();
  RenderOptions options;
  options.clutter_sheets = 4;
  options.clutter_objects = 12;
  options.clutter_reach_m = 0.15;
  options.scene_seed = 3;
  bool same_truth = false;
  const std::vector<Difference> clutter = DressingDifferences(sheet, options, 0.6, &same_truth);
  EXPECT_TRUE(same_truth);
  EXPECT_GT(clutter.size(), 10000u) << "the clutter is seen";
  double nearest = 1e300;
  for (const Difference& d : clutter) {
    nearest = std::min(nearest, DistanceOutsideBoard(sheet, d.x, d.y));
  }
  EXPECT_GE(nearest, 0.009);  // 10 mm less one pixel
}

TEST(RenderClutter, IsReproducibleFromTheSceneSeed) {
  RenderOptions options;
  options.clutter_sheets = 2;
  options.clutter_objects = 6;
  const vpHomogeneousMatrix cMo = FrontoParallel(1.2);
  const RenderedFrame a = SceneRenderer(FourLineA4Target(), options).Render(cMo, 1);
  const RenderedFrame b = SceneRenderer(FourLineA4Target(), options).Render(cMo, 1);
  options.scene_seed = 2;
  const RenderedFrame c = SceneRenderer(FourLineA4Target(), options).Render(cMo, 1);
  EXPECT_TRUE(SameImage(a.image, b.image));
  EXPECT_FALSE(SameImage(a.image, c.image));
}

TEST(RenderOptionsCheck, NamesEachBadSceneField) {
  const auto message_for = [](void (*change)(RenderOptions&)) -> std::string {
    RenderOptions options;
    change(options);
    try {
      options.Check();
    } catch (const std::invalid_argument& error) {
      return error.what();
    }
    return "";
  };
  EXPECT_EQ(message_for([](RenderOptions&) {}), "");
  const std::pair<const char*, void (*)(RenderOptions&)> cases[] = {
      {"background_texel_m", [](RenderOptions& o) { o.background_texel_m = 0.0; }},
      {"vignetting", [](RenderOptions& o) { o.vignetting = 0.95; }},
      {"hot_spot_gain", [](RenderOptions& o) { o.hot_spot_gain = -0.1; }},
      {"hot_spot_u", [](RenderOptions& o) { o.hot_spot_u = 4.0; }},
      {"hot_spot_v", [](RenderOptions& o) { o.hot_spot_v = -3.0; }},
      {"hot_spot_sigma", [](RenderOptions& o) { o.hot_spot_sigma = 0.0; }},
      {"shadow_darkness", [](RenderOptions& o) { o.shadow_darkness = 1.0; }},
      {"shadow_offset_m", [](RenderOptions& o) { o.shadow_offset_m = 0.2; }},
      {"shadow_angle_rad", [](RenderOptions& o) { o.shadow_angle_rad = std::nan(""); }},
      {"shadow_softness_m", [](RenderOptions& o) { o.shadow_softness_m = -0.001; }},
      {"paper_texture_grey", [](RenderOptions& o) { o.paper_texture_grey = 30.0; }},
      {"annotation_grey", [](RenderOptions& o) { o.annotation_grey = 256; }},
      {"clutter_sheets", [](RenderOptions& o) { o.clutter_sheets = 11; }},
      {"clutter_objects", [](RenderOptions& o) { o.clutter_objects = -1; }},
      {"clutter_reach_m", [](RenderOptions& o) { o.clutter_reach_m = 0.0; }},
  };
  for (const auto& [field, change] : cases) {
    EXPECT_NE(message_for(change).find(std::string("RenderOptions::") + field), std::string::npos)
        << field << ": " << message_for(change);
  }
}

TEST(Render, NothingIsSeenWhenTheBoardIsBehindTheCamera) {
  const SceneRenderer renderer(FourLineTarget(), RenderOptions());
  const RenderedFrame frame = renderer.Render(FrontoParallel(-0.5), 1);
  for (unsigned i = 0; i < frame.image.getSize(); ++i) {
    ASSERT_EQ(frame.image.bitmap[i], RenderOptions().background_grey) << i;
  }
  for (const TruthLine& truth : frame.truth) EXPECT_FALSE(truth.visible);
}

TEST(RenderEffects, NoEffectsIsThePlainRender) {
  RenderOptions options;
  options.noise_sigma = 4.0;
  const SceneRenderer renderer(FourLineTarget(), options);
  const vpHomogeneousMatrix cMo = FrontoParallel(0.6, 0.01, -0.02, 0.2);
  EXPECT_TRUE(
      SameImage(renderer.Render(cMo, 3).image, renderer.Render(cMo, 3, FrameEffects()).image));
}

TEST(RenderEffects, GainAndOffsetMapEveryGreyLevel) {
  const LineTarget target = TwoLineTarget();
  const SceneRenderer renderer(target, RenderOptions());
  FrameEffects effects;
  effects.gain = 0.5;
  effects.offset = 10.2;
  const RenderedFrame frame = renderer.Render(FrontoParallel(0.5), 1, effects);
  EXPECT_EQ(frame.image[240][320], 118);  // 0.5 * 215 + 10.2 = 117.7
  const int line_u = static_cast<int>(std::lround(frame.truth[0].ideal.rho_px));
  EXPECT_EQ(frame.image[240][line_u], 28);  // 0.5 * 35 + 10.2 = 27.7
}

TEST(RenderEffects, OccludersHideAndAreCountedInTheTruth) {
  const LineTarget target = TwoLineTarget();
  const SceneRenderer renderer(target, RenderOptions());
  const vpHomogeneousMatrix cMo = FrontoParallel(0.5);  // vertical lines over the full height
  const double u_line = renderer.Truth(cMo)[0].ideal.rho_px;
  FrameEffects effects;
  Occluder rectangle;  // covers line 0 from the top to row 239.5: half its visible part
  rectangle.centre_u_px = u_line;
  rectangle.centre_v_px = 59.75;
  rectangle.half_width_px = 30.0;
  rectangle.half_height_px = 180.0;
  rectangle.grey = 100;
  Occluder disc;
  disc.shape = Occluder::Shape::kDisc;
  disc.centre_u_px = 320.0;
  disc.centre_v_px = 400.0;
  disc.half_width_px = 20.0;
  disc.grey = 160;
  effects.occluders = {rectangle, disc};
  const RenderedFrame frame = renderer.Render(cMo, 1, effects);
  const int u = static_cast<int>(std::lround(u_line));
  EXPECT_EQ(frame.image[100][u], 100);
  EXPECT_EQ(frame.image[239][u + 29], 100);
  EXPECT_EQ(frame.image[300][u], target.line_grey);
  EXPECT_EQ(frame.image[400][320], 160);
  EXPECT_EQ(frame.image[400][345], target.board_grey);
  EXPECT_GT(frame.image[400][340], 160);  // rim: partly covered
  EXPECT_LT(frame.image[400][340], target.board_grey);
  ASSERT_EQ(frame.truth.size(), 2u);
  EXPECT_TRUE(frame.truth[0].visible);
  EXPECT_NEAR(frame.truth[0].occluded_fraction, 0.5, 0.01);
  EXPECT_EQ(frame.truth[1].occluded_fraction, 0.0);
  EXPECT_EQ(renderer.Truth(cMo)[0].occluded_fraction, 0.0);
}

TEST(RenderEffects, BadEffectsNameTheField) {
  const SceneRenderer renderer(TwoLineTarget(), RenderOptions());
  FrameEffects effects;
  effects.gain = -1.0;
  try {
    renderer.Render(FrontoParallel(0.5), 1, effects);
    FAIL() << "no error";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("FrameEffects::gain = -1"), std::string::npos)
        << error.what();
  }
  effects.gain = 1.0;
  effects.occluders.push_back(Occluder{});  // zero size
  EXPECT_THROW(renderer.Render(FrontoParallel(0.5), 1, effects), std::invalid_argument);
}

}  // namespace
}  // namespace oal
