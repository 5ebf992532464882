// A picture printed on the sheet (RenderOptions::printed_picture), as a marker users would print
// instead of the stripes: its texels on their squares of the plane in the target's ink, its
// edges where the lens puts them, the annotations clear of it, and its check.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "scene/scene.h"
#include "tests/scene/scene_test_util.h"

namespace oal {
namespace {

using testing::Darkness;
using testing::FrontoParallel;

// A white picture of cols x rows texels with the texels `black` (column, row) black.
std::shared_ptr<const vpImage<unsigned char>> Picture(
    unsigned cols, unsigned rows, const std::vector<std::pair<unsigned, unsigned>>& black) {
  auto picture = std::make_shared<vpImage<unsigned char>>(rows, cols, 255);
  for (const auto& [i, j] : black) (*picture)[j][i] = 0;
  return picture;
}

// The A3 sheet's board without its stripes.
LineTarget BlankA3() {
  LineTarget sheet = FourLineA3Target();
  sheet.name = "blank-a3";
  sheet.lines.clear();
  return sheet;
}

// Fronto-parallel at 0.6 m with px = 600: pixel (u, v) sees the square of 1 mm around
// X = (u - 319.5) mm, Y = (v - 239.5) mm.
TEST(RenderPicture, TexelsAreSharpSquaresOfInkCentredOnTheBoard) {
  const LineTarget sheet = BlankA3();
  RenderOptions options;
  // 4 x 2 texels of 25.25 mm: texel (1, 0) covers X and Y in [-25.25, 0] mm.
  options.printed_picture.image = Picture(4, 2, {{1, 0}});
  options.printed_picture.width_m = 0.101;
  const RenderedFrame frame = SceneRenderer(sheet, options).Render(FrontoParallel(0.6), 1);
  const auto darkness = [&](int u, int v) { return Darkness(frame.image, sheet, u, v); };
  constexpr double kGreyStep = 1.0 / 180.0;  // one grey level of the contrast
  for (int v = 216; v <= 238; ++v) {
    for (int u = 296; u <= 319; ++u) ASSERT_NEAR(darkness(u, v), 1.0, kGreyStep) << u << ", " << v;
  }
  // Its left edge at u = 294.25 leaves a quarter of column 294 to the ink (the pixel's exact
  // coverage, no smoothing between texels: column 295 is full ink); its top edge at v = 214.25
  // likewise.
  EXPECT_NEAR(darkness(294, 230), 0.25, 2.0 * kGreyStep);
  EXPECT_NEAR(darkness(295, 230), 1.0, kGreyStep);
  EXPECT_NEAR(darkness(305, 214), 0.25, 2.0 * kGreyStep);
  EXPECT_NEAR(darkness(305, 215), 1.0, kGreyStep);
  // Its right edge at X = 0 is the boundary between columns 319 and 320.
  EXPECT_NEAR(darkness(320, 230), 0.0, kGreyStep);
  // The white texels are bare paper, the ink is the target's line grey.
  for (int u = 270; u <= 292; ++u) EXPECT_EQ(frame.image[230][u], sheet.board_grey) << u;
  for (int u = 321; u <= 368; ++u) EXPECT_EQ(frame.image[230][u], sheet.board_grey) << u;
  EXPECT_EQ(frame.image[230][310], sheet.line_grey);
}

// The 50 % crossing of the darkness along the image direction `d` (unit) through `p`, as an
// offset in pixels from p (bilinear darkness, steps of 0.02 px within +-4 px).
double CrossingOffset(const vpImage<unsigned char>& image, const LineTarget& sheet, Point2d p,
                      Point2d d) {
  const auto darkness = [&](double u, double v) {
    const int u0 = static_cast<int>(std::floor(u)), v0 = static_cast<int>(std::floor(v));
    const double a = u - u0, b = v - v0;
    return (1 - b) *
               ((1 - a) * Darkness(image, sheet, u0, v0) + a * Darkness(image, sheet, u0 + 1, v0)) +
           b * ((1 - a) * Darkness(image, sheet, u0, v0 + 1) +
                a * Darkness(image, sheet, u0 + 1, v0 + 1));
  };
  const double w = image.getWidth(), h = image.getHeight();
  for (const double t : {-5.0, 5.0}) {
    const double u = p.u + t * d.u, v = p.v + t * d.v;
    if (!(u >= 0.0 && v >= 0.0 && u < w - 1.0 && v < h - 1.0)) return 1e9;  // not in the image
  }
  double previous = darkness(p.u - 4.0 * d.u, p.v - 4.0 * d.v);
  for (double t = -4.0 + 0.02; t <= 4.0; t += 0.02) {
    const double now = darkness(p.u + t * d.u, p.v + t * d.v);
    if (previous < 0.5 && now >= 0.5) return t - 0.02 * (now - 0.5) / (now - previous);
    previous = now;
  }
  return 1e9;
}

// A black square inside a white border, seen tilted through a barrel lens: its edges are where
// the square's sides project through the lens model (the marker's corners with them).
TEST(RenderPicture, EdgesLieOnTheProjectedSidesThroughATiltedDistortedLens) {
  const LineTarget sheet = BlankA3();
  RenderOptions options;
  options.camera = Lens::WithKdu(600.0, 600.0, 319.5, 239.5, 0.15, 640, 480);
  std::vector<std::pair<unsigned, unsigned>> black;
  for (unsigned j = 1; j <= 8; ++j) {
    for (unsigned i = 1; i <= 8; ++i) black.push_back({i, j});
  }
  options.printed_picture.image = Picture(10, 10, black);
  options.printed_picture.width_m = 0.25;  // the black square: |X|, |Y| <= 0.1 m
  // 0.45 m from the sheet's point (0.02, -0.01), tilted by 0.5 rad about an axis at 0.6 rad
  // from x, rolled by 0.3 rad.
  vpHomogeneousMatrix to_point, tilt, back, roll;
  to_point.buildFrom(0.02, -0.01, 0.0, 0.0, 0.0, 0.0);
  tilt.buildFrom(0.0, 0.0, 0.0, 0.5 * std::cos(0.6), 0.5 * std::sin(0.6), 0.0);
  back.buildFrom(0.0, 0.0, -0.45, 0.0, 0.0, 0.0);
  roll.buildFrom(0.0, 0.0, 0.0, 0.0, 0.0, 0.3);
  const vpHomogeneousMatrix cMo = (to_point * tilt * back * roll).inverse();
  const RenderedFrame frame = SceneRenderer(sheet, options).Render(cMo, 1);
  const auto pixel = [&](double X, double Y) {
    Point2d ideal;
    EXPECT_TRUE(testing::Project(cMo, options.camera, X, Y, &ideal));
    return options.camera.Pixel((ideal.u - 319.5) / 600.0, (ideal.v - 239.5) / 600.0);
  };
  double worst = 0.0;
  // Each side's points and its inward normal on the plane.
  const double sides[4][4] = {{-0.1, 0, 1, 0}, {0.1, 0, -1, 0}, {0, -0.1, 0, 1}, {0, 0.1, 0, -1}};
  for (const auto& side : sides) {
    for (const double along : {-0.09, -0.05, 0.0, 0.05, 0.09}) {
      const double X = side[0] + (side[2] == 0 ? along : 0.0);
      const double Y = side[1] + (side[3] == 0 ? along : 0.0);
      const Point2d p = pixel(X, Y);
      const Point2d in = pixel(X + 0.002 * side[2], Y + 0.002 * side[3]);
      const Point2d out = pixel(X - 0.002 * side[2], Y - 0.002 * side[3]);
      const double n = std::hypot(in.u - out.u, in.v - out.v);
      const Point2d d{(in.u - out.u) / n, (in.v - out.v) / n};
      const double offset = CrossingOffset(frame.image, sheet, p, d);
      worst = std::max(worst, std::fabs(offset));
      EXPECT_LT(std::fabs(offset), 0.2) << X << ", " << Y;
    }
  }
  RecordProperty("worst_edge_offset_px", std::to_string(worst));
}

// The annotations (the name, the scale bar) are laid out clear of the picture, as of stripes.
TEST(RenderPicture, AnnotationsKeepClearOfIt) {
  const LineTarget sheet = BlankA3();
  RenderOptions plain;
  std::vector<std::pair<unsigned, unsigned>> black;
  for (unsigned j = 0; j < 8; ++j) {
    for (unsigned i = 0; i < 8; ++i) black.push_back({i, j});
  }
  plain.printed_picture.image = Picture(8, 8, black);
  plain.printed_picture.width_m = 0.25;
  RenderOptions annotated = plain;
  annotated.annotations = true;
  // 0.4 mm a pixel over the sheet's left half, then its right half.
  int inked = 0;
  double nearest_m = 1e9;
  for (const double x : {-0.1, 0.1}) {
    for (const double y : {-0.08, 0.08}) {
      const vpHomogeneousMatrix cMo = FrontoParallel(0.24, x, y);
      const RenderedFrame a = SceneRenderer(sheet, plain).Render(cMo, 1);
      const RenderedFrame b = SceneRenderer(sheet, annotated).Render(cMo, 1);
      for (int v = 0; v < 480; ++v) {
        for (int u = 0; u < 640; ++u) {
          if (a.image[v][u] == b.image[v][u]) continue;
          ++inked;
          const double X = x + (u - 319.5) * 0.0004, Y = y + (v - 239.5) * 0.0004;
          const double dx = std::max(std::fabs(X) - 0.125, 0.0);
          const double dy = std::max(std::fabs(Y) - 0.125, 0.0);
          nearest_m = std::min(nearest_m, std::hypot(dx, dy));
        }
      }
    }
  }
  EXPECT_GT(inked, 500);
  EXPECT_GE(nearest_m, 0.005 - 0.0004);  // 5 mm less one pixel of filtering
}

TEST(RenderPicture, AWidthIsNeededWithAPicture) {
  RenderOptions options;
  options.printed_picture.image = Picture(2, 2, {});
  try {
    options.Check();
    FAIL() << "accepted a picture without a width";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("RenderOptions::printed_picture.width_m"),
              std::string::npos)
        << error.what();
  }
  options.printed_picture.image = std::make_shared<vpImage<unsigned char>>();
  EXPECT_NO_THROW(options.Check()) << "an empty picture is none";
}

}  // namespace
}  // namespace oal
